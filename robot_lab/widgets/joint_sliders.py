"""joint_state_publisher_gui in the notebook: a slider per movable joint of the robot.

The Qt GUI is joint_state_publisher with sliders; this is the same in ipywidgets: the
robot comes from /robot_description (transient-local: robot_state_publisher may have
started first) or from the text given; each free joint gets a slider over its limits
(continuous joints over ±π, soft limits respected, mimic joints follow their leader and
get none); `rate` times a second the positions go out as a JointState, as the GUI's
timer sends them. Where a joint_state_publisher takes `/joint_sliders` in its
source_list (urdf_launch's display.launch.py does), the sliders feed it instead of
publishing /joint_states beside it, so the two never fight over a joint.
"""

from __future__ import annotations

import html
import random
import threading
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.urdf.joints import JointTable, joint_table
from robot_lab.urdf.model import Robot, parse_urdf
from robot_lab.widgets.output import is_headless, owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import FloatSlider, Widget

__all__ = ['FEED_TOPIC', 'JointSliders', 'joint_sliders']

FEED_TOPIC = '/joint_sliders'  # a joint_state_publisher's source_list entry for the sliders


class JointSliders:
    """Sliders for a robot's joints that publish /joint_states; drivable with `set()`."""

    def __init__(self, robot_description: str | None = None, topic: str | None = None,
                 rate: float = 10.0, zeros: Mapping[str, float] | None = None,
                 timeout: float = 5.0, domain_id: int | None = None) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile
        from sensor_msgs.msg import JointState

        from robot_lab.rclpy_session import session

        self.session = session(domain_id)
        text = robot_description or self._published_description(timeout)
        self.robot: Robot = parse_urdf(text, 'robot_description')
        self.table: JointTable = joint_table(self.robot, zeros)
        self._lock = threading.Lock()
        self._sliders: dict[str, FloatSlider] = {}
        self._widget: Widget | None = None
        self._message_class = JointState
        node = self.session.node
        depth = QoSProfile(depth=10, durability=DurabilityPolicy.VOLATILE)
        self.topic = topic
        self._direct = node.create_publisher(JointState, topic or '/joint_states', depth)
        self._feed = None if topic else node.create_publisher(JointState, FEED_TOPIC, depth)
        self._timer = self.session.run_in_executor(
            lambda: node.create_timer(1.0 / rate, self.publish))
        owned_by_cell(self)

    def _published_description(self, timeout: float) -> str:
        """The URDF robot_state_publisher latched on /robot_description."""
        from std_msgs.msg import String

        from robot_lab.urdf.state_publisher import description_qos

        got: list[str] = []
        arrived = threading.Event()

        def take(message: String) -> None:
            got.append(message.data)
            arrived.set()

        node = self.session.node
        subscription = self.session.run_in_executor(lambda: node.create_subscription(
            String, '/robot_description', take, description_qos()))
        try:
            if not arrived.wait(timeout):
                raise GraphError(
                    f'no robot description on /robot_description within {timeout:g} s',
                    fix='start robot_state_publisher first (ros2 launch urdf_tutorial '
                        'display.launch.py model:=urdf/06-flexible.urdf), or pass the URDF: '
                        'joint_sliders(robot_description=text)')
        finally:
            self.session.run_in_executor(lambda: node.destroy_subscription(subscription))
        return got[-1]

    @property
    def values(self) -> dict[str, float]:
        """Every published joint's position (mimic joints included), by name."""
        with self._lock:
            return dict(zip(self.table.order, self.table.positions(), strict=True))

    def set(self, name: str, value: float) -> float:
        """Move free joint `name` to `value`, held inside its limits; returns the value set."""
        joint = self.table.free.get(name)
        if joint is None:
            movable = ', '.join(self.table.free) or 'none'
            raise GraphError(f"'{name}' is not a joint a slider moves",
                             fix=f'choose one of: {movable}')
        with self._lock:
            joint.position = min(max(float(value), joint.lower), joint.upper)
            position = joint.position
        slider = self._sliders.get(name)
        if slider is not None and slider.value != position:
            slider.value = position
        return position

    def center(self) -> None:
        """Every joint back to its zero (the GUI's Center button)."""
        for name, joint in self.table.free.items():
            self.set(name, joint.zero)

    def randomize(self, seed: int | None = None) -> None:
        """Every joint somewhere in its range (the GUI's Randomize button)."""
        rng = random.Random(seed)
        for name, joint in self.table.free.items():
            self.set(name, rng.uniform(joint.lower, joint.upper))

    def message(self) -> Any:
        with self._lock:
            positions = self.table.positions()
        message = self._message_class(name=list(self.table.order), position=positions)
        message.header.stamp = self.session.node.get_clock().now().to_msg()
        return message

    def publish(self) -> None:
        """One JointState: to a joint_state_publisher that takes the sliders if one is
        matched, else on /joint_states (or on the topic given)."""
        if not self.table.order:
            return
        feeding = self._feed is not None and self._feed.get_subscription_count() > 0
        (self._feed if feeding and self._feed is not None else self._direct).publish(
            self.message())

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            rows: list[Widget] = [widgets.HTML(
                f'<b>{html.escape(self.robot.name)}</b> joints')]
            for name, joint in self.table.free.items():
                slider = widgets.FloatSlider(
                    value=joint.position, min=joint.lower, max=joint.upper,
                    step=(joint.upper - joint.lower) / 1000 or 0.001, description=name,
                    readout_format='.3f', continuous_update=True,
                    style={'description_width': '12em'},
                    layout=widgets.Layout(width='60%', min_width='26em'))
                slider.observe(lambda change, name=name: self.set(name, change['new']),
                               names='value')
                self._sliders[name] = slider
                rows.append(slider)
            if not self.table.free:
                rows.append(widgets.HTML('no movable joints: only fixed ones'))
            center = widgets.Button(description='Center')
            center.on_click(lambda _button: self.center())
            shuffle = widgets.Button(description='Randomize')
            shuffle.on_click(lambda _button: self.randomize())
            rows.append(widgets.HBox([shuffle, center]))
            self._widget = kit_box(rows)
        return self._widget

    def html_table(self) -> str:
        """The joints as a static table (what a page without a live kernel shows)."""
        rows = ''.join(
            f'<tr><td><code>{html.escape(name)}</code></td><td>{joint.lower:.3f} … '
            f'{joint.upper:.3f}</td><td><b>{joint.position:.3f}</b></td></tr>'
            for name, joint in self.table.free.items())
        return ('<table><tr><th>joint</th><th>range</th><th>position</th></tr>'
                f'{rows}</table>')

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(self.html_table()))
        else:
            display(self.widget)

    def close(self) -> None:
        """Stop publishing and drop the sliders (a cell's next run does it too)."""
        node = self.session.node

        def _destroy() -> None:
            node.destroy_timer(self._timer)
            node.destroy_publisher(self._direct)
            if self._feed is not None:
                node.destroy_publisher(self._feed)

        self.session.run_in_executor(_destroy)
        if self._widget is not None:
            self._widget.close()


def joint_sliders(robot_description: str | None = None, topic: str | None = None,
                  rate: float = 10.0, zeros: Mapping[str, float] | None = None,
                  timeout: float = 5.0) -> JointSliders:
    """A slider per movable joint, publishing JointState `rate` times a second.

    `robot_description`: the URDF text (default: what /robot_description carries).
    `topic`: where to publish (default: /joint_states, or a joint_state_publisher's
    /joint_sliders source when one is running). `zeros`: start positions by joint name.
    """
    return JointSliders(robot_description, topic, rate, zeros, timeout)
