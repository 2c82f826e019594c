"""Widget speed in a real JupyterLab and Chromium: what a live plot costs the kernel.

Runs a real sensor (sensor_rate 20) and controller (control_rate 20): two topics at
20 messages/s. Opens JupyterLab on loopback in headless Chromium (Debian's chromium, never
a downloaded browser) and, one kernel per variant, shows a live plot of
`/sensor/temperature` and `/cmd_vel/linear/x`, then measures over `--seconds`:

- the kernel process's CPU (all its threads, % of one core), median of `--runs`;
- the frame rate the browser draws the plot at (frames counted in the page).

Variants: `session` (the kernel's ROS session, nothing subscribed), `subscribed` (the
plot's subscriptions, nothing shown: the floor), `anywidget` (the kit's plot: new samples
sent 20 times a second, an inline canvas script draws) and `bqplot` (the same samples, the
window's arrays re-sent to bqplot Lines 20 times a second).
Round 1's PNG frames measured ≈ 19 % of a core at 20 frames/s.
Measured 2026-11-23 (idle 2-core machine, median of 3): session 0.3 %, subscribed 3.6 %,
anywidget 5.2 % when the session's executor woke per message; after the plot took its
messages in batches on its own thread: subscribed 1.5 %, anywidget 3.0 % at 30 frames/s.

Usage: python bench/bench_widgets.py [--runs N] [--seconds S] [--domain-id D]
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'tests' / 'browser'))

import browser_lab  # noqa: E402

SETUP = ('import os, robot_lab\nfrom robot_lab.grading import setup\nsetup("00_bench")\n'
         'print("pid", os.getpid())')
PATHS = "'/sensor/temperature', '/cmd_vel/linear/x'"
VARIANTS = {
    'session': 'robot_lab.session()',
    'subscribed': f'p = robot_lab.plot({PATHS}, timeout=20)\np.wait_for_samples(5, 20)',
    'anywidget': f'p = robot_lab.plot({PATHS}, timeout=20)\np',
    'bqplot': f"""import threading, time, bqplot
p = robot_lab.plot({PATHS}, timeout=20)
xs, ys = bqplot.LinearScale(), bqplot.LinearScale()
lines = [bqplot.Lines(x=[0.0], y=[0.0], scales={{'x': xs, 'y': ys}}) for _ in range(2)]
fig = bqplot.Figure(marks=lines, axes=[bqplot.Axis(scale=xs), bqplot.Axis(
    scale=ys, orientation='vertical')], animation_duration=0)
def feed():
    while True:
        now = time.monotonic() - p.t0
        for line, samples in zip(lines, p.data.values()):
            window = [(t - now, v) for t, v in samples if t >= now - 10]
            with line.hold_sync():
                line.x, line.y = [w[0] for w in window], [w[1] for w in window]
        time.sleep(0.05)
