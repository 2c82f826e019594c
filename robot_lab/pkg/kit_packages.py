"""The ament packages the kit builds from their definitions, into its own venv.

PyPI has the rosidl generators but not the tutorials' interface packages
(`example_interfaces`, `action_tutorials_interfaces`, turtlesim's msg/srv/action), nor
`ament_lint_auto`/`ament_lint_common`, which the `ros2 pkg create --build-type ament_cmake`
template finds. Their sources live in `robot_lab/data/ament_packages/` (upstream's
definitions, licence notes in NOTICE.md) and are built as colcon's ament_cmake task builds
a package (CMake configure, build, install) with the venv as install prefix: the venv is
already on every path that matters (site-packages, LD_LIBRARY_PATH through the wheels'
bootstrapper, the ament index, CMake's PATH-based search), so `from example_interfaces.srv
import AddTwoInts` works in any kernel or `ros2 run` process with nothing sourced.

`./kit setup` builds them (`robot-lab build --kit`); a package looked up before that is
built on first need. The interface packages are built with the C type supports rclpy
loads, not the C++ ones (rclcpp is not on PyPI): half the build time. `robot-lab build
--kit --cpp` adds them, for a C++ interface package that depends on a kit package.
Programs a kit package provides (turtlesim's) are entries in `KIT_EXECUTABLES`, written
to `<venv>/lib/<package>/<name>` where `ros2 run` finds them.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import itertools
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.compiler_cache import ccache_program, kit_cache_dir
from robot_lab.env import ros_environment
from robot_lab.errors import PackageError
from robot_lab.pkg.wheel_cmake import build_tools, fix_wheel_cmake

__all__ = [
    'KIT_EXECUTABLES',
    'KIT_PACKAGES',
    'KitBuild',
    'build_kit_packages',
    'ensure_kit_package',
    'install_executables',
    'install_underlay',
    'kit_package_sources',
    'warm_compiler_cache',
]

SOURCES = Path(__file__).resolve().parents[1] / 'data' / 'ament_packages'
# The tutorials' own interface packages as a student's notebook writes them (notebook 09's
# robot_interfaces): built once at set-up so the compiler cache holds their objects.
TUTORIAL_SOURCES = SOURCES.with_name('tutorial_packages')
# CMAKE_PROJECT_INCLUDE for an interface package built for Python only (see its comments).
PYTHON_ONLY = SOURCES.with_name('python_only_interfaces.cmake')

# Build order: the lint packages first (the interface packages' CMakeLists may find them).
KIT_PACKAGES: tuple[str, ...] = (
    'ament_lint_auto',
    'ament_lint_common',
    'example_interfaces',
    'action_tutorials_interfaces',
    'turtlesim',
    'tf2_msgs',
    # tf2's Python packages (upstream's module paths over robot_lab.tf2) and their tools
    'tf2_py',
    'tf2_ros',
    'tf2_ros_py',
    'tf2_geometry_msgs',
    'tf2_tools',
    'turtle_tf2_py',
    # Chapter 7's robot description packages (data and launch files; programs below)
    'robot_state_publisher',
    'joint_state_publisher',
    'urdf_launch',
    'urdf_tutorial',
    'xacro',
    # Module 2's simulation packages (robot_lab/sim; launch file and worlds, programs below)
    'ros_gz_interfaces',  # world control from ROS: ControlWorld, through parameter_bridge
    'ros_gz_sim',
    'ros_gz_bridge',
    'teleop_twist_keyboard',
)

# The contract for programs a kit package provides: package -> {executable: 'module:func'}.
# Each becomes <venv>/lib/<package>/<executable>, a script running `func()` of `module`
# with the venv's Python, so `ros2 run <package> <executable>` and launch files find it.
KIT_EXECUTABLES: dict[str, dict[str, str]] = {
    'tf2_ros': {
        'static_transform_publisher': 'robot_lab.tf2.static_publisher:main',
        'tf2_echo': 'robot_lab.tf2.echo:echo_main',
        'tf2_monitor': 'robot_lab.tf2.echo:monitor_main',
        'buffer_server': 'robot_lab.tf2.buffer_server:main',
    },
    'tf2_tools': {
        'view_frames': 'robot_lab.tf2.view_frames:program',
    },
    # upstream's tutorial package, its setup.py's console scripts
    'turtle_tf2_py': {
        name: f'turtle_tf2_py.{name}:main'
        for name in ('static_turtle_tf2_broadcaster', 'turtle_tf2_broadcaster',
                     'turtle_tf2_listener', 'fixed_frame_tf2_broadcaster',
                     'dynamic_frame_tf2_broadcaster', 'turtle_tf2_message_broadcaster')
    },
    'turtlesim': {
        'turtlesim_node': 'robot_lab.turtlesim.node:main',
        'turtle_teleop_key': 'robot_lab.turtlesim.teleop:main',
        'draw_square': 'robot_lab.turtlesim.draw_square:main',
        'mimic': 'robot_lab.turtlesim.mimic:main',
    },
    'robot_state_publisher': {
        'robot_state_publisher': 'robot_lab.urdf.state_publisher:main',
    },
    'joint_state_publisher': {
        'joint_state_publisher': 'robot_lab.urdf.joint_state_publisher:main',
    },
    'xacro': {
        'xacro': 'robot_lab.urdf.xacro_command:main',
    },
    'ros_gz_sim': {
        'gz_sim': 'robot_lab.sim.server:main',  # what gz_sim.launch.py runs for `gz sim`
        'gzserver': 'robot_lab.sim.server:gzserver_main',  # gz_server.launch.py's
        'create': 'robot_lab.sim.create:main',
    },
    'ros_gz_bridge': {
        'parameter_bridge': 'robot_lab.sim.bridge:main',
    },
    'teleop_twist_keyboard': {
        'teleop_twist_keyboard': 'robot_lab.keyboard_teleop.terminal:main',
    },
}

_MARKERS = Path('share', 'ament_index', 'resource_index', 'packages')
_ENSURED: set[str] = set()  # checked current in this process (once: a lookup is frequent)


def kit_package_sources(name: str) -> Path:
    """The source folder of kit package `name` (package.xml, CMakeLists.txt, msg/...)."""
    source = SOURCES / name
    if name not in KIT_PACKAGES or not (source / 'package.xml').is_file():
        raise PackageError(f"'{name}' is not one of the kit's packages: "
                           f"{', '.join(KIT_PACKAGES)}")
    return source


def _state_dir(prefix: Path) -> Path:
    return prefix / 'var' / 'robot_lab' / 'kit_packages'


def _source_hash(source: Path) -> str:
    digest = hashlib.sha256()
    # Bytecode is not source: a compile of the kit (`./kit setup`) must not look like an edit.
    for path in sorted(p for p in source.rglob('*')
                       if p.is_file() and '__pycache__' not in p.parts):
        digest.update(str(path.relative_to(source)).encode() + b'\0' + path.read_bytes())
    return digest.hexdigest()[:16]


def _stamp(name: str, cpp: bool) -> str:
    """What a build of `name` records: its sources' hash, and whether it has the C++ type
    supports (`+cpp`) or not (`+py`; a stamp without either predates the choice)."""
    return _source_hash(kit_package_sources(name)) + ('+cpp' if cpp else '+py')


def _is_current(name: str, prefix: Path, cpp: bool = False) -> bool:
    """Built from these sources (with the C++ type supports if `cpp`: they also serve
    Python)."""
    stamp = _state_dir(prefix) / f'{name}.stamp'
    if not (prefix / _MARKERS / name).is_file() or not stamp.is_file():
        return False
    digest, _, kind = stamp.read_text().strip().partition('+')
    return (digest == _source_hash(kit_package_sources(name))
            and kind in (('cpp',) if cpp else ('py', 'cpp')))


def _write_if_changed(path: Path, text: str, mode: int) -> None:
    if path.is_file() and path.read_text() == text and (path.stat().st_mode & 0o777) == mode:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
    tmp.write_text(text)
    tmp.chmod(mode)
    tmp.replace(path)


# A kit program ends as quietly as upstream's C++ one: Ctrl-C at any moment, even while
# it is still importing, exits 130 with no traceback (the code `robot-lab`'s verbs give a
# KeyboardInterrupt); a reader gone away (`tf2_echo a b | head -n 3`) ends it with the
# shell's code for SIGPIPE (141), stdout pointed at /dev/null so the last flush cannot
# fail again. A program that handles SIGINT itself (the nodes' clean exit 0) is unchanged.
_SCRIPT = """\
#!{python}
\"\"\"{package} {executable}: robot_lab's {module}.{func}.\"\"\"
import os
import sys
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
try:
    from {module} import {func} as main
    if __name__ == '__main__':
        main()
        sys.stdout.flush()
