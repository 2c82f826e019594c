import os
from glob import glob

from setuptools import setup

PKG = 'turtle_guard'

setup(
    name=PKG,
    version='1.2.0',
    packages=[PKG],
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PKG}']),
        (f'share/{PKG}', ['package.xml']),
        (os.path.join('share', PKG, 'launch'), glob(os.path.join('launch', '*.launch.py'))),
        (os.path.join('share', PKG, 'config'), glob(os.path.join('config', '*.yaml'))),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Another Student',
    maintainer_email='another@example.com',
    description='Thermal guard: thermometer, fan logic, fan driver',
    license='Apache-2.0',
    entry_points={'console_scripts': [
        'thermometer = turtle_guard.thermometer:run',
        'fan_logic = turtle_guard.fan_logic:run',
        'fan_driver = turtle_guard.fan_driver:run',
    ]},
)
