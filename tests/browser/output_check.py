"""nbval's output check, for a notebook the browser ran.

`pytest --nbval-lax` compares the outputs of the cells marked `# NBVAL_CHECK_OUTPUT` with
the outputs committed in notebooks/. The course in Chromium runs every notebook from a
fresh kernel in course order, as nbval does, so it makes the same comparison on what
JupyterLab saved, with nbval's own code (its stream merging, skipped keys, sanitizers
from notebooks/nbval_sanitize.cfg), and `./kit test` runs each notebook once less.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import nbformat
from nbval.plugin import (
    IPyNbCell,
    coalesce_streams,
    find_comment_markers,
    find_metadata_tags,
    get_sanitize_patterns,
    nocolors,
)

REPO = Path(__file__).resolve().parents[2]
SANITIZE = REPO / 'notebooks' / 'nbval_sanitize.cfg'
# nbval's keys never compared (IPyNbFile.__init__ without --nbdime): ids, counts, images.
SKIP = ('metadata', 'traceback', 'prompt_number', 'output_type', 'name', 'execution_count',
        'application/vnd.jupyter.widget-view+json', 'image/png', 'image/jpeg')


def checked(cell: Any) -> bool:
    """nbval checks this cell's output (a comment marker or a cell tag says so)."""
    if cell.cell_type != 'code':
        return False
    markers = dict(find_comment_markers(cell.source))
    markers.update(dict(find_metadata_tags(cell.metadata)))
    return bool(markers.get('check', False))


def _comparer() -> Any:
    """What IPyNbCell.compare_outputs reads of itself: its file's skips and sanitizers."""
    patterns = dict(get_sanitize_patterns(SANITIZE.read_text()))
    parent = SimpleNamespace(skip_compare=SKIP, sanitize_patterns=patterns)
    item = SimpleNamespace(parent=parent, colors=nocolors, comparison_traceback=[])
    item.sanitize = lambda s: IPyNbCell.sanitize(item, s)

    def differs(key: str, committed: object, now: object) -> None:  # nbval's needs pytest
        item.comparison_traceback.append(f'{key}:\n' + ''.join(difflib.unified_diff(
            str(committed).splitlines(True), str(now).splitlines(True), 'committed', 'this run')))

    item.format_output_compare = differs
    return item


def _streams(outputs: list[Any]) -> list[Any]:
    """nbval's stream merging, line ends made one: a command run with `!` writes to a pty,
    whose `\\r\\n` nbclient keeps (the committed outputs) and JupyterLab stores as `\\n`."""
    for output in outputs:
        if output.output_type == 'stream':
            output.text = output.text.replace('\r\n', '\n')
    return list(coalesce_streams(outputs))


def mismatches(ran: Path, reference: Path) -> list[str]:
    """Each checked cell of `reference` whose output in `ran` differs, nbval's way."""
    done = {c.get('id'): c for c in nbformat.read(ran, as_version=4).cells}
    problems = []
    for index, cell in enumerate(nbformat.read(reference, as_version=4).cells):
        if not checked(cell):
            continue
        got = done.get(cell.get('id'))
        if got is None:
            problems.append(f'cell {index} (id {cell.get("id")}) is not in the saved notebook')
            continue
        item = _comparer()
        if not IPyNbCell.compare_outputs(item, _streams(got.outputs), _streams(cell.outputs)):
            why = '\n'.join(str(line) for line in item.comparison_traceback)
            printed = ''.join(f'[{o.name}] {o.text}' for o in got.outputs
                              if o.output_type == 'stream')
            problems.append(f'cell {index}: output differs from the committed one (nbval):\n'
                            f'{cell.source[:200]}\n{why}\nThis run printed:\n{printed}')
    return problems
