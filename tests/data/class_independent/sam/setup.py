from setuptools import setup

setup(
    name='cliff_guard',
    version='0.0.1',
    packages=['cliff_guard'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/cliff_guard']),
        ('share/cliff_guard', ['package.xml']),
        ('share/cliff_guard/launch', ['launch/cliff.launch.xml']),
        ('share/cliff_guard/config', ['config/cliff.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Sam',
    maintainer_email='sam@example.com',
    description='Chapter 6 lab 1',
    license='MIT',
    entry_points={
        'console_scripts': [
            'ir_array = cliff_guard.ir_array:main',
            'cliff_guard = cliff_guard.guard:main',
            'drive = cliff_guard.drive:main',
        ],
    },
)
