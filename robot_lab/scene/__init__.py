"""RViz's job in the notebook: `robot_lab.scene_view()` draws the robot, TF and sensor data.

`frames` (the TF tree, newest transforms), `meshes` (package:// and file:// to bytes),
`displays` (what each RViz display takes from ROS), `view` (the live view and its thread),
`canvas` (the anywidget and its committed JavaScript bundle, built from `js/scene_view`).
"""
