"""tf2_tools, as robot_lab provides it (view_frames: robot_lab.tf2.view_frames)."""
