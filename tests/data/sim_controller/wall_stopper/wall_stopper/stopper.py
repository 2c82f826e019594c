"""Drive forward and stop `stop_distance` m before the obstacle ahead (Module 2)."""

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from sensor_msgs.msg import LaserScan


class Stopper(Node):

    def __init__(self):
        super().__init__('stopper')
        self.declare_parameter('stop_distance', 0.3)
        self.declare_parameter('max_speed', 0.3)
        # the lidar sits at the chassis' centre, this far behind the robot's front
        self.declare_parameter('lidar_to_front', 0.2)
        self.publisher = self.create_publisher(Twist, '/cmd_vel', 10)
        self.create_subscription(LaserScan, '/scan', self.on_scan, 10)

    def on_scan(self, scan):
        ahead = round((0.0 - scan.angle_min) / scan.angle_increment)
        gap = scan.ranges[ahead] - self.get_parameter('lidar_to_front').value
        left = gap - self.get_parameter('stop_distance').value
        cmd = Twist()
        if left > 0.0:
            cmd.linear.x = min(self.get_parameter('max_speed').value, 1.5 * left)
        self.publisher.publish(cmd)


def main():
    rclpy.init()
    node = Stopper()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
