from glob import glob

from setuptools import setup

NAME = 'cruise_control'

setup(
    name=NAME,
    version='0.1.0',
    packages=[NAME],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + NAME]),
        ('share/' + NAME, ['package.xml']),
        ('share/' + NAME + '/launch', glob('launch/*.xml')),
        ('share/' + NAME + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Dara',
    maintainer_email='dara@example.com',
    description='Cruise control in one process',
    license='MIT',
    entry_points={'console_scripts': ['cruise_system = cruise_control.system:main']},
)
