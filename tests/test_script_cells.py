"""A `%%bash` cell prints what its program wrote, even a character split across reads.

IPython 8 (the one Python 3.10 gets) decoded each 100-byte read on its own: a `°` at byte
100 of a line came out as `��` (04_parameters' refused `ros2 param set`, on 3.10 only).
The first test fails there without `robot_lab.script_cells`; the others pin what the
replacement keeps of IPython's `%%script`: split reads, stderr, exit status, flags.
"""

from __future__ import annotations

import subprocess

import pytest
from IPython.core.interactiveshell import InteractiveShell

from robot_lab.script_cells import decode_whole_characters, run_script

# '°' (two bytes in UTF-8) at bytes 100-101: across IPython 8's first read of 100 bytes.
AT_100 = "printf '%099d°C\\n' 0 >&2"


@pytest.fixture(scope='module')
def shell() -> InteractiveShell:
    shell = InteractiveShell.instance()
    decode_whole_characters()
    decode_whole_characters()  # a second lesson set-up in the kernel: still one wrapper
    return shell


def test_a_character_at_byte_100_survives_a_bash_cell(
        shell: InteractiveShell, capsys: pytest.CaptureFixture[str]) -> None:
    shell.run_cell_magic('bash', '', AT_100)
    assert capsys.readouterr().err == '0' * 99 + '°C\n'


def test_a_character_across_a_full_read_survives(capsys: pytest.CaptureFixture[str]) -> None:
    # One write of 4095 bytes and a '°': the first read takes 4096 bytes, half the '°'.
    run_script(['bash'], "printf '%04095d°C\\n' 0; printf 'both streams\\n' >&2")
    captured = capsys.readouterr()
    assert captured.out == '0' * 4095 + '°C\n'
    assert captured.err == 'both streams\n'


def test_a_failing_cell_fails_unless_told_not_to(
        shell: InteractiveShell, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(subprocess.CalledProcessError) as failed:
        run_script(['bash'], 'echo half; exit 3')
    assert failed.value.returncode == 3
    shell.run_cell_magic('bash', '--no-raise-error', 'echo half; exit 3')
    shell.run_cell_magic('script', 'sh', 'echo from sh')
    assert capsys.readouterr().out == 'half\nhalf\nfrom sh\n'


def test_a_missing_program_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    run_script(['no-such-program-here'], 'true')
    assert capsys.readouterr().out == "Couldn't find program: 'no-such-program-here'\n"


def test_background_cells_keep_ipythons_own_code(
        shell: InteractiveShell, capsys: pytest.CaptureFixture[str]) -> None:
    shell.run_cell_magic('bash', '--out captured', 'echo kept')
    assert shell.user_ns['captured'] == 'kept\n'
    assert capsys.readouterr().out == ''
