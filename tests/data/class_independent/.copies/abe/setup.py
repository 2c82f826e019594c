from setuptools import setup

package_name = 'wall_keeper'

setup(
    name=package_name,
    version='0.1.0',
    packages=[package_name],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', ['launch/wall.launch.xml']),
        ('share/' + package_name + '/config', ['config/wall.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ana',
    maintainer_email='ana@example.com',
    description='Wall keeping robot',
    license='MIT',
    entry_points={
        'console_scripts': [
            'range_finder = wall_keeper.range_finder:main',
            'keeper = wall_keeper.keeper:main',
            'wheels = wall_keeper.wheels:main',
        ],
    },
)
