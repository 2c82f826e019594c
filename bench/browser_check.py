"""The notebook widgets in a real JupyterLab in a real browser, end to end (not run by CI).

What the headless tests cannot show: that the widgets render in JupyterLab, that a slider
dragged with the mouse reaches the running node, and that the live plot keeps updating
in the page. This script starts JupyterLab from the kit's venv on loopback with a token,
opens copies of the notebooks (the committed ones are never run in place) in headless
Chromium, and:

- 04: runs the cells up to the live plot, counts the plot's image updates in the page
  for `--seconds` (the frame rate the student sees), drags `noise_level` up and
  `temp_threshold` down with the mouse, checks with `robot-lab param get` that the nodes
  took the values, runs the check cell (`/cmd_vel/linear/x` dropped to 0) and shows a
  refusal; screenshots before and after;
- 05: the graph picture and the log console; 06: the recorder, the plot of the bag and
  the player; a launch panel in a scratch notebook.

It needs Debian's chromium and Playwright for Python in a venv of its own (the kit
installs neither; never `playwright install`):

    apt-get install -y chromium
    python3 -m venv /tmp/pw-venv && /tmp/pw-venv/bin/pip install playwright
    /tmp/pw-venv/bin/python bench/browser_check.py /tmp/browser-shots --domain-id 47

Screenshots go to the folder given; the numbers and any problem are printed. Exit code 1
when a check failed.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
VENV_BIN = REPO / '.venv' / 'bin'
CHROMIUM_ARGS = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
                 '--disable-background-networking', '--disable-component-update',
                 '--disable-sync']
# JupyterLab's news pop-up would cover the lower right corner of every screenshot.
LAB_SETTINGS = {'@jupyterlab/apputils-extension/notification': {'fetchNews': 'false'}}

problems: list[str] = []


def note(ok: bool, what: str) -> None:
    print(('✓ ' if ok else '✗ ') + what, flush=True)
    if not ok:
        problems.append(what)


# -- JupyterLab -------------------------------------------------------------------------
@contextmanager
def jupyter_lab(folder: Path, port: int, token: str, env: dict[str, str]) -> Iterator[str]:
    """JupyterLab on 127.0.0.1:port over `folder`; stopped with its kernels at the end."""
    settings = folder.parent / 'lab-settings'
    for plugin, values in LAB_SETTINGS.items():
        file = settings / f'{plugin}.jupyterlab-settings'
        file.parent.mkdir(parents=True, exist_ok=True)
        file.write_text(json.dumps(values))
    runtime = folder.parent / 'runtime'
    base = f'http://127.0.0.1:{port}'
    log = (folder.parent / 'lab.log').open('w')
    lab = subprocess.Popen(
        [str(VENV_BIN / 'jupyter'), 'lab', '--allow-root', '--no-browser', '--ip', '127.0.0.1',
         '--port', str(port), '--notebook-dir', str(folder), f'--ServerApp.token={token}',
         '--ServerApp.port_retries=0'],
        env={**env, 'JUPYTER_RUNTIME_DIR': str(runtime),
             'JUPYTERLAB_WORKSPACES_DIR': str(folder.parent / 'lab-workspaces'),
             'JUPYTERLAB_SETTINGS_DIR': str(settings)},
        stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(f'{base}/api/status?token={token}', timeout=2).read()
                break
            except OSError:
                if lab.poll() is not None or time.monotonic() > deadline:
                    raise SystemExit(f'JupyterLab did not start; see {log.name}') from None
                time.sleep(0.3)
        yield base
    finally:
        shutdown_kernels(base, token)
        lab.terminate()  # SIGTERM: the server stops without asking
        try:
            lab.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(lab.pid, signal.SIGKILL)
            lab.wait()
        log.close()


def shutdown_kernels(base: str, token: str) -> None:
    """Shut every kernel down: the nodes a kernel launched die with it."""
    try:
        auth = {'Authorization': f'token {token}'}  # a token in the URL is GET-only
        kernels = json.loads(urllib.request.urlopen(urllib.request.Request(
            f'{base}/api/kernels', headers=auth), timeout=5).read())
        for kernel in kernels:
            request = urllib.request.Request(
                f'{base}/api/kernels/{kernel["id"]}', headers=auth, method='DELETE')
            urllib.request.urlopen(request, timeout=10).read()
    except OSError as err:
        print(f'could not shut the kernels down: {err}')


# -- the page -----------------------------------------------------------------------------
class Notebook:
    """One notebook open in JupyterLab; cells are addressed by their index in the file."""

    def __init__(self, page: Any, base: str, token: str, name: str) -> None:
        self.page = page
        # A workspace of its own per notebook: JupyterLab restores no other tab (and kernel).
        workspace = re.sub(r'\W', '', name)
        page.goto(f'{base}/lab/workspaces/{workspace}/tree/{name}?token={token}')
        page.wait_for_selector('.jp-Notebook .jp-Cell', timeout=60_000)
        self.wait_idle()
        self.cells = page.locator('.jp-Notebook .jp-Cell')

    def wait_idle(self, timeout: float = 120.0) -> None:
        """Until the status bar says the kernel is idle (keys before that are lost)."""
        deadline = time.monotonic() + timeout
        bar = self.page.locator('.jp-StatusBar-Widget')
        while time.monotonic() < deadline:
            if any('| Idle' in text for text in bar.all_inner_texts()):
                return
            time.sleep(0.2)
        raise SystemExit('the kernel never became idle')

    def cell(self, index: int) -> Any:
        return self.cells.nth(index)

    def run(self, index: int, timeout: float = 120.0) -> list[str]:
        """Run one cell (select it, Shift+Enter), wait for it; its error outputs."""
        cell = self.cell(index)
        for _ in range(20):
            cell.scroll_into_view_if_needed()
            cell.locator('.jp-InputPrompt').first.click()
            if 'jp-mod-active' in (cell.get_attribute('class') or ''):
                break
        else:
            return [f'could not select cell {index}']
        self.page.keyboard.press('Escape')  # command mode: Shift+Enter runs, never types
        self.page.keyboard.press('Shift+Enter')
        if 'jp-CodeCell' not in (cell.get_attribute('class') or ''):
            return []
        prompt = cell.locator('.jp-InputPrompt')
        deadline = time.monotonic() + timeout
        while not re.search(r'\[\d+\]', prompt.inner_text()):
            if time.monotonic() > deadline:
                return [f'cell {index} still running after {timeout:g} s']
            time.sleep(0.1)
        errors = cell.locator('.jp-OutputArea-output[data-mime-type='
                              '"application/vnd.jupyter.stderr"], '
                              '.jp-OutputArea-output[data-mime-type='
                              '"application/vnd.jupyter.error"]')
        return [str(error.text_content())[:400] for error in errors.all()]

    def run_range(self, first: int, last: int) -> None:
        for index in range(first, last + 1):
            errors = self.run(index)
            if errors:
                note(False, f'cell {index} printed an error: {errors}')

    def output(self, index: int) -> Any:
        return self.cell(index).locator('.jp-Cell-outputArea')

    def text(self, index: int) -> str:
        # textContent, not innerText: JupyterLab skips laying out cells scrolled out of
        # view (content-visibility), and their innerText is empty.
        return str(self.output(index).text_content())

    def shot(self, index: int, path: Path) -> None:
        out = self.output(index)
        out.scroll_into_view_if_needed()
        out.screenshot(path=str(path))
        print(f'  screenshot {path} ({path.stat().st_size // 1024} KB)')


def slider_row(nb: Notebook, cell: int, name: str) -> Any:
    return nb.output(cell).locator('.widget-hslider', has=nb.page.locator(
        f'label:text-is("{name}")'))


def drag_slider(nb: Notebook, cell: int, name: str, fraction: float) -> None:
    """Drag the handle of slider `name` with the mouse to `fraction` of its track."""
    row = slider_row(nb, cell, name)
    row.scroll_into_view_if_needed()
    track = row.locator('.noUi-base').bounding_box()
    handle = row.locator('.noUi-handle').bounding_box()
    page = nb.page
    page.mouse.move(handle['x'] + handle['width'] / 2, handle['y'] + handle['height'] / 2)
    page.mouse.down()
    page.mouse.move(track['x'] + fraction * track['width'], track['y'] + track['height'] / 2,
                    steps=12)
    page.mouse.up()


def readout(nb: Notebook, cell: int, name: str) -> float:
    return float(slider_row(nb, cell, name).locator('.widget-readout').inner_text())


def wait_text(nb: Notebook, cell: int, pattern: str, timeout: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if re.search(pattern, nb.text(cell)):
            return True
        time.sleep(0.1)
    return False


def param_get(node: str, name: str, env: dict[str, str]) -> str:
    done = subprocess.run([str(VENV_BIN / 'robot-lab'), 'param', 'get', node, name],
                          env=env, capture_output=True, text=True, timeout=30)
    return (done.stdout + done.stderr).strip()


def subscriptions(topic: str, env: dict[str, str]) -> int:
    """`Subscription count: N` of `robot-lab topic info` (as `ros2 topic info` prints)."""
    done = subprocess.run([str(VENV_BIN / 'robot-lab'), 'topic', 'info', topic], env=env,
                          capture_output=True, text=True, timeout=30)
    found = re.search(r'Subscription count: (\d+)', done.stdout)
    return int(found.group(1)) if found else -1


def reported(text: str) -> float | None:
    """The number in `Double value is: 2.05` (what `ros2 param get` prints)."""
    found = re.search(r'value is: ([-+0-9.eE]+)', text)
    return float(found.group(1)) if found else None


def image_updates(nb: Notebook, cell: int, seconds: float) -> int:
    """How often the plot's <img> got a new picture in `seconds`, counted in the page."""
    image = nb.output(cell).locator('img').first
    image.scroll_into_view_if_needed()
    return int(image.evaluate(
        """(img, ms) => new Promise(done => {
               let n = 0;
               const seen = new MutationObserver(() => { n += 1; });
               seen.observe(img, {attributes: true, attributeFilter: ['src']});
               setTimeout(() => { seen.disconnect(); done(n); }, ms);
           })""", seconds * 1000))


