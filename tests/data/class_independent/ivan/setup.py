from setuptools import setup

setup(
    name='room_heat',
    version='0.0.1',
    packages=['room_heat'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/room_heat']),
        ('share/room_heat', ['package.xml']),
        ('share/room_heat/launch', ['launch/heating.launch.py']),
        ('share/room_heat/config', ['config/heating.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ivan',
    maintainer_email='ivan@example.com',
    description='Chapter 6 lab 1',
    license='GPL-3.0-only',
    entry_points={
        'console_scripts': [
            'thermometer = room_heat.thermometer:main',
            'thermostat = room_heat.thermostat:main',
            'heater = room_heat.heater:main',
        ],
    },
)
