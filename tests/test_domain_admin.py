"""`robot-lab domain list|release USER`, as a hub's admin runs it."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import run_cli
from unixusers import can_create_users, unix_users

from robot_lab import domain
from robot_lab.domain import DomainRegistry, registry_path


def test_release_understands_tljh_names_and_refuses_unknown_users(tmp_path: Path) -> None:
    why = can_create_users()
    if why:
        pytest.skip(why)
    registry = tmp_path / 'domains.json'
    env = {'ROBOT_LAB_DOMAIN_REGISTRY': str(registry)}
    with unix_users() as users:
        student = users.add('k', template='jupyter-{}')  # TLJH's Unix name for hub user
        hub_name = student.name.removeprefix('jupyter-')
        given = DomainRegistry(registry).user_domain(student.uid, range(1, 102))
        listed = run_cli('domain', 'list', env=env)
        assert listed.returncode == 0
        assert listed.stdout.splitlines() == [
            f'{registry}:', f'  domain {given:>3}  {student.name} (uid {student.uid})']
        done = run_cli('domain', 'release', hub_name, env=env)
        assert (done.returncode, done.stdout) == (0, f'{student.name}: domain {given} freed\n')
        again = run_cli('domain', 'release', hub_name, env=env)
        assert again.returncode == 1 and again.stdout == ''
        assert again.stderr.count('\n') == 1 and 'has no domain' in again.stderr
    unknown = run_cli('domain', 'release', 'nobody-here', env=env)
    assert unknown.returncode == 1 and 'nobody-here' in unknown.stderr


def test_without_the_variable_an_admin_gets_the_hubs_registry(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    hub = tmp_path / 'srv' / 'domains.json'
    monkeypatch.setattr(domain, 'HUB_REGISTRY', hub)
    assert registry_path({}) == domain.DEFAULT_REGISTRY  # no hub on this host
    hub.parent.mkdir()
    hub.write_text('{}')
    assert registry_path({}) == hub  # sudo dropped the hub's variable: still the hub's
    assert registry_path({'ROBOT_LAB_DOMAIN_REGISTRY': '/x/d.json'}) == Path('/x/d.json')


if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q']))
