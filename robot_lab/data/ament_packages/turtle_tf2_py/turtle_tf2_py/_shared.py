"""Pieces every demo node needs: a yaw-only quaternion, a turtle spawner, and a main loop.

robot_lab's stand-in for the tutorial package (see __init__.py); written for the kit.
"""

import math

import rclpy
from rclpy.executors import ExternalShutdownException
from turtlesim.srv import Spawn


def quaternion_from_euler(roll, pitch, yaw):
    """(x, y, z, w) of fixed-axis roll, then pitch, then yaw: the order tf2's setRPY uses."""
    half_r, half_p, half_y = roll / 2.0, pitch / 2.0, yaw / 2.0
    cr, sr = math.cos(half_r), math.sin(half_r)
    cp, sp = math.cos(half_p), math.sin(half_p)
    cy, sy = math.cos(half_y), math.sin(half_y)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def fill_rotation(rotation, roll, pitch, yaw):
    """Write the quaternion of (roll, pitch, yaw) into a geometry_msgs Quaternion in place."""
    rotation.x, rotation.y, rotation.z, rotation.w = quaternion_from_euler(roll, pitch, yaw)


class TurtleSpawner:
    """Ask turtlesim's /spawn for one turtle, one step per timer tick, logging as it goes.

    The demo nodes call step() from a 1 Hz timer instead of blocking in their constructor,
    so they start before turtlesim does and say what they are waiting for meanwhile.
    """

    def __init__(self, node, name, x=4.0, y=2.0, theta=0.0):
        self._node = node
        self._client = node.create_client(Spawn, 'spawn')
        self._request = Spawn.Request(name=name, x=x, y=y, theta=theta)
        self._pending = None
        self.spawned = False

    def step(self):
        """Advance the spawn by one tick; True once turtlesim has answered."""
        if self.spawned:
            return True
        log = self._node.get_logger()
        if self._pending is None:
            if self._client.service_is_ready():
                self._pending = self._client.call_async(self._request)
            else:
                log.info('Service is not ready')
        elif self._pending.done():
            log.info(f'Successfully spawned {self._pending.result().name}')
            self.spawned = True
        else:
            log.info('Spawn is not finished')
        return self.spawned


def spin_until_stopped(node):
    """Spin one node until Ctrl-C or a launch's SIGINT, then tidy up without a traceback."""
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
