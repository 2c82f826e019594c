"""JupyterLab in a real headless Chromium: the server, the page, and what a student sees.

One JupyterLab per test session, on 127.0.0.1 with a token, over a scratch copy of the
course (notebooks and exercises, their committed outputs cleared), kernels not headless,
so the widgets draw live. Debian's chromium through Playwright's `executable_path`: a
browser is never downloaded. Also used by `bench/bench_widgets.py --browser`.
"""

from __future__ import annotations

import base64
import importlib.util
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
VENV_BIN = Path(sys.prefix) / 'bin'  # the venv pytest runs in (./kit test --python X: its own)
CHROMIUM_ARGS = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
                 '--disable-background-networking', '--disable-component-update',
                 '--disable-sync', '--disable-dev-shm-usage']
# JupyterLab's news pop-up would cover the lower right corner of every screenshot; a
# windowed notebook keeps only the cells in view in the page (a cell count would stop
# there, a screenshot of the notebook would be a window of it).
# autosave off: a save the test did not ask for (every 120 s) would truncate and rewrite
# the file while the test reads it, and clear the "unsaved" mark before the test's own.
LAB_SETTINGS = {'@jupyterlab/apputils-extension/notification': {'fetchNews': 'false'},
                '@jupyterlab/notebook-extension/tracker': {'windowingMode': 'none'},
                '@jupyterlab/docmanager-extension/plugin': {'autosave': False}}
ERROR_MIME = 'application/vnd.jupyter.error'
# Page-side pieces the waits share (JavaScript): a cell that ran shows its number, `[3]`;
# the visible notebook's code cells first..last that hold code, with their indices (an
# empty one is never run, so never numbered).
NUMBERED_JS = r"cell => /\[\d+\]/.test(cell.querySelector('.jp-InputPrompt')?.textContent || '')"
CODE_CELLS_JS = r"""(a, b) => [...document.querySelectorAll(
        '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-Notebook .jp-Cell')]
    .map((cell, index) => ({cell, index})).slice(a, b + 1)
    .filter(({cell}) => cell.classList.contains('jp-CodeCell')
        && (cell.querySelector('.jp-InputArea-editor')?.textContent || '').trim())"""


def domain_base(offset: int = 80) -> int:
    """A browser module's lesson domains: base + lesson number (tests/conftest.py's layout:
    the course at 80-90, the mistakes' 01-03 at 77-79, so the two modules can run at once)."""
    base = os.environ.get('ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', '').strip()
    if base:
        return int(base)
    return (int(os.environ.get('ROBOT_LAB_TEST_DOMAIN_BASE', '0') or 0) + offset) % 92


def chromium() -> str | None:
    """Debian's chromium, or $ROBOT_LAB_CHROMIUM; None when neither is installed."""
    for candidate in (os.environ.get('ROBOT_LAB_CHROMIUM'), shutil.which('chromium'),
                      '/usr/bin/chromium'):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    return None


def browser_path() -> str | None:
    """Chromium's path when it and Playwright are both here, so the browser tests run:
    `./kit test` then leaves the notebooks to them, and runs nbval over notebooks/ only
    when this is None."""
    found = chromium()
    return found if found and importlib.util.find_spec('playwright') is not None else None


def browser_or_skip() -> tuple[str, Any]:
    """Debian's chromium and Playwright's sync_playwright; a test module without them skips."""
    import pytest

    found = browser_path()
    if found is None:
        pytest.skip('needs Debian chromium and playwright (apt-get install -y chromium)',
                    allow_module_level=True)
    from playwright.sync_api import sync_playwright

    return found, sync_playwright


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return int(sock.getsockname()[1])


def clear_outputs(path: Path) -> None:
    """Drop a copy's committed outputs: what the page shows is then this run's."""
    notebook = json.loads(path.read_text())
    for cell in notebook['cells']:
        if cell['cell_type'] == 'code':
            cell['outputs'] = []
            cell['execution_count'] = None
    notebook.get('metadata', {}).pop('widgets', None)
    path.write_text(json.dumps(notebook, indent=1))


