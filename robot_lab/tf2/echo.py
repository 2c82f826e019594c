"""`ros2 run tf2_ros tf2_echo SOURCE TARGET [rate]` and `tf2_monitor [A B]`, printing what
geometry2's C++ programs print (tf2_ros/src/tf2_echo.cpp, tf2_monitor.cpp).

Both listen with a TransformListener on a node spun in a thread of their own, while the main
thread prints at the asked rate; Ctrl-C ends them quietly.
"""

from __future__ import annotations

import math
import signal
import sys
import threading
import time
from collections.abc import Sequence
from typing import Any

from robot_lab.tf2 import linear_math as lm

ECHO_USAGE = (
    'Usage: tf2_echo source_frame target_frame [echo_rate]\n\n'
    'This will echo the transform from the coordinate frame of the source_frame\n'
    'to the coordinate frame of the target_frame. \n'
    'Note: This is the transform to get data from target_frame into the source_frame.\n'
    'Default echo rate is 1 if echo_rate is not given.\n')


def format_echo(transform: Any) -> str:
    """One tf2_echo report (At time, translation, quaternion, RPY in rad and deg, matrix)."""
    t, r = transform.transform.translation, transform.transform.rotation
    q = (r.x, r.y, r.z, r.w)
    roll, pitch, yaw = lm.euler_from_quaternion(q)
    deg = 180.0 / math.pi
    m = lm.matrix_from_quaternion(q)
    xyz = (t.x, t.y, t.z)
    lines = [f'At time {transform.header.stamp.sec}.{transform.header.stamp.nanosec}',
             f'- Translation: [{t.x:.3f}, {t.y:.3f}, {t.z:.3f}]',
             f'- Rotation: in Quaternion [{r.x:.3f}, {r.y:.3f}, {r.z:.3f}, {r.w:.3f}]',
             f'- Rotation: in RPY (radian) [{roll:.3f}, {pitch:.3f}, {yaw:.3f}]',
             f'- Rotation: in RPY (degree) [{roll * deg:.3f}, {pitch * deg:.3f}, '
             f'{yaw * deg:.3f}]',
             '- Matrix:']
    for i in range(3):
        lines.append(''.join(f' {v:6.3f}' for v in (*m[i], xyz[i])))
    lines.append(''.join(f' {v:6.3f}' for v in (0.0, 0.0, 0.0, 1.0)))
    return '\n'.join(lines) + '\n'


