"""Which students' code is suspiciously alike: `OUT/similarity.html`, with copydetect.

Each student's Python (nodes, launch files, setup.py) is joined into one file and
fingerprinted by copydetect (winnowing over tokens with names replaced, so renamed
identifiers and reordered functions still match). The code every ROS 2 Python package
shares is given to it as boilerplate and never counts: the kit's package template, the
standard `setup.py` and `main()`, the usual imports and launch-file skeletons. The report
names only the pairs above the threshold, with the shared code highlighted.
"""

from __future__ import annotations

import html
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from robot_lab.grading.package.submission import Submission, copy_submission

__all__ = ['SimilarPair', 'similar_pairs', 'similarity_report']

THRESHOLD = 0.5  # share of a student's (non-boilerplate) code found in the other's
_TEMPLATES = Path(__file__).resolve().parents[2] / 'pkg' / 'templates' / 'ament_python'
_SKIP = {'build', 'install', 'log', 'test', '__pycache__'}

# What a student writes because ROS 2 says so, not because they thought of it.
BOILERPLATE = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String, Float32, Float64, Int32, Bool
from geometry_msgs.msg import Twist
import random
import math
import os
from glob import glob
from setuptools import find_packages, setup
from launch import LaunchDescription
from launch_ros.actions import Node
from ament_index_python.packages import get_package_share_directory


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.shutdown()


def main(args=None):
    rclpy.init(args=args)
    node = Node()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()


class Node(Node):
    def __init__(self):
        super().__init__('node')
        self.declare_parameter('name', 1.0)
        self.value = self.get_parameter('name').value
        self.declare_parameter('name', 1.0)
        self.value = self.get_parameter('name').get_parameter_value().double_value
        self.publisher = self.create_publisher(String, 'topic', 10)
        self.subscription = self.create_subscription(String, 'topic', self.callback, 10)
        self.timer = self.create_timer(1.0 / self.value, self.callback)
        self.get_logger().info('started')

    def callback(self, msg):
        self.get_logger().info(f'Received: {msg.data}')


package_name = 'name'

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        (os.path.join('share', package_name, 'launch'), glob('launch/*')),
        (os.path.join('share', package_name, 'config'), glob('config/*.yaml')),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='name',
    maintainer_email='name@example.com',
    description='description',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'node = package.node:main',
        ],
    },
)


def generate_launch_description():
    config = os.path.join(get_package_share_directory('package'), 'config', 'params.yaml')
    return LaunchDescription([
        Node(package='package', executable='node', name='node', output='screen',
             parameters=[config]),
    ])
"""


@dataclass(frozen=True)
class SimilarPair:
    a: str
    b: str
    similarity: float  # the larger of the two directions, 0..1
    code_a: str  # highlighted HTML
    code_b: str


def _student_code(submission: Submission, work: Path) -> str:
    folder = copy_submission(submission, work / 'unpacked' / submission.student)
    parts = []
    for path in sorted(folder.rglob('*.py')):
        rel = path.relative_to(folder)
        if _SKIP & set(rel.parts) or not path.is_file():
            continue
        text = path.read_text(errors='replace')[:200_000]
        parts.append(f'# ---- {rel} ----\n{text}\n')
    return ''.join(parts)


def similar_pairs(submissions: Sequence[Submission], threshold: float = THRESHOLD,
                  ) -> list[SimilarPair]:
    """Pairs of students whose joined Python code overlaps beyond `threshold`."""
    from copydetect import CopyDetector  # type: ignore[import-untyped]

    with tempfile.TemporaryDirectory(prefix='robot_lab_similarity_') as tmp:
        work = Path(tmp)
        code_dir, boiler = work / 'code', work / 'boilerplate'
        code_dir.mkdir()
        boiler.mkdir()
        owner: dict[str, str] = {}
        for i, sub in enumerate(submissions):
            try:
                text = _student_code(sub, work)
            except Exception:  # an unreadable entry is graded elsewhere, not compared
                continue
            if text.strip():
                target = code_dir / f's{i}' / 'code.py'
                target.parent.mkdir()
                target.write_text(text)
                owner[str(target)] = sub.student
        (boiler / 'ros2.py').write_text(BOILERPLATE)
        for template in _TEMPLATES.glob('*.py.tmpl'):
            (boiler / template.name.replace('.tmpl', '')).write_text(template.read_text())
        if len(owner) < 2:
            return []
        detector = CopyDetector(test_dirs=[str(code_dir)], ref_dirs=[str(code_dir)],
                                boilerplate_dirs=[str(boiler)], extensions=['py'],
                                display_t=threshold, autoopen=False, silent=True,
                                out_file=str(work / 'unused.html'))
        detector.run()
        pairs: dict[frozenset[str], SimilarPair] = {}
        for sim_a, sim_b, file_a, file_b, code_a, code_b, _overlap in (
                detector.get_copied_code_list()):
            a, b = owner.get(str(file_a)), owner.get(str(file_b))
            if a is None or b is None or a == b:
                continue
            key = frozenset((a, b))
            score = float(max(sim_a, sim_b))
            if key not in pairs or score > pairs[key].similarity:
                pairs[key] = SimilarPair(a, b, score, code_a, code_b)
    return sorted(pairs.values(), key=lambda p: -p.similarity)


def similarity_report(submissions: Sequence[Submission], out: Path,
                      threshold: float = THRESHOLD) -> list[SimilarPair]:
    """Write the HTML report of the suspicious pairs (none: a page that says so)."""
    pairs = similar_pairs(submissions, threshold)
    rows = ''.join(
        f'<tr data-a="{html.escape(p.a)}" data-b="{html.escape(p.b)}">'
        f'<td><a href="#p{i}">{html.escape(p.a)}</a></td><td>{html.escape(p.b)}</td>'
        f'<td>{p.similarity:.0%}</td></tr>' for i, p in enumerate(pairs))
    details = ''.join(
        f'<h2 id="p{i}">{html.escape(p.a)} &harr; {html.escape(p.b)} ({p.similarity:.0%})</h2>'
        f'<div class="pair"><div><h3>{html.escape(p.a)}</h3><pre>{p.code_a}</pre></div>'
        f'<div><h3>{html.escape(p.b)}</h3><pre>{p.code_b}</pre></div></div>'
        for i, p in enumerate(pairs))
    summary = (f'{len(pairs)} pair(s) of students share more than {threshold:.0%} of their '
               'code' if pairs else f'No pair of students shares more than {threshold:.0%} '
               'of their code')
    page = (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>Similarity report</title>'
        '<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}'
        'td,th{border:1px solid #ccc;padding:.2em .6em}.pair{display:flex;gap:1em}'
        '.pair>div{flex:1;min-width:0}pre{background:#f6f8fa;padding:.5em;overflow-x:auto;'
        'font-size:85%}.highlight-red{background:#fca5a5}.highlight-green{background:#86efac}'
        '</style></head><body>\n<h1>Similarity report</h1>\n'
        f'<p>{len(submissions)} submissions compared with copydetect. {summary}. Code every '
        'ROS 2 Python package shares (the package template, setup.py, the standard main(), '
        'usual imports) is excluded. A high score is a reason to look, not a verdict.</p>\n'
        + (f'<table><tr><th>student</th><th>student</th><th>similarity</th></tr>{rows}'
           '</table>\n' if pairs else '')
        + details + '</body></html>\n')
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(page)
    return pairs
