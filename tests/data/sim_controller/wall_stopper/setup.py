from glob import glob

from setuptools import find_packages, setup

package_name = 'wall_stopper'

setup(
    name=package_name,
    version='0.0.1',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Student',
    maintainer_email='student@example.com',
    description='Module 2: drive forward and stop before the obstacle',
    license='MIT',
    entry_points={
        'console_scripts': [
            'stopper = wall_stopper.stopper:main',
        ],
    },
)
