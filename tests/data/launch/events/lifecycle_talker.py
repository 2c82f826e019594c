"""A managed (lifecycle) talker, as ros2/demos' lifecycle_talker: publishes only when active."""

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from std_msgs.msg import String


class Talker(LifecycleNode):
    def __init__(self) -> None:
        super().__init__('lc_talker')
        self.count = 0
        self.pub = None
        self.timer = None

    def on_configure(self, state):
        self.pub = self.create_lifecycle_publisher(String, 'lifecycle_chatter', 10)
        self.timer = self.create_timer(0.2, self.tick)
        self.get_logger().info('on_configure() is called.')
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state):
        self.get_logger().info('on_activate() is called.')
        return super().on_activate(state)

    def on_deactivate(self, state):
        self.get_logger().info('on_deactivate() is called.')
        return super().on_deactivate(state)

    def tick(self) -> None:
        self.count += 1
        if self.pub is not None and self.pub.is_activated:
            self.pub.publish(String(data=f'Lifecycle HelloWorld #{self.count}'))


def main() -> None:
    rclpy.init(args=sys.argv)
    node = Talker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
