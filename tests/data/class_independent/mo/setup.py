from setuptools import setup

setup(
    name='crossing',
    version='0.0.1',
    packages=['crossing'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/crossing']),
        ('share/crossing', ['package.xml']),
        ('share/crossing/launch', ['launch/crossing.launch.yaml']),
        ('share/crossing/config', ['config/crossing.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Mo',
    maintainer_email='mo@example.com',
    description='Chapter 6 lab 1',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'queue_camera = crossing.queue_camera:main',
            'signal_logic = crossing.signal_logic:main',
            'lights = crossing.lights:main',
        ],
    },
)
