"""turtle_tf2_message_broadcaster: spawn turtle3, drive it in circles, and publish its
position as a PointStamped in `world` on turtle3/turtle_point_stamped.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name turtle_tf2_message_broadcaster: the source of stamped data for the tf2 message
filter page (turtle_tf2_sensor_message.launch.py).
"""

import rclpy
from geometry_msgs.msg import PointStamped, Twist
from rclpy.node import Node
from turtlesim.msg import Pose

from turtle_tf2_py._shared import TurtleSpawner, spin_until_stopped


class TurtlePointSource(Node):
    """Once turtle3 exists, each of its poses yields one circle command and one point."""

    def __init__(self):
        super().__init__('turtle_tf2_message_broadcaster')
        self.spawner = TurtleSpawner(self, 'turtle3')
        self.point_pub = None
        self.timer = self.create_timer(1.0, self.on_timer)

    def on_timer(self):
        if self.point_pub is not None or not self.spawner.step():
            return
        # turtle3's topics exist only now that turtlesim has spawned it
        self.cmd_pub = self.create_publisher(Twist, 'turtle3/cmd_vel', 10)
        self.point_pub = self.create_publisher(PointStamped, 'turtle3/turtle_point_stamped', 10)
        self.pose_sub = self.create_subscription(Pose, 'turtle3/pose', self.on_pose, 10)
        self.timer.cancel()

    def on_pose(self, pose):
        circle = Twist()
        circle.linear.x = 1.0
        circle.angular.z = 1.0
        self.cmd_pub.publish(circle)
        point = PointStamped()
        point.header.stamp = self.get_clock().now().to_msg()
        point.header.frame_id = 'world'
        point.point.x, point.point.y, point.point.z = pose.x, pose.y, 0.0
        self.point_pub.publish(point)


def main():
    rclpy.init()
    spin_until_stopped(TurtlePointSource())
