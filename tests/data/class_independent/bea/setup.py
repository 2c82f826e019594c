from setuptools import setup

setup(
    name='aquarium',
    version='0.0.1',
    packages=['aquarium'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/aquarium']),
        ('share/aquarium', ['package.xml']),
        ('share/aquarium/launch', ['launch/aquarium.launch.yaml']),
        ('share/aquarium/config', ['config/tank.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Bea',
    maintainer_email='bea@example.com',
    description='Chapter 6 lab 1',
    license='BSD-3-Clause',
    entry_points={
        'console_scripts': [
            'water_probe = aquarium.water_probe:main',
            'heater_logic = aquarium.heater_logic:main',
            'heater = aquarium.heater:main',
        ],
    },
)