def shows_its_end(output: Any) -> bool:
    """The last log box in `output` overflows and shows its end (the newest lines)."""
    return bool(output.evaluate("""out => {
        const boxes = [...out.querySelectorAll('div[style*="column-reverse"]')]
            .filter(b => b.offsetParent !== null);  // a hidden, empty log is no console
        const box = boxes[boxes.length - 1];
        if (!box || box.scrollHeight <= box.clientHeight) return false;
        const end = box.firstElementChild.getBoundingClientRect().bottom;
        return Math.abs(end - box.getBoundingClientRect().bottom) < 3;
    }"""))


def kernel_cpu(seconds: float) -> float:
    """CPU use of the (one) notebook kernel over `seconds`, in % of one core."""
    pids = [p for p in Path('/proc').iterdir() if p.name.isdigit()
            and b'ipykernel_launcher' in _read(p / 'cmdline')
            and b'robot_lab-browser-' in _read(p / 'cmdline')]
    if len(pids) != 1:
        return float('nan')

    def used() -> float:
        fields = _read(pids[0] / 'stat').rsplit(b')', 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')

    start, begun = used(), time.monotonic()
    time.sleep(seconds)
    return 100.0 * (used() - start) / (time.monotonic() - begun)


def _read(path: Path) -> bytes:
    try:
        return path.read_bytes()
    except OSError:
        return b''


def strays(nb: Notebook, cells: list[int]) -> list[int]:
    """Cells among `cells` that have any output (background output leaking into them)."""
    return [i for i in cells if nb.cell(i).locator('.jp-OutputArea-output').count()]


# -- the checks ---------------------------------------------------------------------------
def check_parameters(page: Any, base: str, token: str, out: Path, env: dict[str, str],
                     seconds: float) -> None:
    print('04_parameters')
    nb = Notebook(page, base, token, '04_parameters.ipynb')
    nb.run_range(0, 23)  # up to the live plot
    sensor, controller, live, check_cell = 20, 21, 23, 26
    rendered = nb.output(live).locator('img').count() == 1
    note(rendered, 'the live plot renders as an image widget')
    note(slider_row(nb, sensor, 'noise_level').count() == 1, 'noise_level renders as a slider')
    note(wait_text(nb, live, r'data: \d+, linear\.x: \d+ samples'),
         'the plot counts samples in its toolbar')
    if not rendered:
        return
    updates = image_updates(nb, live, seconds)
    print(f'  frame rate in the page: {updates / seconds:.1f} image updates/s '
          f'({updates} in {seconds:g} s; the plot asks for 20)')
    note(updates / seconds >= 5, 'the live plot keeps updating in the page (>= 5 frames/s)')
    nb.shot(sensor, out / '04_sliders_before.png')
    nb.shot(live, out / '04_plot_before.png')
    note('Double value is: 0.1' in param_get('/sensor', 'noise_level', env),
         'noise_level starts at 0.1 (from the parameter file)')

    drag_slider(nb, sensor, 'noise_level', 0.4)  # 0 … 5: about 2.0
    drag_slider(nb, controller, 'temp_threshold', 0.4)  # 0 … 50: about 20.0
    note(wait_text(nb, sensor, '✓ set'), 'the sensor sliders show the node took the value')
    note(wait_text(nb, controller, '✓ set'), 'the controller sliders show ✓ set')
    noise = readout(nb, sensor, 'noise_level')
    threshold = readout(nb, controller, 'temp_threshold')
    got_noise = param_get('/sensor', 'noise_level', env)
    got_threshold = param_get('/controller', 'temp_threshold', env)
    print(f'  dragged: noise_level {noise}, temp_threshold {threshold}; '
          f'robot-lab param get: {got_noise!r}, {got_threshold!r}')
    note(1.5 <= noise <= 2.5 and reported(got_noise) == noise,
         'robot-lab param get /sensor noise_level shows the dragged value')
    note(15 <= threshold <= 25 and reported(got_threshold) == threshold,
         'robot-lab param get /controller temp_threshold shows the dragged value')

    errors = nb.run(check_cell, timeout=60)
    passed = '✓' in nb.text(check_cell) and not errors
    note(passed, f'check cell: /cmd_vel/linear/x dropped to 0 and status HIGH {errors or ""}')
    time.sleep(3.0)  # a pause for the picture: three seconds of the drop in the window
    nb.shot(live, out / '04_plot_after.png')
    leaked = strays(nb, [22, 24, 25])
    note(not leaked, f'nothing printed into cells that were not run {leaked}')
    for i in leaked:
        print(f'  cell {i}: {nb.text(i)[:300]!r}')

    errors = nb.run(32)  # sensor.set('noise_level', 9.0): refused, shown by the slider
    note(wait_text(nb, sensor, 'refused'), 'a refusal shows next to the slider')
    nb.shot(sensor, out / '04_sliders_refused.png')

    # A student re-running the plot cell: the old plots must not draw (and subscribe) on.
    # Their subscriptions are visible on the graph: `topic info` counts them.
    before = subscriptions('/sensor/temperature', env)
    running = kernel_cpu(5.0)
    for _ in range(3):
        nb.run(live)
    after = subscriptions('/sensor/temperature', env)
    rerun = kernel_cpu(5.0)
    print(f'  /sensor/temperature subscriptions: {before} with the plot, {after} after '
          f're-running its cell 3 times')
    note(after == before, 'a re-run plot cell replaces its plot (no extra subscriptions)')
    note(nb.output(live).locator('img').count() == 1, 'the re-run cell shows one plot')
    nb.output(live).locator('button:has-text("Pause")').click()
    paused = kernel_cpu(5.0)
    nb.output(live).locator('button:has-text("Pause")').click()
    print(f'  kernel CPU (% of a core, 5 s each): {running:.0f} live plot, {rerun:.0f} after '
          f'the re-runs, {paused:.0f} paused')


def check_inspect(page: Any, base: str, token: str, out: Path) -> None:
    print('05_inspect_and_verify')
    nb = Notebook(page, base, token, '05_inspect_and_verify.ipynb')
    nb.run_range(0, 24)
    graph = nb.output(20)
    note(graph.locator('img, svg').count() > 0, 'the graph picture renders')
    nb.shot(20, out / '05_graph.png')
    note(wait_text(nb, 22, r'\[robot\]: Status: OK'), 'the console shows records after the '
         'filter changed to INFO/robot')
    nb.shot(22, out / '05_console.png')


def check_bags(page: Any, base: str, token: str, out: Path) -> None:
    print('06_ros_bags')
    nb = Notebook(page, base, token, '06_ros_bags.ipynb')
    nb.run_range(0, 19)
    note(wait_text(nb, 7, r'/sensor/temperature'), 'the recorder shows its topics')
    nb.shot(7, out / '06_recorder.png')
    note(nb.output(12).locator('img').count() == 1, 'the plot of the bag renders')
    nb.shot(12, out / '06_bag_plot.png')
    nb.shot(17, out / '06_player.png')


def check_launch_panel(page: Any, base: str, token: str, out: Path, folder: Path) -> None:
    print('launch panel')
    cells = [
        'import robot_lab\nfrom robot_lab.grading import setup\nsetup("00_panel")',
        "panel = robot_lab.launch_panel('robot_lab', 'robot.launch.xml')\npanel",
    ]
    notebook = {'cells': [{'cell_type': 'code', 'metadata': {}, 'source': s, 'outputs': [],
                           'execution_count': None} for s in cells],
                'metadata': {'kernelspec': {'name': 'robot_lab', 'language': 'python',
                                            'display_name': 'robot_lab (ROS 2 Jazzy)'}},
                'nbformat': 4, 'nbformat_minor': 5}
    (folder / 'launch_panel.ipynb').write_text(json.dumps(notebook))
    nb = Notebook(page, base, token, 'launch_panel.ipynb')
    nb.run_range(0, 1)
    panel = nb.output(1)
    panel.locator('button:has-text("Start")').click()
    note(wait_text(nb, 1, r'robot_node-3 /robot — running', timeout=20),
         'Start launches; the panel shows three running processes')
    note(wait_text(nb, 1, r'Status: OK', timeout=20), 'the console shows their output')
    time.sleep(2.0)  # let the console fill past its height
    note(shows_its_end(panel), 'the console is scrolled to its newest line')
    nb.shot(1, out / 'launch_panel_running.png')
    panel.locator('button:has-text("Stop")').click()
    note(wait_text(nb, 1, r'finished', timeout=20), 'Stop ends them')
    nb.shot(1, out / 'launch_panel_stopped.png')


def clear_outputs(path: Path) -> None:
    """Drop the committed outputs of a copy: what the page shows is then this run's."""
    notebook = json.loads(path.read_text())
    for cell in notebook['cells']:
        if cell['cell_type'] == 'code':
            cell['outputs'] = []
            cell['execution_count'] = None
    path.write_text(json.dumps(notebook, indent=1))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('out', type=Path, help='folder for the screenshots')
    parser.add_argument('--domain-id', type=int, default=47)
    parser.add_argument('--port', type=int, default=8899)
    parser.add_argument('--seconds', type=float, default=10.0,
                        help='how long to count plot updates')
    parser.add_argument('--chromium', default='/usr/bin/chromium')
    parser.add_argument('--only', choices=['04', '05', '06', 'panel'], action='append')
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    args.out.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix='robot_lab-browser-'))
    folder = scratch / 'notebooks'
    shutil.copytree(REPO / 'notebooks', folder)
    for copy in folder.glob('*.ipynb'):
        clear_outputs(copy)
    env = {k: v for k, v in os.environ.items() if k not in {
        'ROBOT_LAB_TEST_DOMAIN_BASE', 'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', 'ROBOT_LAB_HEADLESS',
        'CI'}}  # a test run's settings would make the kernel headless
    env.update(ROS_DOMAIN_ID=str(args.domain_id), ROBOT_LAB_HEADLESS='0',
               ROBOT_LAB_WORKSPACE=str(scratch / 'robot_lab_ws'))
    token = os.urandom(12).hex()
    only = set(args.only or ['04', '05', '06', 'panel'])
    try:
        with jupyter_lab(folder, args.port, token, env) as base, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=args.chromium, args=CHROMIUM_ARGS,
                                         headless=True)
            checks = {
                '04': lambda page: check_parameters(page, base, token, args.out, env,
                                                    args.seconds),
                '05': lambda page: check_inspect(page, base, token, args.out),
                '06': lambda page: check_bags(page, base, token, args.out),
                'panel': lambda page: check_launch_panel(page, base, token, args.out, folder),
            }
            for name, run in checks.items():
                if name not in only:
                    continue
                # One page and one kernel per notebook: two launches of robot.launch.xml
                # in one ROS domain would be two /sensor nodes.
                page = browser.new_page(viewport={'width': 1100, 'height': 900})
                page.on('pageerror', lambda err: note(False, f'page error: {err}'))
                try:
                    run(page)
                finally:
                    page.close()
                    shutdown_kernels(base, token)
            browser.close()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    print(f'{len(problems)} problem(s)' if problems else 'all browser checks passed')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
