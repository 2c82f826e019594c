from setuptools import setup

setup(
    name='bike_light',
    version='0.0.1',
    packages=['bike_light'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/bike_light']),
        ('share/bike_light', ['package.xml']),
        ('share/bike_light/launch', ['launch/bike.launch.xml']),
        ('share/bike_light/config', ['config/bike.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Wen',
    maintainer_email='wen@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'wheel_speed = bike_light.wheel_speed:main',
            'blink_rate = bike_light.blink_rate:main',
            'led = bike_light.led:main',
        ],
    },
)
