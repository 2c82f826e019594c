"""The course in a real browser: every notebook run as a student runs it, and what they see.

One JupyterLab (loopback, token) and one headless Chromium for the session, over a scratch
copy of the course. Each notebook is opened in the page and run in course order (a notebook
builds on the workspace of the ones before), a stretch of cells at a time as a student runs
one (selected, Shift+Enter), each stretch ending at a cell that shows widgets. After such a
cell its widgets are probed in the page: a live plot draws and its sample
counts grow, a dragged slider reaches the running node and changes what the plot shows,
the robot view moves, the graph view fits the column and names the launched nodes. Then:
no error output, no "Error displaying widget", every code cell ran. Screenshots of every
widget and notebook go to the folder printed at the end (ROBOT_LAB_BROWSER_SHOTS to choose).
Last, the notebook is saved and the cells marked `# NBVAL_CHECK_OUTPUT` must show what the
committed notebook shows (output_check.py, nbval's comparison): this is the course's nbval
run, so `./kit test` does not run the notebooks a third time.
"""

from __future__ import annotations

import base64
import json
import os
import re
import shutil
import subprocess
import tempfile
import time
import urllib.parse
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import browser_lab
import output_check
import pytest
from browser_lab import REPO, VENV_BIN, Lab, Notebook, wait_until

# A test runs the notebooks before its own first (course order): more than one's timeout.
pytestmark = [pytest.mark.browser, pytest.mark.timeout(900)]

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()

NOTEBOOKS = sorted(p.name for p in (REPO / 'notebooks').glob('[0-9]*.ipynb'))
WIDGET_MIME = 'application/vnd.jupyter.widget-view+json'
# Cells whose widgets are probed while the system they watch still runs.
SHOWS_WIDGETS = re.compile(r'robot_lab\.(plot|sliders|robot_view|graph_view|console)\(')


DOMAIN_BASE = browser_lab.domain_base()


def lesson_domain(name: str) -> int:
    """The ROS domain a lesson's kernel uses (robot_lab.grading.course._domain)."""
    found = re.match(r'\D*(\d+)', name)
    return (DOMAIN_BASE + (int(found.group(1)) if found else 0)) % 102


@dataclass
class Run:
    """What one notebook showed: problems found while it ran, and its screenshots."""

    name: str
    problems: list[str] = field(default_factory=list)
    probed: list[str] = field(default_factory=list)
    seconds: float = 0.0


class Course:
    """Runs notebooks in course order, each once, in the session's JupyterLab."""

    def __init__(self, lab: Lab, browser: Any, shots: Path) -> None:
        self.lab = lab
        self.browser = browser
        self.shots = shots
        self.runs: dict[str, Run] = {}
        self._page: Any = None

    def page(self) -> Any:
        """The session's one JupyterLab page: each notebook opens in it, as a student's do."""
        if self._page is None or self._page.is_closed():
            self._page = self.browser.new_page(viewport={'width': 1280, 'height': 900})
            self._page.set_default_timeout(30_000)
        return self._page

    def done(self, page: Any) -> None:
        """Close the notebooks open in `page` and end their kernels."""
        browser_lab.close_notebooks(page, self.lab)

    def run(self, name: str) -> Run:
        for earlier in NOTEBOOKS[:NOTEBOOKS.index(name)]:
            if earlier not in self.runs:
                self._run(earlier)
        if name not in self.runs:
            self._run(name)
        return self.runs[name]

    def _run(self, name: str) -> None:
        result = self.runs[name] = Run(name)
        start = time.monotonic()
        page = self.page()
        errors: list[str] = []

        def page_error(err: Any) -> None:
            errors.append(f'page error: {err}')

        page.on('pageerror', page_error)
        try:
            nb = Notebook(page, self.lab, f'notebooks/{name}')
            kinds = nb.kinds()
            probes = [i for i, (kind, text) in enumerate(kinds)
                      if kind == 'code' and SHOWS_WIDGETS.search(text)]
            first = 0
            for last in [*probes, len(kinds) - 1]:
                if last < first:
                    continue
                try:
                    nb.run_cells(first, last)
                except AssertionError as err:
                    result.problems.append(str(err))
                    break
                if last in probes:
                    Probe(nb, last, result, self.shots).all()
                first = last + 1
            result.problems += [f'error output: {e}' for e in nb.errors()]
            result.problems += [f'cell {i} never ran' for i in nb.unrun()]
            result.problems += unrendered(nb)
            result.problems += output_check.mismatches(nb.save(), REPO / 'notebooks' / name)
            whole_notebook(page, self.shots / f'{Path(name).stem}.png')
        finally:
            page.remove_listener('pageerror', page_error)
            result.problems += errors
            self.done(page)
            result.seconds = time.monotonic() - start


