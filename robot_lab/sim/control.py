"""Pause, step and reset the running simulation: the kit's `/world/<name>/control`.

Gazebo takes gz.msgs.WorldControl on its world-control service (`gz service -s
/world/<name>/control --reqtype gz.msgs.WorldControl ... --req 'pause: true'`); the kit
takes the same fields over its socket (`transport`), from Python or a notebook:
`world_control(pause=True)`, `world_control(step=100)`, `world_control(reset=True)`.
`gz_topics()` lists what the simulation publishes and takes (`gz topic -l`).
"""

from __future__ import annotations

from typing import Any

from robot_lab.sim.transport import connect, socket_path
from robot_lab.sim.xml_tree import SimulationError

__all__ = ['bridge_hint', 'gz_topics', 'world_control']


def _request(frame: dict[str, Any]) -> dict[str, Any]:
    connection = connect()
    if connection is None:
        raise SimulationError(f'no simulation runs in this partition ({socket_path()})',
                              fix='start one: ros2 launch ros_gz_sim gz_sim.launch.py '
                                  'gz_args:="-r empty.sdf"')
    try:
        connection.send({**frame, 'id': 1})
        while (reply := connection.receive()) is not None:
            if reply.get('op') == 'reply':
                if reply.get('ok') is False:
                    raise SimulationError(str(reply.get('error')),
                                          fix='name the world the simulation runs')
                data: dict[str, Any] = reply.get('data') or {}
                return data
    finally:
        connection.close()
    raise SimulationError('the simulation closed the connection before it answered')


def world_control(pause: bool | None = None, step: int = 0, reset: bool = False,
                  world: str = '', run_to: float = 0.0) -> dict[str, Any]:
    """Pause or run, advance `step` steps (also while paused), reset to time 0, run until
    sim time `run_to` s and pause there; returns `{'paused': ..., 'iterations': ...}` after
    the request. `world`, if given, must be the one the simulation runs (as
    /world/<name>/control names it)."""
    request: dict[str, Any] = {'op': 'control', 'multi_step': step, 'reset': reset,
                               'world': world}
    if run_to:
        request['run_to_sim_time'] = round(run_to * 1e9)
    if pause is not None:
        request['pause'] = pause
    return _request(request)


def gz_topics() -> dict[str, str]:
    """Topic -> gz message type, of what the simulation publishes or subscribes to."""
    return {str(k): str(v) for k, v in _request({'op': 'topics'}).items()}


def bridge_hint(ros_topic: str) -> str | None:
    """When a ROS topic has no publisher but the simulation publishes a gz topic of that
    name: the parameter_bridge argument that would bridge it (None if it publishes none)."""
    from robot_lab.sim.conversions import PAIRS

    name = ros_topic if ros_topic.startswith('/') else '/' + ros_topic
    kind = gz_topics().get(name)
    if not kind:
        return None
    ros_type = next((r for (r, g), ways in PAIRS.items() if g == kind and 'gz_to_ros' in ways),
                    None)
    if ros_type is None:
        return (f"the simulator publishes gz topic {name} ({kind}), which robot_lab's bridge "
                f'does not convert')
    return (f'nothing publishes {ros_topic}: the simulator publishes gz topic {name}; bridge it '
            f'with: ros2 run ros_gz_bridge parameter_bridge {name}@{ros_type}[{kind}')
