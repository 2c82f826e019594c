"""`ros2 pkg create`: the same files, the same printed lines.

ament_python packages get the kit's two extras the labs need: `with_launch` and
`with_config` add launch/ and config/ *and* the data_files entries that install them, the
step students forget in Lab 1.3 Part 6. ament_cmake packages get Jazzy's template (an
interface package is one; the kit's venv has CMake and the rosidl generators). Creation is
planned first (data), then written; the CLI prints each step as ros2 does.
"""

from __future__ import annotations

import getpass
import keyword
import os
import re
import shutil
import subprocess
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.errors import PackageError

__all__ = [
    'AMENT_LICENSES',
    'PackagePlan',
    'Step',
    'create_package',
    'plan_package',
    'validate_package_name',
]

_TEMPLATES = Path(__file__).with_name('templates') / 'ament_python'

DEFAULT_DESCRIPTION = 'TODO: Package description'
DEFAULT_LICENSE = 'TODO: License declaration'
TEST_DEPENDENCIES = ('ament_copyright', 'ament_flake8', 'ament_pep257', 'python3-pytest')
CMAKE_TEST_DEPENDENCIES = ('ament_lint_auto', 'ament_lint_common')

# The license identifiers ament_copyright knows (ros2 pkg create lists them); the kit
# ships the text of the short ones only.
AMENT_LICENSES = (
    'Apache-2.0', 'BSL-1.0', 'BSD-2.0', 'BSD-2-Clause', 'BSD-3-Clause',
    'GPL-3.0-only', 'LGPL-3.0-only', 'MIT', 'MIT-0',
)
_LICENSE_TEXTS = {'MIT': 'LICENSE.MIT.tmpl', 'Apache-2.0': 'LICENSE.Apache-2.0.tmpl'}

# REP 144: lowercase letter first, then lowercase letters, digits and single underscores.
_REP144 = re.compile(r'^[a-z][a-z0-9]*(_[a-z0-9]+)*$')


@dataclass(frozen=True)
class Step:
    """One thing `ros2 pkg create` does and prints: a folder, a file, or a note."""

    kind: str  # 'folder', 'file', 'license' (written without a line) or 'note'
    path: str  # as printed: relative to the destination given (./NAME/setup.py)
    content: str = ''
    mode: int = 0o644

    @property
    def message(self) -> str:
        if self.kind == 'folder':
            return f'creating folder {self.path}'
        if self.kind == 'file':
            return f'creating {self.path}'
        return self.content if self.kind == 'note' else ''


@dataclass
class PackagePlan:
    """Everything `create_package` will write, and the header ros2 pkg create prints."""

    name: str
    destination: str
    build_type: str
    dependencies: list[str]
    node_name: str | None
    maintainer_name: str
    maintainer_email: str
    license: str
    description: str
    steps: list[Step] = field(default_factory=list)
    warning: str | None = None

    @property
    def package_dir(self) -> Path:
        return Path(self.destination, self.name)

    def summary_lines(self) -> list[str]:
        """The header `ros2 pkg create` prints before touching the disk."""
        lines = [
            'going to create a new package',
            f'package name: {self.name}',
            f'destination directory: {os.path.abspath(self.destination)}',
            'package format: 3',
            'version: 0.0.0',
            f'description: {self.description}',
            f'maintainer: {[f"{self.maintainer_name} <{self.maintainer_email}>"]}',
            f'licenses: {[self.license]}',
            f'build type: {self.build_type}',
            f'dependencies: {self.dependencies}',
        ]
        if self.node_name:
            lines.append(f'node_name: {self.node_name}')
        return lines

    def write(self, on_step: Callable[[Step], None] | None = None) -> Path:
        """Create the folders and files in order; `on_step` sees each before it happens."""
        for step in self.steps:
            if on_step is not None:
                on_step(step)
            if step.kind == 'folder':
                Path(step.path).mkdir(parents=True, exist_ok=True)
            elif step.kind in ('file', 'license'):
                path = Path(step.path)
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(step.content)
                path.chmod(step.mode)
        return self.package_dir


def _render(template: str, **values: str) -> str:
    # 'x.tmpl': an ament_python template; 'ament_cmake/x.tmpl': another build type's.
    text = (_TEMPLATES.parent / template if '/' in template else _TEMPLATES / template).read_text()
    for key, value in values.items():
        text = text.replace('{{' + key + '}}', value)
    return text