def whole_notebook(page: Any, path: Path) -> None:
    """A screenshot of the whole notebook: the window made as tall as its content."""
    height = int(page.evaluate(
        "() => Math.max(...[...document.querySelectorAll('.jp-NotebookPanel .jp-Notebook, "
        ".jp-NotebookPanel .jp-WindowedPanel-outer')].map(n => n.scrollHeight), 900)"))
    size = page.viewport_size
    page.set_viewport_size({'width': size['width'], 'height': min(height + 200, 30_000)})
    try:
        page.screenshot(path=str(path))
    finally:
        page.set_viewport_size(size)


def unrendered(nb: Notebook) -> list[str]:
    """Widget outputs that show no widget (the student would see an empty box)."""
    missing = []
    outputs = nb.page.locator(f'.jp-NotebookPanel:visible .jp-OutputArea-output'
                              f'[data-mime-type="{WIDGET_MIME}"]')
    for k in range(outputs.count()):
        if outputs.nth(k).locator('.jupyter-widgets').count() == 0:
            missing.append(f'widget output {k} rendered nothing: '
                           f'{outputs.nth(k).text_content()!r:.200}')
    return missing


class Probe:
    """Checks the widgets one cell shows, while the system the notebook started runs."""

    def __init__(self, nb: Notebook, index: int, result: Run, shots: Path) -> None:
        self.nb = nb
        self.index = index
        self.result = result
        self.out = nb.output(index)
        self.source = nb.source(index)
        self.stem = f'{Path(nb.path).stem}_cell{index:02d}'
        self.shots = shots

    def fail(self, what: str) -> None:
        self.result.problems.append(f'cell {self.index}: {what}')

    def shot(self, locator: Any, what: str) -> None:
        try:
            self.nb.shot(locator, self.shots / f'{self.stem}_{what}.png')
        except Exception as err:  # a picture is evidence, not the check itself
            self.result.problems.append(f'cell {self.index}: no screenshot of {what}: {err}')

    def all(self) -> None:
        if self.out.locator('.rl-chart').count():
            self.chart()
        if self.out.locator('.rl-pose').count():
            self.pose()
        if self.out.locator('.robot-lab-widget .widget-hslider').count():
            self.sliders()
        if 'graph_view(' in self.source and self.out.locator('img').count():
            self.graph()
        if self.out.locator('.robot-lab-widget select').count() == 2:
            self.console()

    def chart(self) -> None:
        self.result.probed.append('plot')
        root = self.out.locator('.rl-chart').first
        root.scroll_into_view_if_needed()
        live = 'bag=' not in self.source
        if not wait_until(lambda: browser_lab.frames(root) > 0, 10):
            self.fail('the plot never drew a frame')
            return
        if live:
            first_frames, first_total = browser_lab.frames(root), sample_total(root)
            moved = wait_until(lambda: browser_lab.frames(root) >= first_frames + 10
                               and sample_total(root) > first_total, 10)
            if not moved:
                self.fail(f'the live plot does not update in the page (frames '
                          f'{first_frames} -> {browser_lab.frames(root)}, samples '
                          f'{first_total} -> {sample_total(root)})')
        self.shot(self.out, 'plot')

    def pose(self) -> None:
        self.result.probed.append('robot view')
        root = self.out.locator('.rl-pose').first
        root.scroll_into_view_if_needed()

        def where() -> tuple[str | None, str | None]:
            return root.get_attribute('data-x'), root.get_attribute('data-y')

        wait_until(lambda: where()[0] is not None, 10)
        first = where()
        if not wait_until(lambda: where() != first, 10):
            self.fail(f'the robot view does not move (stays at {first})')
        self.shot(self.out, 'robot_view')

    def sliders(self) -> None:
        """Drag a slider with the mouse: the node takes it, the plot shows the change."""
        self.result.probed.append('sliders')
        page = self.nb.page
        rows = self.out.locator('.robot-lab-widget .widget-hslider')
        named = self.out.locator('.robot-lab-widget .widget-hslider',
                                 has=page.locator('label:text-is("noise_level")'))
        row = named.first if named.count() else rows.first
        name = str(row.locator('label').first.text_content()).strip()
        box = row.locator('xpath=ancestor::div[contains(@class,"robot-lab-widget")][1]')
        node = str(box.locator('b').first.text_content()).strip()
        chart = self.nb.page.locator('.jp-NotebookPanel:visible .rl-chart').last
        panels_before = chart.get_attribute('data-ylims') if chart.count() else None
        self.shot(self.out, 'sliders_before')
        browser_lab.drag(page, row, 0.8)
        if not wait_until(lambda: '✓ set' in str(box.text_content()), 10):
            self.fail(f'dragging {node} {name} showed no "✓ set": {box.text_content()!r:.300}')
            return
        readout = float(str(row.locator('.widget-readout').inner_text()))
        reported = browser_lab.param_get(node, name, lesson_domain(self.nb.path))
        found = re.search(r'value is: ([-+0-9.eE]+)', reported)
        if not found or abs(float(found.group(1)) - readout) > 1e-6:
            self.fail(f'dragged {node} {name} to {readout}, but param get says {reported!r}')
        focused = page.evaluate('() => !!document.activeElement?.closest?.(".widget-slider")')
        if focused:
            self.fail('the slider kept keyboard focus after the drag')
        if name == 'noise_level' and panels_before is not None:
            changed = wait_until(lambda: chart.get_attribute('data-ylims') != panels_before, 10)
            if not changed:
                self.fail(f'the plot did not change after noise_level went to {readout}')
            self.shot(chart, 'plot_after_drag')
        self.shot(self.out, 'sliders_after')

    def graph(self) -> None:
        """The picture fits the notebook column and names the nodes that are running."""
        self.result.probed.append('graph view')
        img = self.out.locator('img').first
        img.scroll_into_view_if_needed()
        width = float(img.evaluate('i => i.getBoundingClientRect().width'))
        column = float(self.out.evaluate('o => o.getBoundingClientRect().width'))
        if width > min(960.0, column) + 1:
            self.fail(f'the graph view is {width:.0f} px wide in a {column:.0f} px column')
        picture = svg_text(str(img.get_attribute('src') or ''))
        nodes = node_list(lesson_domain(self.nb.path))
        missing = [n for n in nodes if n.rsplit('/', 1)[-1] not in picture]
        if not nodes or missing:
            self.fail(f'the graph view does not show the running nodes {missing or nodes}')
        self.shot(self.out, 'graph')

    def console(self) -> None:
        """Records show; choosing INFO in the level menu shows the nodes' INFO lines."""
        self.result.probed.append('console')
        records = r'\[(INFO|WARN|ERROR)\]'
        text = lambda: str(self.out.text_content())  # noqa: E731
        if not wait_until(lambda: re.search(records, text()) is not None, 3):
            self.out.locator('select').first.select_option('INFO')
            if not wait_until(lambda: '[INFO]' in text(), 10):
                self.fail(f'the log console shows no records, even at INFO: {text()[:300]!r}')
        self.shot(self.out, 'console')