def lab_environment(scratch: Path, domain_base: int) -> dict[str, str]:
    """The kernels' environment: live widgets, lesson domains from `domain_base`."""
    env = {k: v for k, v in os.environ.items() if k not in {
        'ROBOT_LAB_TEST_DOMAIN_BASE', 'ROBOT_LAB_HEADLESS', 'CI', 'ROS_DOMAIN_ID',
        'PYTEST_CURRENT_TEST', 'JUPYTER_PLATFORM_DIRS'}}
    # ROBOT_LAB_DAEMON_AUTOSTART: graph verbs warm a daemon as a student's do (the suite
    # turns that off); each kernel is a session of its own, and its daemon ends with it.
    env.update(ROBOT_LAB_HEADLESS='0', ROBOT_LAB_NOTEBOOK_DOMAIN_BASE=str(domain_base),
               ROBOT_LAB_DAEMON_AUTOSTART='1',
               ROBOT_LAB_WORKSPACE=str(scratch / 'robot_lab_ws'),
               ROS_AUTOMATIC_DISCOVERY_RANGE=env.get('ROS_AUTOMATIC_DISCOVERY_RANGE',
                                                     'LOCALHOST'),
               PATH=os.pathsep.join([str(VENV_BIN), env.get('PATH', '')]))
    return env


class Lab:
    """A running JupyterLab: its base URL, token and the folder it serves."""

    def __init__(self, base: str, token: str, root: Path, log: Path) -> None:
        self.base = base
        self.token = token
        self.root = root
        self.log = log

    def api(self, path: str, method: str = 'GET') -> Any:
        request = urllib.request.Request(f'{self.base}{path}', method=method,
                                         headers={'Authorization': f'token {self.token}'})
        body = urllib.request.urlopen(request, timeout=10).read()
        return json.loads(body) if body else None

    def shutdown_kernels(self) -> None:
        """Shut every kernel down: the nodes a kernel launched die with it."""
        for kernel in self.api('/api/kernels'):
            with suppress(OSError):
                self.api(f'/api/kernels/{kernel["id"]}', method='DELETE')

    def url(self, path: str, workspace: str) -> str:
        # A workspace of its own per notebook: JupyterLab restores no other tab (or kernel).
        return f'{self.base}/lab/workspaces/{workspace}/tree/{path}?token={self.token}'


