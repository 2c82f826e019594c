import os
from glob import glob

from setuptools import setup

package_name = 'arm_joint'

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
    maintainer='Amir',
    maintainer_email='amir@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'joint_encoder = arm_joint.joint_encoder:main',
            'joint_pd = arm_joint.joint_pd:main',
            'joint_motor = arm_joint.joint_motor:main',
        ],
    },
)