def sample_total(root: Any) -> int:
    """The sum of the sample counts the plot's status line shows."""
    text = str(root.locator('.rl-status').text_content() or '')
    return sum(int(n) for n in re.findall(r': (\d+)', text))


def svg_text(src: str) -> str:
    """The text of an SVG image's data URI (matplotlib keeps each label in a comment)."""
    if not src.startswith('data:image/svg+xml'):
        return ''
    head, _, data = src.partition(',')
    if head.endswith(';base64'):
        return base64.b64decode(data).decode(errors='replace')
    return urllib.parse.unquote(data)


def node_list(domain: int) -> list[str]:
    env = {**os.environ, 'ROS_DOMAIN_ID': str(domain)}
    done = subprocess.run([str(VENV_BIN / 'robot-lab'), 'node', 'list'], env=env,
                          capture_output=True, text=True, timeout=30)
    return [line.strip() for line in done.stdout.splitlines() if line.startswith('/')]


# -- the session: one JupyterLab, one Chromium ------------------------------------------------
@pytest.fixture(scope='session')
def shots(request: pytest.FixtureRequest) -> Iterator[Path]:
    folder = Path(os.environ.get('ROBOT_LAB_BROWSER_SHOTS')
                  or Path(tempfile.gettempdir()) / f'robot_lab-browser-shots-{os.getuid()}')
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    yield folder
    reporter = request.config.pluginmanager.get_plugin('terminalreporter')
    if reporter is not None:
        reporter.write_line(f'browser screenshots: {folder}')


