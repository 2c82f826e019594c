from setuptools import setup

setup(
    name='wheel_odom',
    version='0.0.1',
    packages=['wheel_odom'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/wheel_odom']),
        ('share/wheel_odom', ['package.xml']),
        ('share/wheel_odom/launch', ['launch/odom.launch.xml']),
        ('share/wheel_odom/config', ['config/odom.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Omar',
    maintainer_email='omar@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'encoder = wheel_odom.encoder:main',
            'speed_estimator = wheel_odom.speed_estimator:main',
            'dashboard = wheel_odom.dashboard:main',
        ],
    },
)
