"""check.command_prints and check.command_drives: a student's command line, run as a
terminal runs it, waited on for what it prints and for what it makes a topic carry (never
for a fixed time), then stopped with Ctrl-C together with everything it started.

The deadlines here are far longer than pytest's timeout: a check that waited for its
deadline instead of the condition would fail the test by timing out.
"""

from __future__ import annotations

from pathlib import Path

import psutil
import pytest
from conftest import BIN

from robot_lab.grading import CheckError, check

LONG = 600.0  # seconds: never reached by a check that waits on its condition


def _left(marker: str) -> list[str]:
    """Processes still running whose command line holds `marker`."""
    found = []
    for proc in psutil.process_iter(['cmdline', 'status']):
        line = ' '.join(proc.info['cmdline'] or [])
        if marker in line and proc.info['status'] != psutil.STATUS_ZOMBIE:
            found.append(line)
    return found


def test_prints_returns_at_the_line_and_stops_what_it_started(tmp_path: Path) -> None:
    stopped = tmp_path / 'stopped'
    command = (f"trap 'echo ctrl-c > {stopped}; exit 130' INT; echo 'node started'; "
               f'sleep 3600 & wait')
    check.command_prints(command, r'^node started$', seconds=LONG)
    assert stopped.read_text() == 'ctrl-c\n'  # it got the Ctrl-C a terminal sends
    assert not _left('sleep 3600')  # and so did what it started


def test_prints_says_what_the_command_printed_when_it_ends_without_the_line() -> None:
    with pytest.raises(CheckError) as failed:
        check.command_prints("echo \"Package 'broken' not found\"; exit 1", r'Sensor started',
                             seconds=LONG)
    assert failed.value.expected == "`echo \"Package 'broken' not found\"; exit 1` to print " \
                                    "'Sensor started'"
    assert failed.value.seen == '''it printed "Package 'broken' not found"'''


def test_prints_several_lines_from_one_run_and_names_the_missing_one(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    runs = tmp_path / 'runs'
    command = f"echo run >> {runs}; echo 'remaining: 0.4'; echo 'SUCCEEDED'; sleep 3600"
    check.command_prints(command, [r'^remaining: 0\.4$', r'^SUCCEEDED$'], seconds=LONG)
    assert runs.read_text() == 'run\n'  # one run for both lines
    assert capsys.readouterr().out.count('✓ ') == 2  # each judged
    with pytest.raises(CheckError) as failed:
        check.command_prints("echo 'remaining: 0.4'", [r'remaining', r'SUCCEEDED'],
                             seconds=LONG)
    assert failed.value.expected.endswith("to print 'SUCCEEDED'")
    assert not _left('sleep 3600')


def test_prints_refuses_an_empty_command() -> None:
    with pytest.raises(CheckError, match='the command is empty'):
        check.command_prints('  ', 'x')


def _pub(topic: str, data: int, *options: str) -> str:
    return f'{BIN / "ros2"} topic pub {" ".join(options)} {topic} std_msgs/msg/Int32 ' \
           f'"{{data: {data}}}"'


def test_drives_runs_the_command_until_the_topic_shows_it(capsys: pytest.CaptureFixture[str]
                                                          ) -> None:
    command = _pub('/check_drives', 7, '--rate', '5')
    check.command_drives(command, '/check_drives', prints=r'publishing #2',
                         where=lambda msg: msg.data == 7, description='carrying 7',
                         seconds=LONG)
    shown = capsys.readouterr().out.splitlines()
    assert shown == [f"✓ `{command}` prints 'publishing #2'",
                     '✓ /check_drives publishes std_msgs/msg/Int32 carrying 7']
    assert not _left('/check_drives')


def test_drives_names_what_the_topic_carried_instead() -> None:
    command = _pub('/check_drives_wrong', 3, '--rate', '5')
    with pytest.raises(CheckError) as failed:
        check.command_drives(command, '/check_drives_wrong', where=lambda msg: msg.data == 7,
                             description='carrying 7', seconds=5.0, hint='publish 7')
    assert failed.value.expected == \
        f'a message on /check_drives_wrong carrying 7, while `{command}` runs'
    assert failed.value.seen == "within 5 s the last one was {'data': 3}"
    assert failed.value.hint == 'publish 7'
    assert not _left('/check_drives_wrong')


def test_drives_stops_waiting_when_the_command_ends_without_printing() -> None:
    command = _pub('/check_drives_once', 7, '--times', '1', '-w', '0')
    with pytest.raises(CheckError) as failed:
        check.command_drives(command, '/check_drives_once', prints=r'publishing #3',
                             where=lambda msg: msg.data == 7, description='carrying 7',
                             seconds=LONG)
    assert failed.value.expected == f"`{command}` to print 'publishing #3'"
    assert failed.value.seen.startswith("it printed 'publishing #1: ")


def test_prints_judges_a_command_it_had_to_stop_by_what_came_before_the_ctrl_c() -> None:
    """A client whose answer never comes is stopped at the deadline; its KeyboardInterrupt
    traceback is the check's doing, not the student's (stop 39's CI showed only that)."""
    command = ("trap 'echo Traceback; echo KeyboardInterrupt; exit 130' INT; "
               "echo 'Sending goal'; sleep 3600 & wait")
    with pytest.raises(CheckError) as failed:
        check.command_prints(command, r'Travelled', seconds=1.0)
    seen = failed.value.seen
    assert seen.startswith('it was still running ') and 'stopped it with Ctrl-C' in seen
    assert seen.endswith("its last line was 'Sending goal'")
    assert not any('KeyboardInterrupt' in line for line in failed.value.details)
    assert not _left('sleep 3600')
