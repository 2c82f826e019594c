import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):

    def __init__(self):
        super().__init__('talker')
        self.declare_parameter('greeting', 'hello')
        self.pub = self.create_publisher(String, '/chatter', 10)
        self.timer = self.create_timer(0.5, self.tick)

    def tick(self):
        msg = String()
        msg.data = self.get_parameter('greeting').value
        self.pub.publish(msg)


def main(args=None):
    rclpy.init(args=args)
    rclpy.spin(Talker())
    rclpy.shutdown()


if __name__ == '__main__':
    main()
