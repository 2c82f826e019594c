from glob import glob

from setuptools import setup

package_name = 'lamp_control'

setup(
    name=package_name,
    version='0.1.0',
    packages=[package_name],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.xml')),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Student',
    maintainer_email='student@example.com',
    description='Street lamp controller',
    license='MIT',
    entry_points={
        'console_scripts': [
            'light_sensor = lamp_control.light_sensor:main',
            'lamp_controller = lamp_control.lamp_controller:main',
            'lamp = lamp_control.lamp:main',
        ],
    },
)
