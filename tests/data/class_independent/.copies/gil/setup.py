from setuptools import setup

setup(
    name='night_lamp',
    version='0.0.1',
    packages=['night_lamp'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/night_lamp']),
        ('share/night_lamp', ['package.xml']),
        ('share/night_lamp/launch', ['launch/lamp.launch.xml']),
        ('share/night_lamp/config', ['config/lamp.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Gus',
    maintainer_email='gus@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'light_meter = night_lamp.light_meter:main',
            'lamp_switch = night_lamp.lamp_switch:main',
            'lamp = night_lamp.lamp:main',
        ],
    },
)
