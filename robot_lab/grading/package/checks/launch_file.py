"""`launch_file`: a launch file in launch/ starts every node of the system."""

from __future__ import annotations

import re
from pathlib import Path

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['launch_file', 'static_launch_nodes_count']


def static_launch_nodes_count(path: Path) -> int:
    """How many nodes a launch file declares, read as text (for a package that does not
    build, so the file cannot be resolved)."""
    text = path.read_text(errors='replace')
    if path.suffix == '.xml':
        return len(re.findall(r'<node\b', text))
    if path.suffix in ('.yaml', '.yml'):
        return len(re.findall(r'^\s*-?\s*node\s*:', text, re.MULTILINE))
    return len(re.findall(r'\bNode\s*\(', text))


@register('launch_file', stage='run')
def launch_file(state: JobState, check: RubricCheck) -> Verdict:
    min_nodes = int(check.option('min_nodes', 3))
    live = state.live
    if not state.built:
        for path in state.launch_files:
            if (nodes := static_launch_nodes_count(path)) >= min_nodes:
                return Verdict(True, f'a launch file starting at least {min_nodes} nodes',
                               f'`launch/{path.name}` declares {nodes} nodes (not run: the '
                               'package does not build)')
        return Verdict(False, f'a launch file in launch/ starting at least {min_nodes} nodes',
                       'none found' if not state.launch_files
                       else 'the launch files declare fewer',
                       'add launch/<name>.launch.xml (or .launch.py) with one node entry per '
                       'node')
    if live.not_run:
        return live.not_run_verdict('a launch file that starts the nodes')
    # Nodes, not processes: one process spinning three nodes is a correct system.
    started = [p for p in live.statuses if p.pid is not None]
    # A node that crashed at start still counts: the launch file did start it.
    names = sorted(set(live.obs.nodes if live.obs is not None else [])
                   | {p.name for p in started if p.name.startswith('/')})
    lines = [f'- `{p.label}`: {p.state}'
             + (f', exit code {p.exit_code}' if p.exit_code not in (None, 0) else '')
             for p in live.statuses]
    observed = (f'`launch/{live.launch_name}` started {len(started)} process(es) with '
                f'{len(names)} node(s) in the graph ({", ".join(f"`{n}`" for n in names)}):'
                '\n\n' if live.launch_name else 'no launch file was run.\n\n') + '\n'.join(lines)
    if live.notes:
        observed += '\n\n' + '\n\n'.join(live.notes)
    ok = bool(live.launch_name) and len(names) >= min_nodes
    return Verdict(ok, f'a launch file in launch/ that brings up all (at least {min_nodes}) '
                   'nodes', observed + live.dead(),
                   live.crash_fix() or 'add every node to the launch file (and install '
                   'launch/ with data_files)')
