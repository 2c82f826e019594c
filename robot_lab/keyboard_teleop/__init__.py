"""Driving a robot by hand: upstream's teleop_twist_keyboard and its notebook twin.

`keys` is the key map both share (upstream's keys, speeds and banner, as data), `terminal`
the program `ros2 run teleop_twist_keyboard teleop_twist_keyboard`; the notebook pad
`robot_lab.teleop()` is `robot_lab.widgets.teleop`. Importing this package loads nothing.
(Not `robot_lab/teleop/`: a subpackage of that name would shadow `robot_lab.teleop()`.)
"""