class _Listening:
    """rclpy up, a node with a listener spinning in a thread, SIGINT/SIGTERM -> `stop`."""

    def __init__(self, argv: Sequence[str], node_name: str) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.signals import SignalHandlerOptions

        from robot_lab.tf2.buffer import Buffer
        from robot_lab.tf2.listener import TransformListener

        self.stop = threading.Event()
        signal.signal(signal.SIGINT, lambda *_: self.stop.set())
        signal.signal(signal.SIGTERM, lambda *_: self.stop.set())
        rclpy.init(args=list(argv), signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node(node_name)
        self.clock = self.node.get_clock()
        self.buffer = Buffer(node=self.node)
        self.listener = TransformListener(self.buffer, self.node)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self.stop.is_set():
            self.executor.spin_once(timeout_sec=0.1)

    def sleep(self, seconds: float) -> None:
        self.stop.wait(seconds)

    def close(self) -> None:
        import rclpy
        self.stop.set()
        self._thread.join()
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.utilities.try_shutdown()


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def echo_main(argv: Sequence[str] | None = None) -> None:
    """The tf2_echo program."""
    from rclpy.time import Time
    from rclpy.utilities import remove_ros_args

    from robot_lab.tf2.exceptions import TransformException
    from robot_lab.tf2.static_publisher import version_line

    full = list(sys.argv if argv is None else argv)
    args = remove_ros_args(full)
    if '--version' in args[1:]:
        print(version_line('tf2_echo'))
        return
    rate_hz = 1.0
    if len(args) == 4:
        # std::stof: no number at all exits 2, a number with junk after it exits 3
        text = args[3]
        numeric = [end for end in range(len(text), 0, -1) if _is_float(text[:end])]
        if not numeric or numeric[0] != len(text):
            print(f"Failed to convert rate argument '{text}' to a floating-point number",
                  file=sys.stderr)
            sys.exit(3 if numeric else 2)
        rate_hz = float(text)
    elif len(args) != 3:
        sys.stdout.write(ECHO_USAGE)
        sys.exit(1)
    source, target = args[1], args[2]
    period = 1.0 / rate_hz if rate_hz > 0 else 1.0
    ros = _Listening(full, 'tf2_echo')
    try:
        last_note = -math.inf
        while not ros.stop.is_set():
            ok, why = ros.buffer.can_transform_core(source, target, Time())
            if ok:
                break
            if time.monotonic() - last_note >= 1.0:  # RCLCPP_INFO_THROTTLE 1000 ms
                ros.node.get_logger().info(f'Waiting for transform {source} ->  {target}: {why}')
                last_note = time.monotonic()
            ros.sleep(period)
        while not ros.stop.is_set():
            try:
                found = ros.buffer.lookup_transform_core(source, target, Time())
                sys.stdout.write(format_echo(found))
            except TransformException as exc:
                sys.stdout.write(f'Failure at {ros.clock.now().nanoseconds / 1e9:g}\n'
                                 f'Exception thrown:{exc}\nThe current list of frames is:\n'
                                 f'{ros.buffer.all_frames_as_string()}\n')
            sys.stdout.flush()
            ros.sleep(period)
    finally:
        ros.close()


def _frame_info(name: str, delays: list[float], authority: str) -> str:
    return (f'Frame: {name}, published by {authority}, Average Delay: '
            f'{sum(delays) / len(delays):g}, Max Delay: {max(0.0, *delays):g}\n')


def monitor_main(argv: Sequence[str] | None = None) -> None:
    """The tf2_monitor program: delays per frame (and along A -> B) every 10 s."""
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from rclpy.time import Time
    from rclpy.utilities import remove_ros_args
    from tf2_msgs.msg import TFMessage

    from robot_lab.tf2.static_publisher import version_line

    full = list(sys.argv if argv is None else argv)
    args = remove_ros_args(full)
    if '--version' in args[1:]:
        print(version_line('tf2_monitor'))
        return
    ros = _Listening(full, 'tf2_monitor_main')
    if len(args) not in (1, 3):
        ros.node.get_logger().info('TF_Monitor: usage: tf2_monitor framea frameb')
        ros.close()
        sys.exit(255)
    chain_mode = len(args) == 3
    framea, frameb = (args[1], args[2]) if chain_mode else ('', '')
    lock = threading.Lock()
    delays: dict[str, list[float]] = {}
    authority_delays: list[float] = []
    arrivals: list[float] = []
    authority = '<no authority available>'

    def on_tf(msg: Any) -> None:
        now = ros.clock.now().nanoseconds / 1e9
        with lock:
            offsets = [now - (t.header.stamp.sec + t.header.stamp.nanosec * 1e-9)
                       for t in msg.transforms]
            for t, offset in zip(msg.transforms, offsets, strict=True):
                kept = delays.setdefault(t.child_frame_id, [])
                kept.append(offset)
                del kept[:-1000]
            authority_delays.append(sum(offsets) / max(1, len(offsets)))
            del authority_delays[:-1000]
            arrivals.append(now)
            del arrivals[:-1000]

    chain: list[str] = []
    try:
        if chain_mode:
            last_note = -math.inf
            while not ros.stop.is_set():
                ok, why = ros.buffer.can_transform_core(framea, frameb, Time())
                if ok:
                    break
                if time.monotonic() - last_note >= 1.0:
                    ros.node.get_logger().info(
                        f'Waiting for transform {framea} ->  {frameb}: {why}')
                    last_note = time.monotonic()
                ros.sleep(0.5)
            chain = ros.buffer._chain(frameb, Time(), framea, Time(), frameb)
        ros.node.create_subscription(TFMessage, '/tf', on_tf, QoSProfile(depth=100))
        ros.node.create_subscription(TFMessage, '/tf_static', on_tf, QoSProfile(
            depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        print(f'Gathering data on {framea} -> {frameb} for 10 seconds...' if chain_mode
              else 'Gathering data on all frames for 10 seconds...', flush=True)
        counter, max_diff, avg_diff = 0, 0.0, 0.0
        while not ros.stop.is_set():
            counter += 1
            if chain_mode:
                found = ros.buffer.lookup_transform_core(framea, frameb, Time())
                diff = (ros.clock.now().nanoseconds / 1e9 - found.header.stamp.sec
                        - found.header.stamp.nanosec * 1e-9)
                avg_diff = 0.01 * diff + 0.99 * avg_diff
                max_diff = max(max_diff, diff)
            ros.sleep(0.5)
            if counter <= 20:
                continue
            counter = 0
            out = []
            if chain_mode:
                out += [f'\n\n\nRESULTS: for {framea} to {frameb}\n',
                        f"Chain is: {' -> '.join(chain)}\n",
                        f'Net delay     avg = {avg_diff:g}: max = {max_diff:g}\n']
            else:
                out.append('\n\n\nRESULTS: for all Frames\n')
            with lock:
                out.append('\nFrames:\n')
                for name in sorted(delays):
                    if not chain_mode or name in chain:
                        out.append(_frame_info(name, delays[name], authority))
                print(''.join(out), end='', flush=True)
                print('\nAll Broadcasters:', file=sys.stderr, flush=True)
                if authority_delays:
                    rate = len(arrivals) / max(1e-8, arrivals[-1] - arrivals[0])
                    print(f'Node: {authority} {rate:g} Hz, Average Delay: '
                          f'{sum(authority_delays) / len(authority_delays):g} Max Delay: '
                          f'{max(0.0, *authority_delays):g}', flush=True)
    finally:
        ros.close()