except KeyboardInterrupt:
    sys.exit(130)
except BrokenPipeError:
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    sys.exit(141)
"""


def install_executables(prefix: Path | None = None) -> list[Path]:
    """Write every `KIT_EXECUTABLES` entry as a script under <prefix>/lib/<package>/."""
    root = Path(sys.prefix) if prefix is None else prefix
    written: list[Path] = []
    for package, programs in KIT_EXECUTABLES.items():
        for executable, target in sorted(programs.items()):
            module, _, func = target.partition(':')
            script = _SCRIPT.format(python=sys.executable, package=package,
                                    executable=executable, module=module,
                                    func=func or 'main')
            path = root / 'lib' / package / executable
            _write_if_changed(path, script, 0o755)
            written.append(path)
    return written


_UNDERLAY = """\
# robot_lab: the kit's venv as a ROS 2 underlay, as /opt/ros/jazzy/{name} is for a ROS
# install: rosidl finds its type supports through AMENT_PREFIX_PATH, CMake the packages.
_robot_lab_prefix='{prefix}'
for _robot_lab_var in AMENT_PREFIX_PATH CMAKE_PREFIX_PATH; do
  eval "_robot_lab_have=\\${{$_robot_lab_var:-}}"
  case ":$_robot_lab_have:" in
    *":$_robot_lab_prefix:"*) ;;
    *) export "$_robot_lab_var=$_robot_lab_prefix${{_robot_lab_have:+:$_robot_lab_have}}" ;;
  esac
