"""rqt_reconfigure in the notebook: one control per parameter of a running node.

Each control is built from the parameter's descriptor (type, range, read-only), sets the
value through the node's own `set_parameters` service (so the node can refuse it), shows
the node's answer next to the control, and follows changes made by anyone else (a
`ros2 param set` in a terminal, a launch file) through `/parameter_events`.
"""

from __future__ import annotations

import html
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

from robot_lab.errors import GraphError
from robot_lab.widgets.output import WidgetLog, is_headless, owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import HTML, ValueWidget, Widget
    from rcl_interfaces.msg import ParameterEvent
    from rclpy.task import Future

__all__ = ['SetResult', 'Sliders', 'sliders']

# rcl_interfaces/msg/ParameterType
_BOOL, _INTEGER, _DOUBLE, _STRING = 1, 2, 3, 4
_TYPE_NAMES = {_BOOL: 'bool', _INTEGER: 'integer', _DOUBLE: 'double', _STRING: 'string'}


class SetResult(NamedTuple):
    """The node's answer to a set: `successful`, and its `reason` when it refused."""

    successful: bool
    reason: str

    def __repr__(self) -> str:
        # The last line of a cell: say what happened, not SetResult(successful=False, ...).
        return '✓ set' if self.successful else f'✗ refused: {self.reason or "(no reason given)"}'

    def _repr_html_(self) -> str:
        if self.successful:
            return '<span style="color:#1a7f37">✓ set</span>'
        return (f'<span style="color:#cf222e">✗ refused: '
                f'{html.escape(self.reason or "(no reason given)")}</span>')


@dataclass
class _Control:
    name: str
    kind: int
    read_only: bool
    description: str
    widget: ValueWidget | None = None
    status: HTML | None = None


def _node_name(name: str) -> str:
    return name if name.startswith('/') else '/' + name


