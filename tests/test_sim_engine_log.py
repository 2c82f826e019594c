"""MuJoCo's warnings reach the kit's warning path, never a MUJOCO_LOG.TXT in the cwd.

An unstable state (a NaN position) makes MuJoCo's step warn and reset; without the kit's
handler the C library appends the warning to MUJOCO_LOG.TXT in the current directory.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed
import pytest

from robot_lab.sim import engine_log
from robot_lab.sim.sample_robot import WHEEL_RADIUS, diffbot_urdf
from robot_lab.sim.simulation import Simulation

pytestmark = pytest.mark.no_ros  # the engine alone: no DDS, no domain


def test_an_unstable_world_warns_once_by_name_and_writes_no_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    warnings: list[str] = []
    sim = Simulation('empty.sdf', warn=warnings.append)
    sim.spawn(diffbot_urdf(), 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
    sim.step(10)
    assert warnings == []
    sim.data.qpos[0] = math.nan
    sim.step(5)
    engine = [w for w in warnings if w.startswith('MuJoCo warning')]
    assert len(engine) == 1, warnings
    assert "world 'empty' (empty.sdf)" in engine[0]
    assert 'QPOS' in engine[0] and '\n' not in engine[0]
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT
    assert math.isfinite(sim.data.qpos[0])  # MuJoCo reset the unstable state


def test_a_bare_model_warns_through_the_logger(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(engine_log, '_speaker', None)
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><freejoint/><geom size=".1"/></body></worldbody></mujoco>')
    data = mujoco.MjData(model)
    data.qvel[0] = math.inf
    with caplog.at_level(logging.WARNING, logger='robot_lab.sim'):
        mujoco.mj_step(model, data)
    assert [r.getMessage() for r in caplog.records if 'QVEL' in r.getMessage()] != []
    assert list(tmp_path.iterdir()) == []