done
case ":$PATH:" in
  *":$_robot_lab_prefix/bin:"*) ;;
  *) export PATH="$_robot_lab_prefix/bin:$PATH" ;;
esac
unset _robot_lab_prefix _robot_lab_var _robot_lab_have
"""


# Appended to the venv's bin/activate (bash, zsh): the README's `source .venv/bin/activate`
# gives a terminal what setup.bash gives, or its `colcon build` of an interface package
# stops at "No 'rosidl_typesupport_c' found" (AMENT_PREFIX_PATH unset).
_ACTIVATE_HOOK = """
# robot_lab: the venv as a ROS 2 underlay too (AMENT_PREFIX_PATH, CMAKE_PREFIX_PATH), as
# its setup.bash makes it, so colcon builds interface packages; deactivate leaves them set,
# as a sourced setup.bash does.
if [ -f "$VIRTUAL_ENV/setup.sh" ] ; then
    . "$VIRTUAL_ENV/setup.sh"
fi
"""


def install_underlay(prefix: Path | None = None) -> Path:
    """Write <venv>/setup.bash (and local_setup.*, setup.sh): `source` it as a ROS setup.

    colcon also looks for these: an AMENT_PREFIX_PATH entry without them draws a warning.
    The venv's bin/activate sources setup.sh as well (`_ACTIVATE_HOOK`).
    """
    root = Path(sys.prefix) if prefix is None else prefix
    for name in ('setup.sh', 'setup.bash', 'local_setup.sh', 'local_setup.bash'):
        _write_if_changed(root / name, _UNDERLAY.format(name=name, prefix=root), 0o644)
    activate = root / 'bin' / 'activate'
    with contextlib.suppress(FileNotFoundError):  # a prefix that is no venv has none
        text = activate.read_text()
        if _ACTIVATE_HOOK not in text:
            _write_if_changed(activate, text.rstrip('\n') + '\n' + _ACTIVATE_HOOK,
                              activate.stat().st_mode & 0o777)
    return root / 'setup.bash'


@dataclass
class KitBuild:
    """What `build_kit_packages` did: seconds per package built, those already current."""

    prefix: Path
    built: dict[str, float] = field(default_factory=dict)
    current: list[str] = field(default_factory=list)
    fixed_cmake_files: int = 0
    warmed: dict[str, float] = field(default_factory=dict)  # tutorial package -> seconds

    @property
    def seconds(self) -> float:
        return sum(self.built.values())

    def lines(self) -> list[str]:
        out = [f'built {name} in {secs:.1f} s' for name, secs in self.built.items()]
        if self.current:
            out.append('up to date: ' + ', '.join(self.current))
        if self.built:
            out.append(f'kit packages built in {self.seconds:.1f} s into {self.prefix}')
        out.extend(f'compiler cache warmed with {name} in {secs:.1f} s'
                   for name, secs in self.warmed.items())
        return out


@contextlib.contextmanager
def _build_lock(prefix: Path) -> Iterator[None]:
    """One builder at a time per venv (two kernels may need the same package at once)."""
    state = _state_dir(prefix)
    state.mkdir(parents=True, exist_ok=True)
    with open(state / 'build.lock', 'w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _build_env(prefix: Path) -> dict[str, str]:
    env = ros_environment()
    env['PATH'] = os.pathsep.join([str(prefix / 'bin'), env.get('PATH', '')])
    for var in ('AMENT_PREFIX_PATH', 'CMAKE_PREFIX_PATH'):
        have = [p for p in env.get(var, '').split(os.pathsep) if p and p != str(prefix)]
        env[var] = os.pathsep.join([str(prefix), *have])
    return env


def _run(cmd: Sequence[str], env: dict[str, str], log: Path, name: str) -> None:
    with open(log, 'ab') as out:
        out.write(('$ ' + ' '.join(cmd) + '\n').encode())
        out.flush()
        done = subprocess.run(cmd, env=env, stdout=out, stderr=subprocess.STDOUT, check=False)
    if done.returncode != 0:
        tail = log.read_text(errors='replace').splitlines()
        errors = [line for line in tail if 'error' in line.lower()][-3:] or tail[-3:]
        raise PackageError(
            f'building the kit package {name} failed: ' + ' | '.join(e.strip() for e in errors),
            file=log, fix='read the log; `robot-lab build --kit` retries',
        )


def _build_one(name: str, prefix: Path, env: dict[str, str], cpp: bool) -> float:
    tools = build_tools()
    source = kit_package_sources(name)
    python_only = not cpp and _generates_interfaces(name)
    state = _state_dir(prefix)
    build_dir = state / 'build' / name
    log = state / f'{name}.log'
    state.mkdir(parents=True, exist_ok=True)
    log.write_text('')
    started = time.monotonic()
    _run([str(tools.cmake), '-S', str(source), '-B', str(build_dir),
          f'-DCMAKE_INSTALL_PREFIX={prefix}', '-DBUILD_TESTING=OFF',
          '-DCMAKE_BUILD_TYPE=Release', f'-DPython3_EXECUTABLE={sys.executable}',
          f'-DCMAKE_C_COMPILER={tools.c_compiler}',
          f'-DCMAKE_CXX_COMPILER={tools.cxx_compiler}',
          # always given: a build folder's cache keeps the last configure's value
          f'-DCMAKE_PROJECT_INCLUDE={PYTHON_ONLY if python_only else ""}'],
         env, log, name)
    _run([str(tools.cmake), '--build', str(build_dir), '--parallel', str(os.cpu_count() or 1)],
         env, log, name)
    _run([str(tools.cmake), '--install', str(build_dir)], env, log, name)
    (state / f'{name}.stamp').write_text(_stamp(name, cpp) + '\n')
    return time.monotonic() - started


def build_kit_packages(
    names: Sequence[str] | None = None,
    force: bool = False,
    progress: Callable[[str], None] | None = None,
    cpp: bool = False,
    lanes: int = 2,
) -> KitBuild:
    """Build the kit's packages (all, or `names`) into the venv unless already current
    (`cpp`: with the C++ type supports too; `lanes`: interface packages built at once)."""
    prefix = Path(sys.prefix)
    wanted = [n for n in KIT_PACKAGES if names is None or n in names]
    unknown = sorted(set(names or ()) - set(KIT_PACKAGES))
    if unknown:
        raise PackageError(f"not kit packages: {', '.join(unknown)}",
                           fix=f"choose from {', '.join(KIT_PACKAGES)}")
    if not os.access(prefix, os.W_OK):
        raise PackageError(
            f'the kit packages {", ".join(wanted)} are not built and {prefix} is read-only',
            fix='run `robot-lab build --kit` once as the user who installed the kit',
        )
    result = KitBuild(prefix=prefix)
    with _build_lock(prefix):
        result.fixed_cmake_files = len(fix_wheel_cmake(prefix))
        env = _build_env(prefix)
        todo = [n for n in wanted if force or not _is_current(n, prefix, cpp)]
        result.current = [n for n in wanted if n not in todo]
        # The CMake-only packages first (others may find them), one at a time; then the
        # interface packages and the cache warming side by side: each spends a third of
        # its time in serial steps (configure, generators): two at a time took a clean
        # set-up's build from 71.5 to 61.8 s on 2 cores (bench/bench_kit_build.py).
        order = itertools.count(1)

        def build(name: str) -> float:
            if progress is not None:
                progress(f'building {name} ({next(order)}/{len(todo)}) from its definitions ...')
            return _build_one(name, prefix, env, cpp)

        generating = [n for n in todo if _generates_interfaces(n)]
        serial = {name: build(name) for name in todo if name not in generating}
        with ThreadPoolExecutor(max_workers=max(1, min(lanes, os.cpu_count() or 1))) as pool:
            lanes_done = {name: pool.submit(build, name) for name in generating}
            warming = (pool.submit(warm_compiler_cache, env, force=force, progress=progress)
                       if names is None else None)
        # The block has waited for every job; a failure is raised here, in the kit's order.
        result.built = {n: serial[n] if n in serial else lanes_done[n].result() for n in todo}
        if warming is not None:
            result.warmed = warming.result()
        install_executables(prefix)
        install_underlay(prefix)
    return result


def _generates_interfaces(name: str) -> bool:
    """Whether kit package `name` runs rosidl (an interface package: minutes, not a second)."""
    return 'rosidl_default_generators' in (kit_package_sources(name) / 'package.xml').read_text()


def warm_compiler_cache(
    env: dict[str, str] | None = None,
    force: bool = False,
    progress: Callable[[str], None] | None = None,
) -> dict[str, float]:
    """`colcon build` each tutorial package once in a scratch workspace, through ccache.

    A student's first build of the same definitions (in any folder) then compiles nothing.
    Nothing to do without ccache, or when the cache already holds these sources.
    """
    env = _build_env(Path(sys.prefix)) if env is None else env
    if ccache_program() is None or 'CMAKE_C_COMPILER_LAUNCHER' not in env:
        return {}
    cache = Path(env.get('CCACHE_DIR', kit_cache_dir()))
    warmed: dict[str, float] = {}
    for source in sorted(p for p in TUTORIAL_SOURCES.iterdir() if (p / 'package.xml').is_file()):
        stamp = cache / f'robot_lab-warm-{source.name}.stamp'
        digest = _source_hash(source)
        if not force and stamp.is_file() and stamp.read_text().strip() == digest:
            continue
        if progress is not None:
            progress(f'warming the compiler cache: building {source.name} once ...')
        started = time.monotonic()
        with tempfile.TemporaryDirectory(prefix='robot_lab_warm_') as scratch:
            workspace = Path(scratch)
            shutil.copytree(source, workspace / 'src' / source.name)
            log = _state_dir(Path(sys.prefix)) / f'warm-{source.name}.log'
            log.write_text('')
            try:
                _run([str(Path(sys.prefix) / 'bin' / 'colcon'),
                      '--log-base', str(workspace / 'log'), 'build',
                      '--base-paths', str(workspace / 'src'),
                      '--build-base', str(workspace / 'build'),
                      '--install-base', str(workspace / 'install')], env, log, source.name)
            except PackageError as exc:  # only a slower first build: say so, go on
                if progress is not None:
                    progress(f'the compiler cache is not warmed ({exc})')
                continue
        cache.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest + '\n')
        warmed[source.name] = time.monotonic() - started
    return warmed


def ensure_kit_package(name: str, progress: Callable[[str], None] | None = None) -> bool:
    """Build kit package `name` on first need (False: `name` is not a kit package)."""
    if name not in KIT_PACKAGES:
        return False
    if name in _ENSURED:
        return True
    prefix = Path(sys.prefix)
    if _is_current(name, prefix):
        install_executables(prefix)
        _ENSURED.add(name)
        return True
    say = progress or (lambda line: print(f'[robot_lab] {line}', file=sys.stderr, flush=True))
    build = build_kit_packages([name], progress=say)
    for line in build.lines():
        say(line)
    _ENSURED.add(name)
    return True
