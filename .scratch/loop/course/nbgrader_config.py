# nbgrader's configuration of the robot_lab course (written by `robot-lab course nbgrader`).
c = get_config()  # noqa: F821 (nbgrader's config loader provides it)
c.CourseDirectory.course_id = 'robot_lab'
c.CourseDirectory.root = '/work/wt/i23-semester/.scratch/loop/course'
# Where release_assignment puts assignments and students' submit puts their work: every
# student must be able to reach it (on a hub, a shared folder such as /srv/nbgrader/exchange).
c.Exchange.root = '/work/wt/i23-semester/.scratch/loop/course/exchange'
# A check that starts ROS nodes and watches them needs more than nbgrader's 30 s per cell.
c.ExecutePreprocessor.timeout = 120
