"""The kit's programs (`<venv>/lib/<package>/<exe>`) end as quietly as upstream's C++ ones:
Ctrl-C while a program is still importing exits 130 with no traceback, and a reader that
goes away (`tf2_echo a b | head -n 1`) ends it with SIGPIPE's shell code, 141, silently.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import BIN

from robot_lab.env import ros_environment
from robot_lab.pkg import kit_packages
from robot_lab.process import child_setup

TF2_ROS = Path(sys.prefix, 'lib', 'tf2_ros')

# A program whose import never ends until a signal comes: says so first, so the test knows
# the SIGINT lands inside the import, the moment lesson 12 hit.
SLOW_IMPORT = """\
import signal, sys
sys.stdout.write('importing\\n')
sys.stdout.flush()
signal.pause()
def main():
    pass
"""


@pytest.mark.no_ros
def test_sigint_while_a_kit_program_imports_exits_130_without_traceback(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / 'slow_import_probe.py').write_text(SLOW_IMPORT)
    monkeypatch.setattr(kit_packages, 'KIT_EXECUTABLES',
                        {'probe_pkg': {'probe': 'slow_import_probe:main'}})
    [script] = kit_packages.install_executables(tmp_path)
    assert script == tmp_path / 'lib' / 'probe_pkg' / 'probe'
    env = {**ros_environment(), 'PYTHONPATH': str(tmp_path)}
    # child_setup: Ctrl-C as a terminal gives it, even when this run was started with
    # SIGINT ignored (a CI job started with `&` passes it on ignored, and Python keeps that).
    child = subprocess.Popen([str(script)], env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, preexec_fn=child_setup)
    assert child.stdout is not None and child.stdout.readline() == b'importing\n'
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=30)
    assert (child.returncode, err) == (130, b'')


def test_tf2_echo_piped_to_a_reader_that_leaves_exits_141_quietly() -> None:
    env = ros_environment()
    static = subprocess.Popen(
        [str(BIN / 'ros2'), 'run', 'tf2_ros', 'static_transform_publisher',
         '--frame-id', 'world', '--child-frame-id', 'turtle1'],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        # `ros2 run tf2_ros tf2_echo world turtle1 10 | head -n 1`: this test is `head`
        echo = subprocess.Popen([str(BIN / 'ros2'), 'run', 'tf2_ros', 'tf2_echo',
                                 'world', 'turtle1', '10'],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        assert echo.stdout is not None
        first = echo.stdout.readline()
        echo.stdout.close()  # the reader leaves; tf2_echo's next report meets a closed pipe
        assert first.startswith(b'At time '), first
        _, err = echo.communicate(timeout=30)
    finally:
        static.send_signal(signal.SIGINT)
        static.wait(30)
    assert b'Traceback' not in err and b'BrokenPipe' not in err, err.decode()
    assert echo.returncode == 141, err.decode()


def test_sigint_right_after_tf2_echo_starts_prints_no_traceback() -> None:
    """A real tf2_echo, interrupted once its own code runs: Python prints each import as it
    ends (PYTHONPROFILEIMPORTTIME), so the SIGINT follows the import of `robot_lab` itself,
    inside the entry script (a signal during the interpreter's own start-up, before the
    script's first line, is the interpreter's and out of the script's reach)."""
    env = {**ros_environment(), 'PYTHONPROFILEIMPORTTIME': '1'}
    echo = subprocess.Popen([str(TF2_ROS / 'tf2_echo'), 'world', 'nowhere'], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            preexec_fn=child_setup)
    assert echo.stderr is not None
    seen = []
    for raw in iter(echo.stderr.readline, b''):
        seen.append(raw)
        if re.search(rb'\|\s+robot_lab$', raw.rstrip()):
            break
    echo.send_signal(signal.SIGINT)
    _, rest = echo.communicate(timeout=30)
    err = (b''.join(seen) + rest).decode(errors='replace')
    assert re.search(r'\|\s+robot_lab$', err, re.M), err[-2000:]
    assert 'Traceback' not in err and 'KeyboardInterrupt' not in err, err[-2000:]
    # 130 if it landed in an import; 0 once tf2_echo's own handler stopped it
    assert echo.returncode in (0, 130), (echo.returncode, err[-2000:])


def test_every_kit_program_is_written_with_the_quiet_ending(tmp_path: Path) -> None:
    written = kit_packages.install_executables(tmp_path)
    assert len(written) == sum(len(p) for p in kit_packages.KIT_EXECUTABLES.values())
    for script in written:
        text = script.read_text()
        assert 'except KeyboardInterrupt:\n    sys.exit(130)' in text, script
        assert 'except BrokenPipeError:' in text, script
        compile(text, str(script), 'exec')
        assert os.access(script, os.X_OK)
