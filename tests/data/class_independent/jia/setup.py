import os
from glob import glob

from setuptools import setup

package_name = 'tank_level'

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
    maintainer='Jia',
    maintainer_email='jia@example.com',
    description='Chapter 6 lab 1',
    license='BSD-3-Clause',
    entry_points={
        'console_scripts': [
            'level_gauge = tank_level.level_gauge:main',
            'pump_pi = tank_level.pump_pi:main',
            'pump = tank_level.pump:main',
        ],
    },
)
