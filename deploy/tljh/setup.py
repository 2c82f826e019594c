"""The robot_lab plugin for The Littlest JupyterHub (see docs/deploy.md)."""
from setuptools import setup

setup(
    name='tljh-robot-lab',
    version='0.1.0',
    py_modules=['tljh_robot_lab'],
    entry_points={'tljh': ['robot_lab = tljh_robot_lab']},
)
