import os
from glob import glob

from setuptools import setup

package_name = 'air_quality'

setup(
    name=package_name,
    version='0.0.1',
    packages=[package_name],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        (os.path.join('share', package_name, 'launch'), glob('launch/*')),
        (os.path.join('share', package_name, 'config'), glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Yusuf',
    maintainer_email='yusuf@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'co2_sensor = air_quality.co2_sensor:main',
            'vent_controller = air_quality.vent_controller:main',
            'fan_node = air_quality.fan_node:main',
        ],
    },
)