@pytest.fixture(scope='module')  # Playwright's sync loop must not outlive these tests
def course(shots: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Course]:
    scratch = tmp_path_factory.mktemp('browser')
    root = scratch / 'course'
    for part in ('notebooks', 'exercises'):
        shutil.copytree(REPO / part, root / part)
        for copy in (root / part).glob('*.ipynb'):
            browser_lab.clear_outputs(copy)
    env = browser_lab.lab_environment(scratch, DOMAIN_BASE)
    with browser_lab.jupyter_lab(root, env) as lab, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=browser_lab.CHROMIUM_ARGS)
        try:
            yield Course(lab, browser, shots)
        finally:
            browser.close()


# -- the tests --------------------------------------------------------------------------------
@pytest.mark.parametrize('name', NOTEBOOKS)
def test_notebook_runs_clean_in_the_browser(course: Course, name: str) -> None:
    run = course.run(name)
    assert not run.problems, f'{name} ({run.seconds:.0f} s):\n' + '\n'.join(run.problems)


def _with(call: str) -> list[str]:
    """The notebooks with a code cell that makes this call."""
    def code(name: str) -> str:
        cells = json.loads((REPO / 'notebooks' / name).read_text())['cells']
        return '\n'.join(''.join(c['source']) for c in cells if c['cell_type'] == 'code')

    return [name for name in NOTEBOOKS if call in code(name)]


@pytest.mark.parametrize('name', _with('robot_lab.sliders('))
def test_sliders_reach_the_node_and_change_the_plot(course: Course, name: str) -> None:
    run = course.run(name)
    assert 'sliders' in run.probed, f'{name} showed no sliders in the page'
    assert not [p for p in run.problems if 'slider' in p or 'dragg' in p or 'plot' in p]


@pytest.mark.parametrize('name', _with('robot_lab.plot('))
def test_live_plots_update_in_the_page(course: Course, name: str) -> None:
    run = course.run(name)
    assert 'plot' in run.probed, f'{name} showed no plot in the page'
    assert not [p for p in run.problems if 'plot' in p]


@pytest.mark.parametrize('name', _with('robot_lab.robot_view('))
def test_the_robot_view_moves(course: Course, name: str) -> None:
    run = course.run(name)
    assert 'robot view' in run.probed, f'{name} showed no robot view in the page'
    assert not [p for p in run.problems if 'robot view' in p]


@pytest.mark.parametrize('name', _with('robot_lab.graph_view('))
def test_the_graph_view_fits_and_shows_the_nodes(course: Course, name: str) -> None:
    run = course.run(name)
    assert 'graph view' in run.probed, f'{name} showed no graph view in the page'
    assert not [p for p in run.problems if 'graph view' in p]


def test_launch_panel_lights_follow_the_launch(course: Course) -> None:
    """Start launches the reference system, the lights turn green, Stop ends it."""
    source = ('import robot_lab\nfrom robot_lab.grading import setup\nsetup("08_panel")\n'
              "panel = robot_lab.launch_panel('robot_lab', 'robot.launch.xml')\npanel")
    path = course.lab.root / 'notebooks' / 'launch_panel.ipynb'
    path.write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'metadata': {}, 'source': source, 'outputs': [],
                   'execution_count': None}],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'language': 'python',
                                    'display_name': 'robot_lab (ROS 2 Jazzy)'}},
        'nbformat': 4, 'nbformat_minor': 5}))
    page = course.page()
    try:
        nb = Notebook(page, course.lab, 'notebooks/launch_panel.ipynb')
        nb.run(0)
        panel = nb.output(0)
        panel.locator('button:has-text("Start")').click()
        running = panel.locator('span[title="running"]')  # the green lights
        assert wait_until(lambda: running.count() == 3, 30), nb.text(0)
        assert wait_until(lambda: 'Status: OK' in nb.text(0), 20), nb.text(0)
        nb.shot(panel, course.shots / 'launch_panel_running.png')
        panel.locator('button:has-text("Stop")').click()
        assert wait_until(lambda: running.count() == 0, 30), nb.text(0)
        assert panel.locator('span[title="finished"]').count() == 3, nb.text(0)
        nb.shot(panel, course.shots / 'launch_panel_stopped.png')
        assert nb.errors() == []
    finally:
        course.done(page)