def _git_email() -> str:
    git = shutil.which('git')
    if git is None:
        return ''
    try:
        out = subprocess.run(
            [git, 'config', 'user.email'], capture_output=True, text=True, timeout=5, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return ''
    return out.stdout.strip()


def validate_package_name(name: str) -> None:
    """Refuse names REP 144 forbids (ros2 pkg create would accept them, then colcon warns)."""
    if not _REP144.match(name) or len(name) < 2:
        suggestion = re.sub(r'_+', '_', re.sub(r'[^a-z0-9_]', '_', name.lower())).strip('_')
        if not suggestion or not suggestion[0].isalpha():
            suggestion = 'my_' + suggestion if suggestion else 'my_package'
        raise PackageError(
            f"invalid package name '{name}': REP 144 package names start with a lowercase "
            'letter and hold only lowercase letters, digits and single underscores '
            '(at least two characters)',
            fix=f"use a name like '{suggestion}'",
        )
    if keyword.iskeyword(name):
        raise PackageError(
            f"invalid package name '{name}': it is a Python keyword, so its module "
            'could not be imported', fix=f"use a name like 'my_{name}'",
        )


def _check_node_name(node_name: str) -> None:
    # The node becomes NAME/<node>.py and the console script `<node> = NAME.<node>:main`.
    if not node_name.isidentifier() or keyword.iskeyword(node_name):
        raise PackageError(
            f"invalid node name '{node_name}': it becomes a Python module, so it must be a "
            'Python identifier',
            fix=f"use a name like '{re.sub(r'[^0-9A-Za-z_]', '_', node_name)}'",
        )


def _depends_block(dependencies: Iterable[str], cmake: bool = False) -> str:
    text = '  <buildtool_depend>ament_cmake</buildtool_depend>\n\n' if cmake else ''
    deps = list(dependencies)
    if deps:
        text += ''.join(f'  <depend>{dep}</depend>\n' for dep in deps) + '\n'
    tests = CMAKE_TEST_DEPENDENCIES if cmake else TEST_DEPENDENCIES
    text += ''.join(f'  <test_depend>{dep}</test_depend>\n' for dep in tests) + '\n'
    return text


def _cmake_steps(plan: PackagePlan, package_path: str) -> None:
    """Jazzy's ament_cmake template: src/, include/NAME/, CMakeLists.txt (+ a C++ node)."""
    name, deps, node_name = plan.name, plan.dependencies, plan.node_name
    if deps:
        finds = ''.join(f'find_package({dep} REQUIRED)\n' for dep in deps)
    else:
        finds = ('# uncomment the following section in order to fill in\n'
                 '# further dependencies manually.\n# find_package(<dependency> REQUIRED)\n')
    node = ''
    if node_name:
        node = (
            f'\nadd_executable({node_name} src/{node_name}.cpp)\n'
            f'target_include_directories({node_name} PUBLIC\n'
            '  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>\n'
            '  $<INSTALL_INTERFACE:include/${PROJECT_NAME}>)\n'
            f'target_compile_features({node_name} PUBLIC c_std_99 cxx_std_17)'
            '  # Require C99 and C++17\n'
        )
        if deps:
            node += (f'ament_target_dependencies(\n  {node_name}\n'
                     + ''.join(f'  "{dep}"\n' for dep in deps) + ')\n')
        node += f'\ninstall(TARGETS {node_name}\n  DESTINATION lib/${{PROJECT_NAME}})\n'
    plan.steps.append(Step('note', '', 'creating source and include folder'))
    plan.steps.append(Step('folder', os.path.join(package_path, 'src')))
    plan.steps.append(Step('folder', os.path.join(package_path, 'include', name)))
    plan.steps.append(Step('file', os.path.join(package_path, 'CMakeLists.txt'), _render(
        'ament_cmake/CMakeLists.txt.tmpl', name=name, find_dependencies=finds,
        node=node)))
    if node_name:
        plan.steps.append(Step('file', os.path.join(package_path, 'src', node_name + '.cpp'),
                               _render('ament_cmake/main.cpp.tmpl', name=name)))


def _launch_file(name: str, node_name: str | None, with_config: bool) -> str:
    if node_name is None:
        nodes = (
            f'  <!-- <node pkg="{name}" exec="my_node" name="my_node" output="screen"/> -->\n'
        )
    elif with_config:
        nodes = (
            f'  <node pkg="{name}" exec="{node_name}" name="{node_name}" output="screen">\n'
            f'    <param from="$(find-pkg-share {name})/config/params.yaml"/>\n'
            '  </node>\n'
        )
    else:
        nodes = f'  <node pkg="{name}" exec="{node_name}" name="{node_name}" output="screen"/>\n'
    return _render('launch.xml.tmpl', nodes=nodes)


def plan_package(
    name: str,
    destination: str | os.PathLike[str] = '.',
    build_type: str = 'ament_python',
    dependencies: Iterable[str] = (),
    node_name: str | None = None,
    maintainer_name: str | None = None,
    maintainer_email: str | None = None,
    license: str = DEFAULT_LICENSE,
    description: str = DEFAULT_DESCRIPTION,
    with_launch: bool = False,
    with_config: bool = False,
) -> PackagePlan:
    """Check the request the way ros2 pkg create does and list what it would create."""
    if build_type == 'cmake':
        raise PackageError(
            "build type 'cmake' (plain CMake, no ament) is not supported by robot_lab",
            fix='use --build-type ament_cmake (interfaces) or ament_python (nodes)',
        )
    if build_type not in ('ament_python', 'ament_cmake'):
        raise PackageError(
            f"unknown build type '{build_type}'",
            fix='use --build-type ament_python or ament_cmake',
        )
    if name == 'test' and build_type == 'ament_python':
        raise PackageError(
            "Aborted since 'ament_python' packages can't be named 'test'.",
            fix='choose a different package name',
        )
    validate_package_name(name)
    if node_name and build_type == 'ament_python':
        _check_node_name(node_name)
    dest = os.fspath(destination)
    package_path = os.path.join(dest, name)
    if os.path.exists(package_path):
        raise PackageError(
            f'Aborted! The directory already exists: {package_path}',
            fix='remove the directory or choose a different destination directory or '
            'package name',
        )
    maintainer = maintainer_name or getpass.getuser()
    email = maintainer_email or _git_email() or f'{maintainer}@todo.todo'
    deps = list(dependencies)
    plan = PackagePlan(
        name=name, destination=dest, build_type=build_type, dependencies=deps,
        node_name=node_name or None, maintainer_name=maintainer, maintainer_email=email,
        license=license, description=description,
    )
    src = os.path.join(package_path, name)
    people = {'maintainer_name': maintainer, 'maintainer_email': email}
    extra_data_files = ''
    if with_launch:
        extra_data_files += "        ('share/' + package_name + '/launch', glob('launch/*')),\n"
    if with_config:
        extra_data_files += "        ('share/' + package_name + '/config', glob('config/*')),\n"
    console = f"            '{node_name} = {name}.{node_name}:main'\n" if node_name else ''
    steps = plan.steps
    steps.append(Step('folder', package_path))
    cmake = build_type == 'ament_cmake'
    steps.append(Step('file', os.path.join(package_path, 'package.xml'), _render(
        'package.xml.tmpl', name=name, description=description, license=license,
        depends=_depends_block(deps, cmake), build_type=build_type, **people,
    )))
    if cmake:
        _cmake_steps(plan, package_path)
        _license_step(plan, package_path)
        return plan
    steps.append(Step('note', '', 'creating source folder'))
    steps.append(Step('folder', src))
    steps.append(Step('file', os.path.join(package_path, 'setup.py'), _render(
        'setup.py.tmpl', name=name, description=description, license=license,
        glob_import='from glob import glob\n\n' if extra_data_files else '',
        extra_data_files=extra_data_files, console_scripts=console, **people,
    )))
    steps.append(Step('file', os.path.join(package_path, 'setup.cfg'),
                      _render('setup.cfg.tmpl', name=name)))
    steps.append(Step('folder', os.path.join(package_path, 'resource')))
    steps.append(Step('file', os.path.join(package_path, 'resource', name)))
    steps.append(Step('file', os.path.join(src, '__init__.py')))
    steps.append(Step('folder', os.path.join(package_path, 'test')))
    for test in ('test_copyright', 'test_flake8', 'test_pep257'):
        steps.append(Step('file', os.path.join(package_path, 'test', test + '.py'),
                          _render(test + '.py.tmpl')))
    if node_name:
        steps.append(Step('file', os.path.join(src, node_name + '.py'),
                          _render('node.py.tmpl', name=name)))
    if with_launch:
        steps.append(Step('folder', os.path.join(package_path, 'launch')))
        steps.append(Step('file', os.path.join(package_path, 'launch', f'{name}.launch.xml'),
                          _launch_file(name, node_name, with_config)))
    if with_config:
        steps.append(Step('folder', os.path.join(package_path, 'config')))
        steps.append(Step('file', os.path.join(package_path, 'config', 'params.yaml'),
                          _render('params.yaml.tmpl', name=name)))
    _license_step(plan, package_path)
    return plan


def _license_step(plan: PackagePlan, package_path: str) -> None:
    license = plan.license
    if license in _LICENSE_TEXTS:
        # ros2 pkg create writes LICENSE silently (no `creating` line).
        plan.steps.append(Step('license', os.path.join(package_path, 'LICENSE'),
                               _render(_LICENSE_TEXTS[license])))
    elif license in AMENT_LICENSES:
        plan.warning = (
            f"\n[WARNING]: robot_lab has no text for license '{license}'.  It has been set in "
            'the package.xml, but no LICENSE file has been created; add the license text '
            'yourself.'
        )
    else:
        plan.warning = (
            f"\n[WARNING]: Unknown license '{license}'.  This has been set in the package.xml, "
            'but no LICENSE file has been created.\nIt is recommended to use one of the ament '
            'license identifiers:\n' + '\n'.join(AMENT_LICENSES)
        )


def create_package(
    name: str,
    destination: str | os.PathLike[str] = '.',
    build_type: str = 'ament_python',
    dependencies: Iterable[str] = (),
    node_name: str | None = None,
    maintainer_name: str | None = None,
    maintainer_email: str | None = None,
    license: str = DEFAULT_LICENSE,
    description: str = DEFAULT_DESCRIPTION,
    with_launch: bool = False,
    with_config: bool = False,
) -> Path:
    """Create a package as `ros2 pkg create` does; returns its directory."""
    plan = plan_package(
        name, destination, build_type, dependencies, node_name, maintainer_name,
        maintainer_email, license, description, with_launch, with_config,
    )
    return plan.write()
