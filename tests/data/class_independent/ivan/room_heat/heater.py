# Heater node: the actuator, it just reports every command it gets
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool


class Heater(Node):
    def __init__(self):
        super().__init__('heater')
        self.commandsReceived = 0
        self.create_subscription(Bool, 'heater/on', self.commandCallback, 10)

    def commandCallback(self, msg):
        self.commandsReceived = self.commandsReceived + 1
        if msg.data:
            self.get_logger().info('heater ON (command %d)' % self.commandsReceived)
        else:
            self.get_logger().info('heater OFF (command %d)' % self.commandsReceived)


def main(args=None):
    rclpy.init(args=args)
    heaterNode = Heater()
    rclpy.spin(heaterNode)
    heaterNode.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
