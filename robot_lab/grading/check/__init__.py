"""What a notebook's check cell calls: real checks of the running system, one line each.

Every check looks at the real graph (nodes, topics, parameters, logs, files), waits a
bounded time for it to become true, prints one deterministic `✓ …` line when it is, and
otherwise raises CheckError: what was expected, what was seen, what to try. A failing
check is a failing cell, so nbval fails with it. Checks return nothing: a check cell's
output is only its ✓ lines, the same on every run (nbval compares it).

One module per thing checked (`graph`, `parameters`, `package`, `output`, `description`, `sim`,
`tf2`, `unit_tests` with its pytest plugin `wrong_node`; `base` holds the error and the
bounded wait);
notebooks use them all as `check.<name>`. The grader loads this package afresh from the
kit's files for each check cell (answer_key).
"""

from __future__ import annotations

from robot_lab.grading.check.base import CheckError, eventually
from robot_lab.grading.check.description import (
    point_in_frame,
    transform_broadcast,
    translation_is,
    urdf_tree,
    xacro_expands,
)
from robot_lab.grading.check.graph import (
    graph_matches,
    node_subscribes,
    nodes_running,
    responds,
    topic_publishes,
    topic_rate,
    topics_exist,
    wiring_is,
)
from robot_lab.grading.check.output import (
    answer_is,
    bag_contains,
    command_drives,
    command_prints,
    first_time,
    full_marks,
    logs_contain,
    no_errors,
    plot_shows,
)
from robot_lab.grading.check.package import (
    answered,
    files_exist,
    launch_file_nodes,
    node_starts,
    package_built,
    readme_explains,
    setup_py,
    stop_node,
)
from robot_lab.grading.check.parameters import (
    param_applied,
    param_count,
    param_described,
    param_equals,
    param_file_accepted,
    param_refused,
)
from robot_lab.grading.check.sim import (
    bridged,
    gazebo_tags,
    reacts_to_scan,
    stops_before_obstacle,
)
from robot_lab.grading.check.tf2 import (
    echo_prints,
    follows,
    lookup_returns,
    time_travel,
    transform_is,
)
from robot_lab.grading.check.unit_tests import tests_catch, tests_pass

__all__ = [
    'CheckError',
    'answer_is',
    'answered',
    'bag_contains',
    'bridged',
    'command_drives',
    'command_prints',
    'echo_prints',
    'eventually',
    'files_exist',
    'first_time',
    'follows',
    'full_marks',
    'gazebo_tags',
    'graph_matches',
    'launch_file_nodes',
    'logs_contain',
    'lookup_returns',
    'no_errors',
    'node_starts',
    'node_subscribes',
    'nodes_running',
    'package_built',
    'param_applied',
    'param_count',
    'param_described',
    'param_equals',
    'param_file_accepted',
    'param_refused',
    'plot_shows',
    'point_in_frame',
    'reacts_to_scan',
    'readme_explains',
    'responds',
    'setup_py',
    'stop_node',
    'stops_before_obstacle',
    'tests_catch',
    'tests_pass',
    'time_travel',
    'topic_publishes',
    'topic_rate',
    'topics_exist',
    'transform_broadcast',
    'transform_is',
    'translation_is',
    'urdf_tree',
    'wiring_is',
    'xacro_expands',
]
