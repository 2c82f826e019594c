import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32
from std_msgs.msg import String


class DoorLogic(Node):

    def __init__(self):
        super().__init__('door_logic')
        self.declare_parameter('open_within', 1.5)
        self.declare_parameter('close_beyond', 2.0)
        self.declare_parameter('hold_ticks', 4)
        self.state = 'closed'
        self.ticks_away = 0
        self.subscription = self.create_subscription(
            Float32,
            'person_distance',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning
        self.publisher_ = self.create_publisher(String, 'door_command', 10)

    def listener_callback(self, msg):
        if msg.data < self.get_parameter('open_within').value:
            self.state = 'open'
            self.ticks_away = 0
        elif msg.data > self.get_parameter('close_beyond').value:
            self.ticks_away += 1
            if self.ticks_away >= self.get_parameter('hold_ticks').value:
                self.state = 'closed'
        command = String()
        command.data = self.state
        self.publisher_.publish(command)


def main(args=None):
    rclpy.init(args=args)

    door_logic = DoorLogic()

    rclpy.spin(door_logic)

    door_logic.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
