from glob import glob

from setuptools import find_packages, setup

package_name = 'robot_system'

setup(
    name=package_name,
    version='0.0.1',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*')),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Student',
    maintainer_email='student@example.com',
    description='Chapter 6 Lab 1: sensor, controller and actuator nodes',
    license='MIT',
    entry_points={
        'console_scripts': [
            'sensor_node = robot_system.sensor_node:main',
            'controller_node = robot_system.controller_node:main',
            'actuator_node = robot_system.actuator_node:main',
        ],
    },
)
