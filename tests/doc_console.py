"""Run a document's ```console blocks as printed and compare what they print.

A command is a line starting with `$ ` (continued while a quote is open or the line ends in
a backslash); the lines up to the next command are what it prints. Every command of one
document part runs in one bash, in order, so `cd` and `export` carry over. A printed line
may hold `…`, which stands for any text; a line that is only `…` stands for any lines.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

_MARK = '@@robot_lab_doc@@'


@dataclass
class Command:
    text: str
    expected: list[str]


def section(markdown: str, heading: str) -> str:
    """The part of `markdown` under `heading` (a `#` line), up to the next heading as high."""
    lines = markdown.splitlines()
    start = lines.index(heading)
    level = len(heading) - len(heading.lstrip('#'))
    end = next((i for i in range(start + 1, len(lines))
                if re.match(rf'#{{1,{level}}} ', lines[i])), len(lines))
    return '\n'.join(lines[start:end])


def commands(markdown: str) -> list[Command]:
    found: list[Command] = []
    for block in re.findall(r'```console\n(.*?)```', markdown, re.S):
        lines = block.splitlines()
        i = 0
        while i < len(lines):
            line = lines[i]
            if not line.startswith('$ '):
                if found:
                    found[-1].expected.append(line)
                i += 1
                continue
            text = line[2:]
            while (text.count("'") % 2 or text.endswith('\\')) and i + 1 < len(lines):
                i += 1
                text += '\n' + lines[i]
            found.append(Command(text, []))
            i += 1
    return found


def _matches(expected: list[str], actual: list[str]) -> bool:
    if not expected:
        return not actual
    head, rest = expected[0], expected[1:]
    if head.strip() == '…':
        return any(_matches(rest, actual[k:]) for k in range(len(actual) + 1))
    if not actual:
        return False
    pattern = '.*'.join(re.escape(part) for part in head.split('…'))
    return re.fullmatch(pattern, actual[0].rstrip()) is not None and _matches(rest, actual[1:])


def run(markdown: str, cwd: Path, env: dict[str, str], timeout: float = 1800) -> list[str]:
    """Run every console command of `markdown`; a message per command whose output differs."""
    cmds = commands(markdown)
    assert cmds, 'no console commands found'
    script = ''.join(f"printf '\\n{_MARK} {n}\\n'\n{c.text}\n" for n, c in enumerate(cmds))
    done = subprocess.run(['bash', '-c', script + f"printf '\\n{_MARK} end\\n'"], cwd=cwd,
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=timeout, check=False)
    parts = re.split(rf'\n{_MARK} (\d+|end)\n', '\n' + done.stdout)
    outputs: dict[int, list[str]] = {}
    for key, text in zip(parts[1::2], parts[2::2], strict=True):
        if key != 'end':
            outputs[int(key)] = text.splitlines()
    problems = []
    for n, cmd in enumerate(cmds):
        actual = outputs.get(n)
        if actual is None:
            problems.append(f'$ {cmd.text}\n  never ran (the script stopped before it)')
        elif not _matches(cmd.expected, actual):
            problems.append(f'$ {cmd.text}\n  printed:\n' + '\n'.join(actual) +
                            '\n  the document says:\n' + '\n'.join(cmd.expected))
    return problems
