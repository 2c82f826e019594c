# park_assist: reversing sensor -> beep rate -> buzzer. All three nodes in one file,
# each with its own entry point in setup.py.
import itertools

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, Int32

BACK_AND_FORTH = [2.0, 1.6, 1.2, 0.9, 0.6, 0.4, 0.25, 0.15, 0.4, 0.9, 1.5]


class Ultrasonic(Node):
    """Reversing towards a wall and pulling away again, over and over."""

    def __init__(self):
        super().__init__('ultrasonic')
        hz = self.declare_parameter('hz', 3.0).value
        self.script = itertools.cycle(BACK_AND_FORTH)
        self.echo = self.create_publisher(Float32, 'rear_distance', 10)
        self.create_timer(1 / hz, lambda: self.echo.publish(Float32(data=next(self.script))))


class BeeperLogic(Node):
    """Closer -> faster beeps; inside `solid_below` a continuous tone (beeps = -1)."""

    def __init__(self):
        super().__init__('beeper_logic')
        self.start = self.declare_parameter('start_beeping_m', 1.5).value
        self.solid = self.declare_parameter('solid_below_m', 0.3).value
        self.fastest = self.declare_parameter('fastest_beeps', 8).value
        self.beeps = self.create_publisher(Int32, 'beeps_per_second', 10)
        self.create_subscription(Float32, 'rear_distance', self.judge, 10)

    def judge(self, echo):
        if echo.data < self.solid:
            rate = -1
        elif echo.data > self.start:
            rate = 0
        else:
            closeness = (self.start - echo.data) / (self.start - self.solid)
            rate = 1 + round(closeness * (self.fastest - 1))
        self.beeps.publish(Int32(data=rate))


class Buzzer(Node):
    def __init__(self):
        super().__init__('buzzer')
        self.create_subscription(Int32, 'beeps_per_second', self.sound, 10)

    def sound(self, beeps):
        if beeps.data < 0:
            self.get_logger().info('BEEEEEEEP')
        elif beeps.data == 0:
            self.get_logger().info('(quiet)')
        else:
            self.get_logger().info('beep ' * beeps.data)


def _run(node_class):
    rclpy.init()
    node = node_class()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def run_ultrasonic():
    _run(Ultrasonic)


def run_beeper_logic():
    _run(BeeperLogic)


def run_buzzer():
    _run(Buzzer)
