import os
from glob import glob

from setuptools import setup

package_name = 'auto_door'

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
    maintainer='Xia',
    maintainer_email='xia@example.com',
    description='Chapter 6 lab 1',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'presence_sensor = auto_door.presence_sensor:main',
            'door_logic = auto_door.door_logic:main',
            'door_motor = auto_door.door_motor:main',
        ],
    },
)
