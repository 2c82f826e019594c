"""robot_lab's ament_copyright: the copyright/license check of ROS 2 packages' tests.

PyPI has ament_flake8 and ament_pep257 but not ament_copyright, which the `test/` of every
`ros2 pkg create --build-type ament_python` package imports. This one keeps its command
line, its messages and its exit codes (ament_lint's ament_copyright, Jazzy) for the
licenses students use: Apache-2.0 (`apache2`) and MIT (`mit`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

__all__ = ['COPYRIGHT_NAMES', 'LICENSES', 'UNKNOWN_IDENTIFIER', 'License']

UNKNOWN_IDENTIFIER = '<unknown>'

_TEMPLATES = Path(__file__).resolve().parents[1] / 'robot_lab' / 'pkg' / 'templates'

APACHE2_HEADER = """\
{copyright}

Licensed under the Apache License, Version 2.0 (the "License");
you may not use this file except in compliance with the License.
You may obtain a copy of the License at

    http://www.apache.org/licenses/LICENSE-2.0

Unless required by applicable law or agreed to in writing, software
distributed under the License is distributed on an "AS IS" BASIS,
WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
See the License for the specific language governing permissions and
limitations under the License.
"""


@dataclass(frozen=True)
class License:
    """A license ament_copyright recognises: its header in sources, its LICENSE file."""

    name: str
    header: str  # with a {copyright} line first
    license_file: str


def _read(name: str) -> str:
    path = _TEMPLATES / 'ament_python' / name
    return path.read_text() if path.is_file() else ''


_MIT_TEXT = _read('LICENSE.MIT.tmpl')

LICENSES: dict[str, License] = {
    'apache2': License('Apache License, Version 2.0', APACHE2_HEADER,
                       _read('LICENSE.Apache-2.0.tmpl')),
    'mit': License('MIT License', '{copyright}\n\n' + _MIT_TEXT, _MIT_TEXT),
}

COPYRIGHT_NAMES: dict[str, str] = {'osrf': 'Open Source Robotics Foundation, Inc.'}
