"""The mistake path of 11 (tf2 on turtlesim), as tests/test_mistake_path.py walks 01–06 (its
docstring says what a walk promises), in a workspace of its own: 11 builds a package of its
own (learning_tf2_py) and stands alone.

Its wrong answers are the tf2 mistakes a student meets: a frame name with a leading `/`,
parent and child swapped, roll/pitch/yaw written into the quaternion (not normalised), a
transform stamped 0 (looked up at the time now), a lookup as the listener starts with no
`timeout=`, target and source swapped, a carrot under the wrong parent, and a past time
given as an absolute one (`Time(seconds=5.0)`, extrapolation into the past).
"""

from __future__ import annotations

from mistake_walk import standalone_walk

NAME = '11_tf2_turtlesim'

course, test_every_answer_cell_walks_its_ladder_then_runs_again = standalone_walk(NAME)
