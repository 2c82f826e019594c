"""RViz's job in the notebook: `robot_lab.scene_view()` draws the robot, TF and sensor data.

`frames` (the TF tree, newest transforms), `meshes` (package:// and file:// to bytes),
`displays` (what each RViz display takes from ROS), `view` (the live view and its tick),
`subscriptions` (what the view hears from ROS, and with which QoS), `camera` (where the
view looks from), `picture` (the still drawn when no browser is there), `canvas` (the
anywidget and its committed JavaScript bundle, built from `js/scene_view`).

A simulated world is drawn as markers (`view.show_markers('world', [Marker, ...])`: boxes,
cylinders, spheres, meshes by package:// or file://) and its lidar as a topic
(`view.add('/scan')`); a new kind of display is a class in `displays` and its twin in
`js/scene_view/src/displays.js`.
"""
