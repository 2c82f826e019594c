# The students' nbgrader configuration of the robot_lab course (`robot-lab course nbgrader`):
# on a hub, copy it to /etc/jupyter/nbgrader_config.py (or each student's ~/.jupyter/).
c = get_config()  # noqa: F821 (nbgrader's config loader provides it)
c.CourseDirectory.course_id = 'robot_lab'
c.Exchange.root = '/work/wt/i23-semester/.scratch/loop/course/exchange'
