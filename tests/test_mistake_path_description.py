"""The mistake path of 12 (the robot's body: URDF, xacro, tf2), as tests/test_mistake_path.py
walks 01–06 (its docstring says what a walk promises), in a workspace of its own: 12 builds a
package of its own (my_robot_description) and stands alone.

Its wrong answers are Chapter 7's mistakes: a joint on the wrong parent link, a revolute
joint without limits, the frames of tf2_echo read the other way round, a macro called once,
a transform with no stamp (a stamp from the past), a quaternion that is not normalised or
built from the whole angle, a lookup before the transform exists (in __init__: in a callback
it is a race, whose message tests/test_description_checks.py checks), a lookup with target
and source swapped, a point left in the sensor's frame.
"""

from __future__ import annotations

from mistake_walk import standalone_walk

NAME = '12_robot_description'

course, test_every_answer_cell_walks_its_ladder_then_runs_again = standalone_walk(NAME)
