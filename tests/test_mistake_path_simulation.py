"""The mistake path of 13 (the robot in the simulator), as tests/test_mistake_path.py walks
01–06 (its docstring says what a walk promises), in a workspace of its own: 13 builds a
package of its own (my_robot_sim) and stands alone.

Its wrong answers are Module 2's mistakes: DiffDrive given the wheel links instead of their
joints, the wheel's diameter as its radius, a lidar on a gz topic nobody bridges, /scan left
out of the bridge (the simulator publishes it: the check names the bridge line), /cmd_vel
bridged the wrong way, `ranges[0]` taken as straight ahead (it is the beam at angle_min,
behind), an increment taken in degrees, a speed never clamped, and a controller without
`use_sim_time` (judged in the simulator, by its ground truth).
"""

from __future__ import annotations

from mistake_walk import standalone_walk

NAME = '13_simulation'

course, test_every_answer_cell_walks_its_ladder_then_runs_again = standalone_walk(NAME)