threading.Thread(target=feed, daemon=True).start()
fig""",
}
# What shows that each variant is on screen, and how its frames are counted in the page.
RENDERED = {'session': None, 'subscribed': None, 'anywidget': '.rl-chart', 'bqplot': '.bqplot'}
COUNT_SVG_FRAMES = """(root, ms) => new Promise(done => {
    let n = 0, last = -1;
    const seen = new MutationObserver(() => { n += 1; });
    seen.observe(root, {attributes: true, subtree: true, attributeFilter: ['d']});
    setTimeout(() => { seen.disconnect(); done(n / 2); }, ms);  // two lines per frame
})"""


def cpu_seconds(pid: int) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def notebook(path: Path, cells: list[str]) -> None:
    import json

    path.write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'metadata': {}, 'source': s, 'outputs': [],
                   'execution_count': None} for s in cells],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'language': 'python',
                                    'display_name': 'robot_lab (ROS 2 Jazzy)'}},
        'nbformat': 4, 'nbformat_minor': 5}))


def measure(browser: object, lab: browser_lab.Lab, variant: str,
            seconds: float) -> tuple[float, float]:
    """(kernel CPU % of a core, browser frames/s) for one variant, in a fresh kernel."""
    page = browser.new_page(viewport={'width': 1200, 'height': 900})  # type: ignore[attr-defined]
    try:
        nb = browser_lab.Notebook(page, lab, f'{variant}.ipynb')
        nb.run(0)
        pid = int(re.search(r'pid (\d+)', nb.text(0)).group(1))  # type: ignore[union-attr]
        nb.run(1)
        errors = nb.errors()
        if errors:
            raise SystemExit(f'{variant}: {errors}')
        selector = RENDERED[variant]
        root = None
        if selector:
            root = nb.output(1).locator(selector).first
            root.wait_for(timeout=30_000)
            root.scroll_into_view_if_needed()
        time.sleep(2.0)  # let the first view settle before the measured span
        start_cpu, start = cpu_seconds(pid), time.monotonic()
        if variant == 'anywidget':
            first = browser_lab.frames(root)
            time.sleep(seconds)
            fps = (browser_lab.frames(root) - first) / seconds
        elif variant == 'bqplot':
            fps = float(root.evaluate(COUNT_SVG_FRAMES, seconds * 1000)) / seconds
        else:
            time.sleep(seconds)
            fps = 0.0
        cpu = 100.0 * (cpu_seconds(pid) - start_cpu) / (time.monotonic() - start)
        return cpu, fps
    finally:
        page.close()
        lab.shutdown_kernels()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--seconds', type=float, default=10.0)
    parser.add_argument('--domain-id', type=int, default=95)
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    from robot_lab.env import ros_environment
    from robot_lab.process import spawn, stop

    exe = browser_lab.chromium()
    if exe is None:
        raise SystemExit('no chromium: apt-get install -y chromium')
    os.environ['ROS_DOMAIN_ID'] = str(args.domain_id)
    cli = str(Path(sys.executable).parent / 'robot-lab')
    env = ros_environment()
    procs = [
        spawn([cli, 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
               '-p', 'sensor_rate:=20'], env=env),
        spawn([cli, 'run', 'robot_lab', 'controller_node', '--ros-args',
               '-r', '__node:=controller', '-p', 'control_rate:=20'], env=env),
    ]
    scratch = Path(tempfile.mkdtemp(prefix='robot_lab-bench-'))
    root = scratch / 'course'
    root.mkdir()
    for variant, code in VARIANTS.items():
        notebook(root / f'{variant}.ipynb', [SETUP, code])
    lab_env = browser_lab.lab_environment(scratch, args.domain_id)
    results: dict[str, list[tuple[float, float]]] = {v: [] for v in VARIANTS}
    try:
        with browser_lab.jupyter_lab(root, lab_env) as lab, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=exe, args=browser_lab.CHROMIUM_ARGS)
            for _ in range(args.runs):
                for variant in VARIANTS:
                    results[variant].append(measure(browser, lab, variant, args.seconds))
            browser.close()
    finally:
        for proc in procs:
            stop(proc)
    print(f'two topics at 20 messages/s, {args.seconds:g} s spans, median of {args.runs} runs')
    print('variant      kernel CPU (% of a core)   browser frames/s')
    for variant, runs in results.items():
        cpu = statistics.median(r[0] for r in runs)
        fps = statistics.median(r[1] for r in runs)
        print(f'{variant:<12} {cpu:>10.1f}                 {fps:>8.1f}')
    kit = results['anywidget']
    print(f'live plot kernel CPU: {statistics.median(r[0] for r in kit):.1f} % of a core '
          f"(the plot's subscriptions alone: "
          f'{statistics.median(r[0] for r in results["subscribed"]):.1f} %)')
    print(f'live plot browser frame rate: {statistics.median(r[1] for r in kit):.1f} frames/s')


if __name__ == '__main__':
    main()
