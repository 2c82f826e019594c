from setuptools import setup

setup(
    name='pressure_cooker',
    version='0.0.1',
    packages=['pressure_cooker'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/pressure_cooker']),
        ('share/pressure_cooker', ['package.xml']),
        ('share/pressure_cooker/launch', ['launch/cooker.launch.py']),
        ('share/pressure_cooker/config', ['config/cooker.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Zoe',
    maintainer_email='zoe@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'manometer = pressure_cooker.manometer:main',
            'valve_control = pressure_cooker.valve_control:main',
            'relief_valve = pressure_cooker.relief_valve:main',
        ],
    },
)