def test_an_exercise_opened_from_the_file_browser_checks_the_answer(course: Course) -> None:
    """exercises/ from the file browser; the check says what is missing, then passes."""
    page = course.page()
    try:
        page.goto(f'{course.lab.base}/lab/workspaces/exercise?token={course.lab.token}')
        listing = page.locator('.jp-DirListing-content')
        listing.locator('.jp-DirListing-item:has-text("exercises")').dblclick()
        listing.locator('.jp-DirListing-item:has-text("ex01_create_package")').dblclick()
        page.wait_for_selector('.jp-NotebookPanel:visible .jp-Cell')
        nb = Notebook.__new__(Notebook)
        nb.page, nb.lab, nb.path = page, course.lab, 'exercises/ex01_create_package.ipynb'
        nb.cells = page.locator('.jp-NotebookPanel:visible .jp-Notebook .jp-Cell')
        nb.wait_idle()
        cells = [nb.source(i) for i in range(nb.count())]
        setup = next(i for i, s in enumerate(cells) if "setup('ex01" in s)
        answer = next(i for i, s in enumerate(cells) if 'YOUR CODE HERE' in s)
        check = answer + 1
        nb.run(setup)
        nb.run(check)  # no answer yet: the check says what is missing
        assert re.search(r'temperature_tools|package\.xml', nb.text(check)), nb.text(check)
        assert nb.errors(), 'a check without an answer passed'
        nb.select(answer)
        page.keyboard.press('Enter')  # edit mode
        page.keyboard.press('Control+a')
        page.keyboard.insert_text(
            "robot_lab.create_package('temperature_tools', ws / 'src', "
            "dependencies=['rclpy', 'std_msgs'], node_name='hello_node')")
        nb.run(answer)
        nb.run(check)
        assert '✓ temperature_tools depends on rclpy, std_msgs' in nb.text(check), \
            nb.text(check)
        nb.shot(nb.cell(check), course.shots / 'exercise_ex01_check.png')
    finally:
        course.done(page)


def scratch_notebook(course: Course, name: str, cells: list[str]) -> str:
    """A notebook of `cells` in the served course; its path for Notebook()."""
    (course.lab.root / 'notebooks' / name).write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'metadata': {}, 'source': s, 'outputs': [],
                   'execution_count': None} for s in cells],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'language': 'python',
                                    'display_name': 'robot_lab (ROS 2 Jazzy)'}},
        'nbformat': 4, 'nbformat_minor': 5}))
    return f'notebooks/{name}'


def test_widgets_look_disconnected_after_a_kernel_restart(course: Course) -> None:
    """Old controls must not look usable; a stop cell still runs in the new kernel."""
    path = scratch_notebook(course, 'restart.ipynb', [
        'import robot_lab\nfrom robot_lab.grading import setup\nsetup("08_restart")\n'
        'logs = robot_lab.console()\nlogs',
        'import robot_lab\nprint("closed", robot_lab.close_widgets())',
    ])
    page = course.page()
    try:
        nb = Notebook(page, course.lab, path)
        nb.run(0)
        box = nb.output(0).locator('.robot-lab-widget').first
        box.wait_for()
        assert 'jupyter-widgets-disconnected' not in (box.get_attribute('class') or '')
        page.locator('.lm-MenuBar-itemLabel:text-is("Kernel")').click()
        page.locator('.lm-Menu-itemLabel:text-is("Restart Kernel…")').click()
        page.locator('.jp-Dialog button:has-text("Restart")').click()
        assert wait_until(lambda: 'jupyter-widgets-disconnected' in
                          (box.get_attribute('class') or ''), 30)
        looks = box.evaluate("""b => ({opacity: getComputedStyle(b).opacity,
                                      events: getComputedStyle(b).pointerEvents,
                                      label: getComputedStyle(b, '::after').content})""")
        assert float(looks['opacity']) < 0.6 and looks['events'] == 'none', looks
        assert 'disconnected' in looks['label'], looks
        nb.shot(nb.output(0), course.shots / 'restart_disconnected.png')
        nb.wait_idle()
        nb.run(1)  # the new kernel made no widgets: nothing to close, nothing fails
        assert 'closed 0' in nb.text(1) and nb.errors() == [], nb.text(1)
    finally:
        course.done(page)