@contextmanager
def jupyter_lab(root: Path, env: dict[str, str]) -> Iterator[Lab]:
    """JupyterLab on 127.0.0.1 over `root`; stopped with its kernels at the end."""
    settings = root.parent / 'lab-settings'
    for plugin, values in LAB_SETTINGS.items():
        file = settings / f'{plugin}.jupyterlab-settings'
        file.parent.mkdir(parents=True, exist_ok=True)
        file.write_text(json.dumps(values))
    port = free_port()
    token = os.urandom(16).hex()
    log_path = root.parent / 'lab.log'
    with log_path.open('w') as log:
        lab = subprocess.Popen(
            # window.jupyterapp: a loaded page opens the next notebook itself (Notebook)
            [str(VENV_BIN / 'jupyter'), 'lab', '--allow-root', '--no-browser',
             '--LabApp.expose_app_in_browser=True',
             '--ip', '127.0.0.1', '--port', str(port), '--ServerApp.port_retries=0',
             f'--ServerApp.root_dir={root}', f'--IdentityProvider.token={token}'],
            env={**env, 'JUPYTER_RUNTIME_DIR': str(root.parent / 'runtime'),
                 'JUPYTERLAB_WORKSPACES_DIR': str(root.parent / 'lab-workspaces'),
                 'JUPYTERLAB_SETTINGS_DIR': str(settings)},
            stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        running = Lab(f'http://127.0.0.1:{port}', token, root, log_path)
        try:
            deadline = time.monotonic() + 90
            while True:
                try:
                    running.api('/api/status')
                    break
                except OSError:
                    if lab.poll() is not None or time.monotonic() > deadline:
                        raise RuntimeError(f'JupyterLab did not start; see {log_path}') \
                            from None
                    time.sleep(0.2)  # polling the server's own readiness answer
            yield running
        finally:
            with suppress(OSError):
                running.shutdown_kernels()
            lab.send_signal(signal.SIGTERM)
            try:
                lab.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(lab.pid, signal.SIGKILL)
                lab.wait()


def close_notebooks(page: Any, lab: Lab) -> None:
    """Close every tab of the page's JupyterLab (no "save?" dialog), then end the kernels:
    the nodes a notebook launched end with its kernel."""
    if not page.is_closed() and page.url.startswith(f'{lab.base}/lab'):
        page.evaluate("""() => { if (window.jupyterapp) {
                           for (const w of [...window.jupyterapp.shell.widgets('main')])
                               w.dispose(); } }""")
    lab.shutdown_kernels()


def wait_until(predicate: Any, timeout: float, step: float = 0.05) -> bool:
    """Poll the page's state (the browser has no event we can block on from here)."""
    deadline = time.monotonic() + timeout
    while True:
        if predicate():
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(step)


def wait_in_page(page: Any, predicate: str, arg: Any, timeout: float) -> bool:
    """Until the JavaScript `predicate(arg)` holds: tested in the page at each change of
    the document (a MutationObserver), and once a second in case a change is not one.

    For the long waits (a cell running, a kernel starting). Measured over 10 s of waiting,
    Chromium + Playwright's driver + this process: a Python-side poll every 50 ms (a
    DevTools round trip each) 1.6-1.75 CPU-s; Playwright's wait_for_function polling every
    100 ms 0.6 CPU-s; this 0.1 CPU-s, as much as an idle page."""
    return bool(page.evaluate("""([source, arg, ms]) => new Promise(resolve => {
        const ok = eval(source);
        const test = () => { try { return !!ok(arg); } catch (e) { return false; } };
        if (test()) return resolve(true);
        let mo, tick, timer;
        const end = value => { mo.disconnect(); clearInterval(tick); clearTimeout(timer);
                               resolve(value); };
        mo = new MutationObserver(() => { if (test()) end(true); });
        mo.observe(document.body, {subtree: true, childList: true, characterData: true});
        tick = setInterval(() => { if (test()) end(true); }, 1000);
        timer = setTimeout(() => end(test()), ms);
    })""", [predicate, arg, timeout * 1000]))


class Notebook:
    """One notebook open in JupyterLab; cells addressed by their index in the page."""

    def __init__(self, page: Any, lab: Lab, path: str) -> None:
        """Open `path` in `page`: in the JupyterLab already loaded there, as a student opens
        the next notebook (loading JupyterLab again costs Chromium ~5 CPU-s), or by loading
        it. Close the one before with `close_notebooks` (one notebook in view at a time)."""
        self.page = page
        self.lab = lab
        self.path = path
        if page.url.startswith(f'{lab.base}/lab') and page.evaluate('() => !!window.jupyterapp'):
            # The command resolves to the notebook's widget: returned, Playwright would
            # serialise its whole object graph (~100 KB to MBs, parsed and validated in
            # this process: 4 CPU-s for one notebook's tests). Wait for it, return nothing.
            page.evaluate("async p => { await window.jupyterapp.commands.execute("
                          "'docmanager:open', {path: p}); }", path)
        else:
            page.goto(lab.url(path, re.sub(r'\W', '', path)))
        page.wait_for_selector('.jp-NotebookPanel:visible .jp-Notebook .jp-Cell', timeout=90_000)
        self.cells = page.locator('.jp-NotebookPanel:visible .jp-Notebook .jp-Cell')
        self.wait_idle()

    def wait_idle(self, timeout: float = 120.0) -> None:
        """Until the status bar says the kernel is idle (keys pressed before are lost)."""
        if not wait_in_page(self.page, """() => [...document.querySelectorAll(
                '.jp-StatusBar-Widget')].some(w => w.innerText.includes('| Idle'))""",
                            None, timeout):
            raise AssertionError(f'{self.path}: the kernel never became idle')

    def count(self) -> int:
        return int(self.cells.count())

    def cell(self, index: int) -> Any:
        return self.cells.nth(index)

    def is_code(self, index: int) -> bool:
        return 'jp-CodeCell' in (self.cell(index).get_attribute('class') or '')

    def source(self, index: int) -> str:
        return str(self.cell(index).locator('.jp-InputArea-editor').text_content() or '')

    def select(self, index: int) -> None:
        cell = self.cell(index)
        for _ in range(20):
            cell.scroll_into_view_if_needed()
            cell.locator('.jp-InputPrompt, .jp-InputArea-prompt').first.click()
            if 'jp-mod-active' in (cell.get_attribute('class') or ''):
                return
        raise AssertionError(f'{self.path}: could not select cell {index}')

    def active(self, index: int) -> bool:
        return 'jp-mod-active' in (self.cell(index).get_attribute('class') or '')

    def run(self, index: int, timeout: float = 180.0) -> None:
        """Run one cell as a student does (Shift+Enter on it) and wait for it.

        Shift+Enter moves on to the next cell by itself: a click selects the cell only
        when something else (a widget, a probe) took the selection away.
        """
        if not (self.active(index) and self.page.evaluate(
                "() => !!document.activeElement?.closest?.('.jp-Notebook')")):
            self.select(index)
        self.page.keyboard.press('Escape')  # command mode: Shift+Enter runs, never types
        self.page.keyboard.press('Shift+Enter')
        if not self.is_code(index):
            return
        if not wait_in_page(self.page, NUMBERED_JS, self.cell(index).element_handle(),
                            timeout):
            raise AssertionError(f'{self.path}: cell {index} not done after {timeout:g} s '
                                 f'({self.state(index)}):\n{self.source(index)[:300]}')

    def kinds(self) -> list[tuple[str, str]]:
        """Each cell's type and source, from the notebook's model in one question."""
        return [(str(t), str(src)) for t, src in self.page.evaluate(
            """() => window.jupyterapp.shell.currentWidget.content.widgets.map(
                   w => [w.model.type, w.model.sharedModel.getSource()])""")]

    def run_cells(self, first: int, last: int, timeout: float = 300.0) -> None:
        """Run cells `first`..`last` as a student runs a stretch of a notebook: the
        stretch selected (the selection a click and a Shift+click make, set through the
        notebook widget) and Shift+Enter pressed once; JupyterLab runs them in order. Waits
        until each non-empty code cell among them has its number, or an error stopped the
        run (the cells after it are then left unnumbered: `unrun` names them).

        Measured on 01_create_package (21 code cells), Chromium's CPU: a Shift+Enter per
        cell, waiting for each, 6.1 CPU-s; the whole notebook at once 2.3 CPU-s. Each key
        JupyterLab handles costs its page ~45 ms of script and layout on this host.
        """
        self.page.evaluate("""([a, b]) => {
            const panel = window.jupyterapp.shell.currentWidget, nb = panel.content;
            nb.mode = 'command'; nb.activeCellIndex = a; nb.deselectAll();
            nb.extendContiguousSelectionTo(b); nb.node.focus(); }""", [first, last])
        self.page.keyboard.press('Shift+Enter')
        if not wait_in_page(self.page, f"""([a, b]) => {{
                const cells = ({CODE_CELLS_JS})(a, b).map(({{cell}}) => cell);
                if (cells.every({NUMBERED_JS})) return true;
                return !cells.some(c => (c.querySelector('.jp-InputPrompt')?.textContent || '')
                                        .includes('*'))
                    && cells.some(c => c.querySelector(
                        '.jp-OutputArea-output[data-mime-type="{ERROR_MIME}"], '
                        + '.jp-OutputArea-output[data-mime-type='
                        + '"application/vnd.jupyter.stderr"]'));
            }}""", [first, last], timeout):
            running = next((i for i in range(first, last + 1)
                            if '*' in self.prompt(i)), last)
            raise AssertionError(f'{self.path}: cells {first}-{last} not done after '
                                 f'{timeout:g} s ({self.state(running)}):\n'
                                 f'{self.source(running)[:300]}')

    def state(self, index: int) -> str:
        """What tells a lost key from a busy or dead kernel: the cell's prompt ([ ] never
        queued, [*] running), the kernel's status, any dialog, the server's last lines."""
        status = ' '.join(self.page.locator('.jp-StatusBar-Widget').all_text_contents())
        dialogs = ' | '.join(self.page.locator('.jp-Dialog').all_text_contents())
        try:
            log = self.lab.log.read_text(errors='replace').splitlines()[-8:]
        except OSError as err:
            log = [f'(no server log: {err})']
        return (f'prompt {self.prompt(index).strip()!r}; status bar {status[:200]!r}; '
                f'dialogs {dialogs[:300]!r}; server log:\n' + '\n'.join(log))

    def prompt(self, index: int) -> str:
        return str(self.cell(index).locator('.jp-InputPrompt').text_content() or '')

    def output(self, index: int) -> Any:
        return self.cell(index).locator('.jp-Cell-outputArea')

    def text(self, index: int) -> str:
        # textContent, not innerText: JupyterLab skips laying out cells scrolled out of
        # view (content-visibility), and their innerText is empty.
        return str(self.output(index).text_content() or '')

    def errors(self) -> list[str]:
        """Tracebacks and widgets that failed to display, anywhere in the notebook."""
        scope = self.page.locator('.jp-NotebookPanel:visible')
        # JupyterLab shows an exception as a stderr text output, like any stream: a
        # traceback, or a failed check's two lines (it has no traceback), is what tells it
        # from a warning a command printed.
        stderr = '.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.stderr"]'
        found = [str(e.text_content())[-800:] for e in scope.locator(
            f'.jp-OutputArea-output[data-mime-type="{ERROR_MIME}"], '
            f'{stderr}:has-text("Traceback (most recent call last)"), '
            f'{stderr}:has-text("✗ expected")').all()]
        found += [str(e.text_content())[:300] for e in scope.locator(
            '.jupyter-widgets:has-text("Error displaying widget")').all()]
        return found

    def unrun(self) -> list[int]:
        """Code cells that never ran (an empty one, as Shift+Enter adds at the end, aside).
        One question to the page: a locator per cell cost ~3 DevTools round trips each."""
        return [int(i) for i in self.page.evaluate(
            f"""() => ({CODE_CELLS_JS})(0, Infinity)
                .filter(({{cell}}) => !({NUMBERED_JS})(cell)).map(({{index}}) => index)""")]

    def save(self, timeout: float = 30.0) -> Path:
        """File ▸ Save (Ctrl+S), as a student saves; the file once JupyterLab wrote it."""
        path = self.lab.root / self.path
        before = path.stat().st_mtime_ns
        dirty = self.page.locator('.lm-TabBar-tab.jp-mod-current.jp-mod-dirty')
        self.page.keyboard.press('Escape')
        self.page.keyboard.press('Control+s')
        # The server truncates the file, then writes it: one that does not parse is mid-write.
        if not wait_until(lambda: path.stat().st_mtime_ns != before and dirty.count() == 0
                          and _whole_json(path), timeout):
            raise AssertionError(f'{self.path}: Ctrl+S did not save the notebook')
        return path

    def shot(self, locator: Any, path: Path) -> None:
        locator.scroll_into_view_if_needed()
        locator.screenshot(path=str(path))


def _whole_json(path: Path) -> bool:
    try:
        json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return True


def frames(root: Any) -> int:
    """How many frames a browser-drawn robot_lab widget has drawn (its data-frames)."""
    return int(root.get_attribute('data-frames') or 0)


def param_get(node: str, name: str, domain: int) -> str:
    """What `robot-lab param get` prints, in the notebook's domain."""
    env = {**os.environ, 'ROS_DOMAIN_ID': str(domain)}
    done = subprocess.run([str(VENV_BIN / 'robot-lab'), 'param', 'get', node, name], env=env,
                          capture_output=True, text=True, timeout=30)
    return (done.stdout + done.stderr).strip()


def drag(page: Any, row: Any, fraction: float) -> None:
    """Drag a slider's handle with the mouse to `fraction` of its track."""
    row.scroll_into_view_if_needed()
    track = row.locator('.noUi-base').bounding_box()
    handle = row.locator('.noUi-handle').bounding_box()
    page.mouse.move(handle['x'] + handle['width'] / 2, handle['y'] + handle['height'] / 2)
    page.mouse.down()
    page.mouse.move(track['x'] + fraction * track['width'], track['y'] + track['height'] / 2,
                    steps=12)
    page.mouse.up()


# A SceneView replayed without JupyterLab: a test records what the kernel would send the
# widget (SceneRecorder), then draws it with the committed bundle in a bare page.
_SCENE_PAGE = """<html><body style="margin:0"><div id="view" style="width: 800px"></div><script>
window.saved = [];
window.makeModel = (state) => {
  const handlers = {};
  const fire = (event, ...args) => (handlers[event] || []).slice().forEach(f => f(...args));
  window.send = (msg, buffers) => fire('msg:custom', msg, buffers);
  // a trait set from the kernel: anywidget's model fires change:<name>
  window.setTrait = (key, value) => { state[key] = value; fire('change:' + key); };
  return {
    get: (key) => state[key],
    set: (key, value) => { state[key] = value; },
    save_changes: () => { window.saved.push(JSON.stringify(state)); },
    on: (event, f) => { (handlers[event] = handlers[event] || []).push(f); },
    off: (event, f) => { handlers[event] = (handlers[event] || []).filter(g => g !== f); },
    send: () => {},
  };
};
</script></body></html>"""
_SCENE_RENDER = """async ([source, fixedFrame, more]) => {
  const url = URL.createObjectURL(new Blob([source], {type: 'text/javascript'}));
  const widget = (await import(url)).default;
  widget.render({model: window.makeModel({height: 400, fixed_frame: fixedFrame,
                                          hidden_frames: [], status: [], ...more}),
                 el: document.getElementById('view')});
}"""
_SCENE_SEND = """([msg, buffers]) => window.send(msg, buffers.map(b64 => {
  const bytes = Uint8Array.from(atob(b64), c => c.charCodeAt(0));
  return new DataView(bytes.buffer);
}))"""


class SceneRecorder:
    """Stands in for the SceneView widget: keeps what the view sends, in order."""

    def __init__(self, fixed_frame: str = '') -> None:
        self.sent: list[tuple[dict[str, Any], list[bytes]]] = []
        self.status: list[str] = []
        self.fixed_frame = fixed_frame
        self.camera: list[float] = []  # what SceneView.look_at set
        self.lock = threading.Lock()

    def send(self, msg: dict[str, Any], buffers: list[bytes] | None) -> None:
        with self.lock:
            self.sent.append((msg, list(buffers or [])))


def show_scene(page: Any, bundle: str, fixed_frame: str,
               traits: dict[str, Any] | None = None) -> None:
    """The scene view's bundle (its source text), drawing in `page` (window.saved: the
    model's states it saved; `traits`: more of the model's first state, e.g. camera)."""
    page.set_content(_SCENE_PAGE)
    page.evaluate(_SCENE_RENDER, [bundle, fixed_frame, traits or {}])


def replay_scene(page: Any, sent: list[tuple[dict[str, Any], list[bytes]]]) -> None:
    """What a SceneRecorder kept, sent to the page's widget in order."""
    for msg, buffers in sent:
        page.evaluate(_SCENE_SEND, [msg, [base64.b64encode(b).decode() for b in buffers]])
