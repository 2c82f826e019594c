from setuptools import setup

setup(
    name='servo_knob',
    version='0.0.1',
    packages=['servo_knob'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/servo_knob']),
        ('share/servo_knob', ['package.xml']),
        ('share/servo_knob/launch', ['launch/knob.launch.xml']),
        ('share/servo_knob/config', ['config/knob.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Quinn',
    maintainer_email='quinn@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'pot = servo_knob.pot:main',
            'mapper = servo_knob.mapper:main',
            'servo = servo_knob.servo:main',
        ],
    },
)
