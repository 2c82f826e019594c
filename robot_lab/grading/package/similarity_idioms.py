"""The code every rclpy solution to a lab shares, which similarity never counts as copied.

Only the *shape* of these lines matters (names, strings and numbers are abstracted), so
each block stands for every solution written the same way with other names. Kept apart
from robot_lab.grading.package.similarity so that module stays about the comparison.
"""

from __future__ import annotations

__all__ = ['IDIOMS']

# What a student writes because rclpy says so, or because the tutorial or the lab's own
# handout showed it, not because they thought of it: variants of each idiom (the shape
# ignores names, strings and numbers, not structure). Type annotations need no variants:
# similarity drops them before comparing.
IDIOMS = """
import rclpy
from rclpy.node import Node
from rclpy.executors import MultiThreadedExecutor
from std_msgs.msg import Float32
from std_msgs.msg import Float32, String
from geometry_msgs.msg import Twist
import random
import math
import os
from glob import glob
from launch import LaunchDescription
from launch_ros.actions import Node
from ament_index_python.packages import get_package_share_directory


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.shutdown()


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.shutdown()


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


def main():
    rclpy.init()
    rclpy.spin(Node())


def main():
    rclpy.init()
    node = rclpy.create_node('node')
    value = node.declare_parameter('name', 1.0).value
    pub = node.create_publisher(String, 'topic', 10)
    node.create_subscription(String, 'topic', callback, 10)
    node.create_timer(value, callback)
    node.get_logger().info('text')


if __name__ == '__main__':
    main()


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()


class Name(Node):
    def __init__(self):
        super().__init__('node')
        self.declare_parameter('name', 1.0)
        self.declare_parameter('name', 1.0)
        self.declare_parameter('name', 1.0)
        self.declare_parameters('', [('name', 1.0), ('name', 1.0)])
        self.value = self.get_parameter('name').value
        self.value = self.get_parameter('name').get_parameter_value().double_value
        self.value = self.declare_parameter('name', 1.0).value
        rate = self.get_parameter('name').value
        self.publisher = self.create_publisher(String, 'topic', 10)
        self.create_publisher(String, 'topic', 10)
        self.subscription = self.create_subscription(String, 'topic', self.callback, 10)
        self.create_subscription(String, 'topic', self.callback, 10)
        self.timer = self.create_timer(1.0 / self.value, self.callback)
        self.timer = self.create_timer(1.0 / rate, self.callback)
        self.create_timer(1.0 / rate, self.callback)
        self.create_timer(self.value, self.callback)
        self.create_timer(self.get_parameter('name').value, self.callback)
        self.get_logger().info('started')
        self.get_logger().info(f'text {self.value}')

        self.create_subscription(Twist, 'topic', self.callback, 10)

    def callback(self, msg):
        value = self.get_parameter('name').value
        msg = Twist()
        msg.linear.x = float(value)
        self.publisher.publish(msg)


def main(args=None):
    pass


class Name(Node):
    def callback(self, msg):
        msg = Twist()
        msg.linear.x = value
        msg.angular.z = value
        self.publisher.publish(msg)
        self.get_logger().info(f'Received: {msg.data}')
        self.get_logger().info('text %s' % msg.data)
        msg = String()
        msg.data = 'text'
        self.publisher.publish(msg)
        self.publisher.publish(String(data=value))
        self.value = msg.data
        value = self.get_parameter('name').value


def generate_launch_description():
    config = os.path.join(get_package_share_directory('package'), 'config', 'params.yaml')
    return LaunchDescription([
        Node(package='package', executable='node', name='node', output='screen',
             parameters=[config]),
        Node(package='package', executable='node', name='node', parameters=[config]),
    ])


# The ROS 2 tutorials' publisher and subscriber, the layout many students start from.
class Name(Node):

    def __init__(self):
        super().__init__('node')
        self.publisher_ = self.create_publisher(String, 'topic', 10)
        timer_period = 0.5  # seconds
        self.timer = self.create_timer(timer_period, self.timer_callback)
        self.i = 0
        self.subscription = self.create_subscription(
            String,
            'topic',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning

    def timer_callback(self):
        msg = String()
        msg.data = 'text: %d' % self.i
        self.publisher_.publish(msg)
        self.get_logger().info('Publishing: "%s"' % msg.data)
        self.i += 1

    def listener_callback(self, msg):
        self.get_logger().info('I heard: "%s"' % msg.data)


def main(args=None):
    rclpy.init(args=args)

    node = Name()

    rclpy.spin(node)

    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()


# The course's Lab 1.3 handout (sensor, controller, robot node), as students adapt it.
class Name(Node):
    def __init__(self):
        super().__init__('node')
        self.declare_parameter('name', 10)
        self.declare_parameter('name', 0.1)
        rate = self.get_parameter('name').value
        self.value = self.get_parameter('name').value
        self.pub = self.create_publisher(Float32, 'topic', 10)
        self.timer = self.create_timer(1.0 / rate, self.callback)
        self.sub = self.create_subscription(
            Float32, 'topic', self.callback, 10)
        self.get_logger().info(f'text {rate} text')
        self.get_logger().info('text')

    def callback(self):
        value = 22.5 + random.uniform(-self.value, self.value)
        msg = Float32()
        msg.data = value
        self.pub.publish(msg)
        self.get_logger().debug(f'text {value:.2f} text')
        msg = Float32()
        msg.data = self.value
        self.pub.publish(msg)

    def callback(self, msg):
        self.value = msg.data
        if msg.data > self.value:
            self.get_logger().warn(f'text {msg.data:.2f} text')
        status = String()
        status.data = f'text {self.value:.1f} text'
        self.pub.publish(status)
        self.get_logger().info(f'text {msg.data}')


def generate_launch_description():
    config = os.path.join(
        get_package_share_directory('package'),
        'config',
        'params.yaml'
    )
    return LaunchDescription([
        Node(
            package='package',
            executable='node',
            name='node',
            parameters=[config]
        ),
        Node(
            package='package',
            executable='node',
            name='node'
        ),
    ])
"""
