import os
from glob import glob

from setuptools import setup

package_name = 'conveyor'

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
    maintainer='Hana',
    maintainer_email='hana@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'count_sensor = conveyor.count_sensor:main',
            'belt_controller = conveyor.belt_controller:main',
            'belt_motor = conveyor.belt_motor:main',
        ],
    },
)
