"""Feedback a student reads where they are: a single student's `robot-lab grade -o OUT` says
only what it wrote (no similarity report), and the feedback page shows the running graph
inside a notebook (the picture embedded as a data URI, as notebook 07 displays it, not a
link to a file beside the page, which a notebook elsewhere cannot reach).

One real grading run of the reference package (build, launch, watch); the page is then shown
as notebook 07 shows it (an IPython Markdown output) in JupyterLab in a real Chromium.
"""

from __future__ import annotations

import base64
import json
import os
import re
import shutil
import signal
import subprocess
import time
import urllib.request
from pathlib import Path

import nbformat
import pytest
from conftest import BIN, REPO, run_cli
from lab_chromium import free_port, headless_chromium

DATA = REPO / 'tests' / 'data' / 'class_ch6'
CONFIG = REPO / 'config' / 'jupyter' / 'jupyter_server_config.py'
_IMAGE = re.compile(r'!\[your running graph\]\((data:image/png;base64,([A-Za-z0-9+/=]+))\)')


@pytest.fixture(scope='module')
def graded(tmp_path_factory: pytest.TempPathFactory) -> tuple[subprocess.CompletedProcess[str],
                                                                Path]:
    root = tmp_path_factory.mktemp('one')
    shutil.copytree(DATA / 'reference', root / 'alice')
    out = tmp_path_factory.mktemp('out')
    # A report left by an earlier run of a whole class: this run must not claim it.
    stale = out / 'similarity.html'
    stale.write_text('<p>an earlier class</p>\n')
    os.utime(stale, (time.time() - 3600, time.time() - 3600))
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), timeout=900)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done, out


def test_grade_says_only_what_it_wrote(graded: tuple[subprocess.CompletedProcess[str],
                                                     Path]) -> None:
    done, out = graded
    said = done.stdout + done.stderr
    wrote = [line for line in said.splitlines() if line.startswith('wrote ')]
    assert len(wrote) == 1 and 'grades.csv' in wrote[0], said
    assert 'similarity' not in said, said  # one student: nothing compared, nothing written
    assert (out / 'similarity.html').read_text() == '<p>an earlier class</p>\n'


def test_feedback_embeds_the_graph(graded: tuple[subprocess.CompletedProcess[str],
                                                 Path]) -> None:
    _done, out = graded
    page = (out / 'feedback' / 'alice.md').read_text()
    found = _IMAGE.search(page)
    assert found, 'no embedded graph in the feedback'
    picture = base64.b64decode(found.group(2))
    assert picture[:4] == b'\x89PNG'
    assert picture == (out / 'feedback' / 'alice.graph.png').read_bytes()
    assert '](alice.graph.png)' not in page
    assert f'src="{found.group(1)}"' in (out / 'feedback' / 'alice.html').read_text()


def _shown_pictures(notebook: Path, shots: Path) -> list[int]:
    """JupyterLab (the kit's config) opens `notebook` in Chromium: the natural width of each
    picture in its Markdown outputs (0: the browser could not load it)."""
    port, token = free_port(), os.urandom(8).hex()
    home = notebook.parent
    env = {**os.environ, 'JUPYTER_RUNTIME_DIR': str(home / 'runtime'),
           'JUPYTER_CONFIG_DIR': str(home / 'config'), 'JUPYTER_DATA_DIR': str(home / 'data'),
           'JUPYTERLAB_WORKSPACES_DIR': str(home / 'workspaces')}
    with (home / 'lab.log').open('wb') as log:
        lab = subprocess.Popen(
            [str(BIN / 'jupyter'), 'lab', f'--config={CONFIG}', '--allow-root', '--no-browser',
             f'--ServerApp.port={port}', '--ServerApp.port_retries=0',
             f'--ServerApp.root_dir={home}', f'--IdentityProvider.token={token}'],
            env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    base = f'http://127.0.0.1:{port}'
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                urllib.request.urlopen(f'{base}/api/status?token={token}', timeout=5)
                break
            except OSError:
                assert lab.poll() is None and time.monotonic() < deadline, \
                    (home / 'lab.log').read_text()[-3000:]
                time.sleep(0.2)  # polling the server's own readiness answer
        with headless_chromium() as browser:
            page = browser.new_page()
            page.goto(f'{base}/lab/tree/{notebook.name}?token={token}')
            pictures = page.locator('.jp-OutputArea-output img')
            pictures.first.wait_for(state='attached', timeout=120_000)
            # Until every picture has either loaded or failed (img.complete).
            page.wait_for_function(
                'n => { const all = document.querySelectorAll(".jp-OutputArea-output img");'
                ' return all.length === n && [...all].every(i => i.complete); }',
                arg=2, timeout=60_000)
            widths = pictures.evaluate_all('all => all.map(i => i.naturalWidth)')
            page.screenshot(path=str(shots), full_page=True)
    finally:
        os.killpg(lab.pid, signal.SIGTERM)
        try:
            lab.wait(30)
        except subprocess.TimeoutExpired:  # its kernel still shutting down: not our test
            os.killpg(lab.pid, signal.SIGKILL)
            lab.wait()
    return [int(w) for w in widths]


@pytest.mark.browser
def test_feedback_shows_the_graph_in_a_notebook(
        graded: tuple[subprocess.CompletedProcess[str], Path], tmp_path: Path) -> None:
    """Notebook 07's way, `Markdown(feedback.read_text())`, in a notebook that is not next to
    the page: the embedded picture loads; the relative link it replaced does not."""
    _done, out = graded
    page = (out / 'feedback' / 'alice.md').read_text()
    linked = _IMAGE.sub('![your running graph](alice.graph.png)', page)
    nb = nbformat.v4.new_notebook()
    for text in (page, linked):
        cell = nbformat.v4.new_code_cell('Markdown(feedback.read_text())')
        cell.outputs = [nbformat.v4.new_output(
            'execute_result', data={'text/markdown': text, 'text/plain': '<Markdown>'},
            execution_count=1)]
        nb.cells.append(cell)
    notebook = tmp_path / 'capstone_feedback.ipynb'
    notebook.write_text(json.dumps(nb))
    embedded, relative = _shown_pictures(notebook, tmp_path / 'feedback.png')
    assert embedded > 100, 'the embedded graph did not load'
    assert relative == 0, 'the control case: a relative link should not load here'
