"""ROS bags: record topics into rosbag2 bags, inspect them, play them back, read columns.

One module per part of rosbag2: `record` (ros2 bag record), `play` (ros2 bag play, with
`timeline`, the bag's clock, and `delivery`, getting messages to subscribers),
`info` (ros2 bag info), `reindex` (ros2 bag reindex), `read` (opening bags and reading
a topic into columns for plots), `writer` (the storage files).
"""

from __future__ import annotations

from robot_lab.bag.info import BagInfo, TopicInfo, bag_info, format_info
from robot_lab.bag.play import Player, play
from robot_lab.bag.read import TopicColumns, open_bag, read_topic
from robot_lab.bag.record import Recorder, default_bag_name, record
from robot_lab.bag.reindex import reindex

__all__ = [
    'BagInfo',
    'Player',
    'Recorder',
    'TopicColumns',
    'TopicInfo',
    'bag_info',
    'default_bag_name',
    'format_info',
    'open_bag',
    'play',
    'read_topic',
    'record',
    'reindex',
]