class Sliders:
    """Controls for every parameter of one node; drivable with `set()` and `values`."""

    def __init__(self, node: str, timeout: float = 5.0, domain_id: int | None = None,
                 call_timeout: float = 3.0) -> None:
        from rclpy.parameter import parameter_value_to_python
        from rclpy.parameter_client import AsyncParameterClient

        from robot_lab.rclpy_session import session

        self.node = _node_name(node)
        self.session = session(domain_id)
        self.call_timeout = call_timeout
        self.log = WidgetLog(max_lines=20, height='5em')
        self._lock = threading.Lock()
        self._updating = threading.local()
        self._widget: Widget | None = None
        self.client = self.session.run_in_executor(
            lambda: AsyncParameterClient(self.session.node, self.node))
        if not self.client.wait_for_services(timeout_sec=timeout):
            raise GraphError(
                f"Node not found: no parameter services of '{self.node}' within {timeout:g} s",
                fix='start the node first and check its name with `robot-lab node list`',
            )
        # Through the graph's parameter calls: they resend a request lost right after
        # discovery, which these first three calls are.
        from rcl_interfaces.srv import DescribeParameters, GetParameters, ListParameters

        from robot_lab.graph.parameters import call_parameter_service

        def call(service: str, srv_type: Any, request: Any) -> Any:
            return call_parameter_service(self.session, self.node, service, srv_type,
                                          request, timeout=self.call_timeout)

        names = sorted(call('list_parameters', ListParameters,
                            ListParameters.Request()).result.names)
        described = call('describe_parameters', DescribeParameters,
                         DescribeParameters.Request(names=names)).descriptors
        got = call('get_parameters', GetParameters, GetParameters.Request(names=names)).values
        self.descriptors = dict(zip(names, described, strict=True))
        self._values: dict[str, object] = {
            name: parameter_value_to_python(value) for name, value in zip(names, got, strict=True)
        }
        self.controls = {
            name: _Control(name, int(d.type), bool(d.read_only), d.description)
            for name, d in self.descriptors.items()
        }
        self.last_result: dict[str, SetResult] = {}
        from rcl_interfaces.msg import ParameterEvent

        self._events = self.session.run_in_executor(
            lambda: self.session.node.create_subscription(
                ParameterEvent, '/parameter_events', self.log.guard(self._on_event), 100))
        owned_by_cell(self)

    def _call(self, future: Future, what: str) -> Any:
        return self.session.wait_future(future, self.call_timeout, f'{self.node} {what}')

    # -- driving from code -----------------------------------------------------------
    @property
    def values(self) -> dict[str, object]:
        """Parameter name -> value as the node last reported it."""
        with self._lock:
            return dict(self._values)

    def set(self, name: str, value: Any) -> SetResult:
        """Ask the node to take `value`; its answer shows next to the control and is returned."""
        from rclpy.parameter import Parameter

        control = self.controls.get(name)
        if control is None:
            raise GraphError(f"node '{self.node}' has no parameter '{name}'",
                             fix=f'its parameters are: {", ".join(self.controls)}')
        value = _coerce(value, control.kind)
        future = self.client.set_parameters([Parameter(name, value=value)])
        try:
            results = self._call(future, f'set_parameters {name}').results
            result = SetResult(bool(results[0].successful), str(results[0].reason))
        except GraphError as err:
            result = SetResult(False, err.message)
        self.last_result[name] = result
        if result.successful:
            self._take(name, value)
        self._show(name, result)
        return result

    def wait_for(self, name: str, value: object, timeout: float = 5.0) -> bool:
        """Block until the node reports `name == value` (e.g. set elsewhere); True if so."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.values.get(name) == value:
                return True
            time.sleep(0.02)
        return False

    # -- following /parameter_events -------------------------------------------------
    def _on_event(self, event: ParameterEvent) -> None:
        from rclpy.parameter import parameter_value_to_python

        if event.node != self.node:
            return
        for param in [*event.new_parameters, *event.changed_parameters]:
            self._take(param.name, parameter_value_to_python(param.value))

    def _take(self, name: str, value: object) -> None:
        with self._lock:
            self._values[name] = value
        control = self.controls.get(name)
        if control is not None and control.widget is not None and control.widget.value != value:
            self._updating.active = True  # the widget follows the node; do not send it back
            try:
                control.widget.value = value
            finally:
                self._updating.active = False

    # -- the widget ------------------------------------------------------------------
    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            rows = [widgets.HTML(f'<b>{html.escape(self.node)}</b> parameters')]
            for name, control in self.controls.items():
                control.widget = self._make_control(control, self.values.get(name))
                # shown once the node has answered: an empty one would take a wrapped line
                control.status = widgets.HTML(layout=widgets.Layout(
                    width='40%', min_width='14em', display='none'))
                # a comm handler's exception would only reach the server's log: show it here
                control.widget.observe(self.log.guard(self._user_changed(name)), names='value')
                # In a narrow notebook the node's answer wraps below the control rather
                # than squeezing the slider's track to nothing.
                rows.append(widgets.HBox([control.widget, control.status],
                                         layout=widgets.Layout(flex_flow='row wrap')))
            from robot_lab.widgets.canvas import kit_box

            # greyed out and labelled when the kernel restarts; a drag leaves no focus
            self._widget = kit_box([*rows, self.log.widget])
        return self._widget

    def _make_control(self, control: _Control, value: Any) -> Any:
        import ipywidgets as widgets

        descriptor = self.descriptors[control.name]
        common: dict[str, Any] = {
            'description': control.name,
            'disabled': control.read_only,
            'tooltip': control.description or None,
            'style': {'description_width': '11em'},
            'layout': widgets.Layout(width='55%', min_width='26em'),
        }
        if control.kind == _BOOL:
            # A checkbox's name is its label on the right: as wide as it needs, so a long
            # one (start_type_description_service) is not cut to 'start_type_descr…'.
            common['layout'] = widgets.Layout(width='auto', min_width='26em', flex='0 0 auto')
            return widgets.Checkbox(value=bool(value), indent=True, **common)
        if control.kind == _INTEGER and descriptor.integer_range:
            rng = descriptor.integer_range[0]
            return widgets.IntSlider(value=int(value), min=rng.from_value, max=rng.to_value,
                                     step=max(1, rng.step), continuous_update=False, **common)
        if control.kind == _INTEGER:
            return widgets.IntText(value=int(value), **common)
        if control.kind == _DOUBLE and descriptor.floating_point_range:
            rng = descriptor.floating_point_range[0]
            step = rng.step or (rng.to_value - rng.from_value) / 100
            return widgets.FloatSlider(value=float(value), min=rng.from_value,
                                       max=rng.to_value, step=step, readout_format='.2f',
                                       continuous_update=False, **common)
        if control.kind == _DOUBLE:
            return widgets.FloatText(value=float(value), **common)
        if control.kind == _STRING:
            return widgets.Text(value=str(value), continuous_update=False, **common)
        common['disabled'] = True  # arrays and byte arrays: shown, set them from code
        return widgets.Text(value=repr(value), **common)

    def _user_changed(self, name: str) -> Callable[[dict[str, object]], None]:
        def _changed(change: dict[str, object]) -> None:
            if getattr(self._updating, 'active', False):
                return
            result = self.set(name, change['new'])
            if not result.successful:
                self._take(name, self.values.get(name))  # put the control back

        return _changed

    def _show(self, name: str, result: SetResult) -> None:
        control = self.controls[name]
        if control.status is None:
            return
        control.status.layout.display = None
        if result.successful:
            control.status.value = '<span style="color:#1a7f37">✓ set</span>'
        else:
            control.status.value = (f'<span style="color:#cf222e">✗ refused: '
                                    f'{html.escape(result.reason)}</span>')

    def html_table(self) -> str:
        """The parameters as a static table (what a page without a live kernel shows)."""
        rows = []
        for name, control in self.controls.items():
            descriptor = self.descriptors[name]
            span = ''
            if descriptor.integer_range:
                rng = descriptor.integer_range[0]
                span = f'{rng.from_value} … {rng.to_value}'
            elif descriptor.floating_point_range:
                frng = descriptor.floating_point_range[0]
                span = f'{frng.from_value:g} … {frng.to_value:g}'
            result = self.last_result.get(name)
            note = '' if result is None else ('✓ set' if result.successful else
                                              f'✗ refused: {result.reason}')
            cells = [f'<code>{html.escape(name)}</code>',
                     html.escape(_TYPE_NAMES.get(control.kind, 'other')), span,
                     f'<b>{html.escape(repr(self.values.get(name)))}</b>',
                     html.escape(control.description), html.escape(note)]
            rows.append('<tr>' + ''.join(f'<td style="text-align:left">{c}</td>'
                                         for c in cells) + '</tr>')
        head = ''.join(f'<th style="text-align:left">{h}</th>' for h in
                       ('parameter', 'type', 'range', 'value', 'description', ''))
        return (f'<div><b>{html.escape(self.node)}</b> parameters<table><thead><tr>{head}'
                f'</tr></thead><tbody>{"".join(rows)}</tbody></table></div>')

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(self.html_table()))
        else:
            display(self.widget)

    def __repr__(self) -> str:
        values = ', '.join(f'{k}={v!r}' for k, v in self.values.items())
        return f'<Sliders {self.node}: {values}>'

    def close(self) -> None:
        """Stop following events and drop the service clients."""
        node = self.session.node

        def _destroy() -> None:
            node.destroy_subscription(self._events)
            for value in vars(self.client).values():
                if value in node.clients:
                    node.destroy_client(value)

        self.session.run_in_executor(_destroy)


def _coerce(value: Any, kind: int) -> Any:
    """A slider gives 2 where a double is declared: send 2.0, as the node expects."""
    if kind == _DOUBLE and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if kind == _INTEGER and isinstance(value, float) and value.is_integer():
        return int(value)
    return value


def sliders(node: str, timeout: float = 5.0, domain_id: int | None = None) -> Sliders:
    """Controls for the parameters of a running node: `robot_lab.sliders('/sensor')`."""
    return Sliders(node, timeout=timeout, domain_id=domain_id)
