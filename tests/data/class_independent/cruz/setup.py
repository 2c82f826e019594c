from setuptools import setup

setup(
    name='drone_alt',
    version='0.0.1',
    packages=['drone_alt'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/drone_alt']),
        ('share/drone_alt', ['package.xml']),
        ('share/drone_alt/launch', ['launch/altitude.launch.xml']),
        ('share/drone_alt/config', ['config/altitude.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Cruz',
    maintainer_email='cruz@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'barometer = drone_alt.barometer:main',
            'altitude_hold = drone_alt.altitude_hold:main',
            'rotors = drone_alt.rotors:main',
        ],
    },
)
