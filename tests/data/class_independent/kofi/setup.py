from setuptools import setup

setup(
    name='park_assist',
    version='0.0.1',
    packages=['park_assist'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/park_assist']),
        ('share/park_assist', ['package.xml']),
        ('share/park_assist/launch', ['launch/park.launch.xml']),
        ('share/park_assist/config', ['config/park.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Kofi',
    maintainer_email='kofi@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'ultrasonic = park_assist.nodes:run_ultrasonic',
            'beeper_logic = park_assist.nodes:run_beeper_logic',
            'buzzer = park_assist.nodes:run_buzzer',
        ],
    },
)
