"""Launch files -> LaunchPlan: launch_ros command lines, scopes, namespaces, substitutions,
parameters and errors, for XML, YAML and Python files. Nothing is started (no DDS)."""

from __future__ import annotations

import os
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
import yaml

from robot_lab.errors import LaunchError, ParamFileError
from robot_lab.launch.plan import (
    LaunchPlan,
    LogAction,
    ProcessSpec,
    ShutdownAction,
    TimerSpec,
)
from robot_lab.launch.resolve import describe_launch, launch_arguments, parse_launch_arguments
from robot_lab.pkg.index import find_executable, package_prefix, package_share

DATA = Path(__file__).resolve().parent / 'data' / 'launch'
REPO = Path(__file__).resolve().parents[1]


def exe(name: str, package: str = 'robot_lab') -> str:
    return str(find_executable(package, name))


def share(package: str = 'robot_lab') -> Path:
    return package_share(package)


def write(tmp_path: Path, text: str, name: str = 'test.launch.xml') -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def describe_text(tmp_path: Path, text: str, name: str = 'test.launch.xml',
                  **args: str) -> LaunchPlan:
    return describe_launch(write(tmp_path, text, name), args=args)


def temp_params(path: str) -> Any:
    assert Path(path).name.startswith('launch_params_')
    return yaml.safe_load(Path(path).read_text())


def logs(plan: LaunchPlan) -> list[str]:
    return [a.message for a in plan.actions if isinstance(a, LogAction)]


def error_of(tmp_path: Path, text: str, name: str = 'test.launch.xml',
             **args: str) -> LaunchError:
    with pytest.raises(LaunchError) as info:
        describe_text(tmp_path, text, name, **args)
    return info.value


# ------------------------------------------------------------------------- shipped files


def test_seed_robot_launch_xml_resolves_as_launch_ros_would() -> None:
    plan = describe_launch('robot_lab', 'robot.launch.xml', {'robot_name': 'robot_alpha'})
    config = str(share() / 'config' / 'robot_params.yaml')
    sensor, controller, robot = plan.processes()
    assert sensor.cmd == [exe('sensor_node'), '--ros-args', '-r', '__node:=sensor',
                          '--params-file', config]
    assert controller.cmd == [exe('controller_node'), '--ros-args', '-r', '__node:=controller',
                              '--params-file', config]
    assert robot.cmd[:4] == [exe('robot_node'), '--ros-args', '-r', '__node:=robot']
    assert robot.cmd[4] == '--params-file' and len(robot.cmd) == 6
    # no namespace given, so launch_ros writes the name/value file for every node ('/**')
    assert temp_params(robot.cmd[5]) == {'/**': {'ros__parameters': {'robot_name': 'robot_alpha'}}}
    assert [p.label for p in plan.processes()] == ['sensor_node-1', 'controller_node-2',
                                                   'robot_node-3']
    assert [p.node_name for p in plan.processes()] == ['/sensor', '/controller', '/robot']
    assert all(p.output == 'screen' for p in plan.processes())
    assert sensor.param_files == [config] and robot.param_files == [robot.cmd[5]]
    assert sensor.env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert sensor.package == 'robot_lab' and sensor.executable == 'sensor_node'
    assert sensor.source is not None and sensor.source.endswith('robot.launch.xml:11')
    assert [(a.name, a.default) for a in plan.arguments] == [
        ('robot_name', 'my_robot'), ('config_file', 'robot_params.yaml')]


def normalised(plan: LaunchPlan) -> list[list[Any]]:
    """Command lines with temp parameter files replaced by their content."""
    out = []
    for spec in plan.processes():
        out.append([temp_params(part) if Path(part).name.startswith('launch_params_') else part
                    for part in spec.cmd] + [spec.label, spec.output])
    return out


def test_shipped_xml_yaml_and_python_files_describe_the_same_system() -> None:
    args = {'robot_name': 'robot_beta'}
    xml = normalised(describe_launch('robot_lab', 'robot.launch.xml', args))
    assert normalised(describe_launch('robot_lab', 'robot.launch.yaml', args)) == xml
    assert normalised(describe_launch('robot_lab', 'robot.launch.py', args)) == xml
    assert [a.name for a in launch_arguments('robot_lab', 'robot.launch.py')] == [
        'robot_name', 'config_file']


def test_robot_sim_two_independent_robots() -> None:
    plan = describe_launch('robot_lab', 'robot_sim.launch.xml', {'robot2_name': 'beta'})
    names = [p.node_name for p in plan.processes()]
    assert names == ['/robot1/sensor', '/robot1/controller', '/robot1/robot',
                     '/robot2/sensor', '/robot2/controller', '/robot2/robot']
    for spec in plan.processes():
        ns = spec.node_name.rsplit('/', 1)[0] if spec.node_name else ''
        assert spec.cmd[4:6] == ['-r', f'__ns:={ns}']
        assert spec.cmd[-6:] == ['-r', '/sensor/temperature:=sensor/temperature',
                                 '-r', '/robot/status:=robot/status', '-r', '/cmd_vel:=cmd_vel']
    robots = [p for p in plan.processes() if p.executable == 'robot_node']
    assert [temp_params(r.param_files[0]) for r in robots] == [
        {'/robot1/robot': {'ros__parameters': {'robot_name': 'robot_one'}}},
        {'/robot2/robot': {'ros__parameters': {'robot_name': 'beta'}}},
    ]


def test_seed_chapter6_python_launch_file(monkeypatch: pytest.MonkeyPatch) -> None:
    prefix = DATA / 'prefix'
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    plan = describe_launch('robot_controller', 'robot_launch.py')
    (spec,) = plan.processes()
    params = str(prefix / 'share' / 'robot_controller' / 'config' / 'params.yaml')
    assert spec.node_name == '/robot_controller'
    assert spec.cmd == [str(prefix / 'lib' / 'robot_controller' / 'controller'), '--ros-args',
                        '-r', '__node:=robot_controller', '--params-file', params]
    assert spec.label == 'controller-1' and spec.output == 'screen'
    assert plan.arguments[0].name == 'params_file' and plan.arguments[0].default == params
    other = describe_launch('robot_controller', 'robot_launch.py',
                            {'params_file': str(REPO / 'config' / 'robot_params.yaml')})
    assert other.processes()[0].cmd[-1] == str(REPO / 'config' / 'robot_params.yaml')


def test_seed_flat_parameter_file_refused_before_anything_starts() -> None:
    with pytest.raises(ParamFileError) as info:
        describe_launch(DATA / 'flat_param_node.launch.xml')
    text = str(info.value)
    assert info.value.file == str(DATA / 'robot_params.yaml') and info.value.line == 2
    assert 'robot_params.yaml:2: Cannot have a value before ros__parameters' in text
    assert 'flat_param_node.launch.xml:2' in text and '/**: {ros__parameters:' in text


# --------------------------------------------------------------------------- node & params


def test_node_command_line_order_and_attributes() -> None:
    plan = describe_launch(DATA / 'node_full.launch.xml')
    (spec,) = plan.processes()
    files = spec.param_files
    assert spec.cmd == [
        'nice', '-n', '5', exe('controller_node'), '--flag', 'two words',
        '--ros-args', '--log-level', 'debug',
        '--ros-args', '-r', '__node:=ctl', '-r', '__ns:=/bot',
        '-p', 'use_sim_time:=True',
        *[part for f in files for part in ('--params-file', f)],
        '-r', '/cmd_vel:=/global_cmd', '-r', '/sensor/temperature:=temp',
    ]
    assert spec.label == 'brain-1' and spec.node_name == '/bot/ctl'
    assert (spec.output, spec.respawn, spec.respawn_delay, spec.on_exit) == (
        'both', True, 2.5, 'shutdown')
    assert spec.env['NODE_ONLY'] == 'yes'
    contents = [temp_params(f)['/bot/ctl']['ros__parameters'] for f in files]
    assert contents == [{'control_rate': 20}, {'robot_name': '10'},
                        {'gains.p': 1.5, 'gains.i': 0}, {'names': ['a', 'b', 'c']},
                        {'flags': [True, False]}]


def test_node_without_name_or_namespace(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        <launch>
          <node pkg="robot_lab" exec="sensor_node"><param name="sensor_rate" value="7"/></node>
          <node pkg="robot_lab" exec="sensor_node" namespace="only_ns">
            <param name="sensor_rate" value="8"/>
          </node>
        </launch>""")
    first, second = plan.processes()
    assert first.cmd[:2] == [exe('sensor_node'), '--ros-args'] and first.node_name is None
    assert temp_params(first.cmd[3]) == {'/**': {'ros__parameters': {'sensor_rate': 7}}}
    assert second.cmd[2:4] == ['-r', '__ns:=/only_ns']
    assert temp_params(second.cmd[5]) == {'/**': {'ros__parameters': {'sensor_rate': 8}}}


@pytest.mark.parametrize(('attrs', 'value'), [
    ('value="10"', 10), ('value="0.5"', 0.5), ('value="true"', True), ('value="abc"', 'abc'),
    ('value="10" type="str"', '10'), ('value="3" type="float"', 3.0),
    ('value="1" type="bool"', True), ('value="[1, 2]"', [1, 2]),
    ('value="1,2" value-sep="," type="list_of_int"', [1, 2]),
    ("value=\"'quoted'\"", 'quoted'), ('value="$(var n)"', 42),
])
def test_param_value_typing(tmp_path: Path, attrs: str, value: Any) -> None:
    plan = describe_text(tmp_path, f"""
        <launch>
          <let name="n" value="42"/>
          <node pkg="robot_lab" exec="sensor_node" name="s"><param name="p" {attrs}/></node>
        </launch>""")
    got = temp_params(plan.processes()[0].param_files[0])['/**']['ros__parameters']['p']
    assert got == value and type(got) is type(value)


def test_global_parameters_files_and_remaps_apply_in_scope(tmp_path: Path) -> None:
    nested = tmp_path / 'nested.yaml'
    nested.write_text('/**:\n  ros__parameters:\n    sensor_rate: 5\n')
    plan = describe_text(tmp_path, f"""
        <launch>
          <group>
            <set_parameters_from_file filename="{nested}"/>
            <set_parameter name="noise_level" value="0.0"/>
            <set_remap from="a" to="b"/>
            <node pkg="robot_lab" exec="sensor_node" name="inside">
              <param from="{nested}"/>
              <remap from="c" to="d"/>
            </node>
          </group>
          <node pkg="robot_lab" exec="sensor_node" name="outside"/>
        </launch>""")
    inside, outside = plan.processes()
    assert inside.cmd[4:] == ['--params-file', str(nested), '-p', 'noise_level:=0.0',
                              '--params-file', str(nested), '-r', 'a:=b', '-r', 'c:=d']
    assert inside.param_files == [str(nested), str(nested)]
    assert outside.cmd == [exe('sensor_node'), '--ros-args', '-r', '__node:=outside']


def test_set_parameters_from_file_is_validated(tmp_path: Path) -> None:
    with pytest.raises(ParamFileError) as info:
        describe_text(tmp_path, f"""
            <launch>
              <set_parameters_from_file filename="{DATA / 'robot_params.yaml'}"/>
            </launch>""")
    assert info.value.line == 2 and 'ros__parameters' in info.value.message


def test_namespaces_nest_relative_and_keep_absolute() -> None:
    plan = describe_launch(DATA / 'namespaces.launch.xml')
    assert [p.node_name for p in plan.processes()] == [
        '/top', '/outer/a', '/outer/inner/b', '/outer/inner/rel/c', '/abs/d', '/root/e',
        '/outer/f', '/solo/g']
    assert plan.processes()[0].cmd[2:] == ['-r', '__node:=top']


def test_executable_tag(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        <launch>
          <set_env name="GREETING" value="hi"/>
          <executable cmd="$(find-exec echo) one 'two three' $(env GREETING)" cwd="/tmp"
                      name="talk" output="screen" shell="true" sigterm_timeout="2"
                      sigkill_timeout="3" respawn="$(eval 'True')" respawn_max_retries="4"
                      launch-prefix="env X=1">
            <env name="EXTRA" value="1"/>
          </executable>
          <executable cmd="sleep 1"/>
        </launch>""")
    talk, sleep = plan.processes()
    assert talk.cmd == ['env', 'X=1', exe_on_path('echo'), 'one', 'two three', 'hi']
    assert (talk.label, talk.cwd, talk.output, talk.shell) == ('talk-1', '/tmp', 'screen', True)
    assert (talk.sigterm_timeout, talk.sigkill_timeout) == (2.0, 3.0)
    assert talk.respawn and talk.respawn_max_retries == 4
    assert talk.env['EXTRA'] == '1' and talk.env['GREETING'] == 'hi'
    assert sleep.label == 'sleep-2' and sleep.node_name is None and sleep.output == 'log'


def exe_on_path(name: str) -> str:
    import shutil

    found = shutil.which(name)
    assert found is not None
    return found


def test_timer_log_shutdown_and_labels_in_start_order(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        <launch>
          <timer period="2.0">
            <executable cmd="echo late"/>
          </timer>
          <timer period="$(eval '0.5 + 0.5')">
            <log message="one second"/>
            <executable cmd="echo sooner"/>
          </timer>
          <executable cmd="echo now"/>
          <log message="hello"/>
          <shutdown reason="bye"/>
        </launch>""")
    late, sooner, now, hello, bye = plan.actions
    assert isinstance(late, TimerSpec) and late.period == 2.0
    assert isinstance(sooner, TimerSpec) and sooner.period == 1.0
    assert isinstance(sooner.actions[0], LogAction) and sooner.actions[0].message == 'one second'
    assert isinstance(now, ProcessSpec) and now.label == 'echo-1'
    assert [p.label for p in plan.processes()] == ['echo-3', 'echo-2', 'echo-1']
    assert isinstance(hello, LogAction) and hello.message == 'hello'
    assert isinstance(bye, ShutdownAction) and bye.reason == 'bye'


def test_environment_actions_are_scoped_by_groups(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        <launch>
          <set_env name="RL_A" value="a"/>
          <append_env name="RL_A" value="b"/>
          <append_env name="RL_A" value="z" prepend="true" separator=","/>
          <group>
            <set_env name="RL_B" value="b"/>
            <unset_env name="RL_A"/>
            <executable cmd="echo inner"/>
          </group>
          <executable cmd="echo outer"/>
        </launch>""")
    inner, outer = plan.processes()
    assert 'RL_A' not in inner.env and inner.env['RL_B'] == 'b'
    assert outer.env['RL_A'] == 'z,a' + os.pathsep + 'b' and 'RL_B' not in outer.env


def test_groups_scoped_unscoped_forwarding_keep(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        <launch>
          <let name="x" value="outer"/>
          <group><let name="x" value="scoped"/></group>
          <log message="1 $(var x)"/>
          <group scoped="false"><let name="x" value="leaked"/></group>
          <log message="2 $(var x)"/>
          <group forwarding="false">
            <keep name="kept" value="$(var x)"/>
            <log message="3 $(var kept) $(var x unset)"/>
          </group>
        </launch>""")
    assert logs(plan) == ['1 outer', '2 leaked', '3 leaked unset']


def test_include_is_not_scoped_and_group_scopes_it() -> None:
    plan = describe_launch(DATA / 'include_parent.launch.xml')
    assert [p.node_name for p in plan.processes()] == ['/child_node', '/scoped_node']
    child = DATA / 'include_child.launch.xml'
    assert logs(plan) == [f'child dir {DATA} file {child}', 'after include: yes child_node',
                          f'child dir {DATA} file {child}', 'after group: child_node']


def test_include_relative_path_resolves_against_cwd(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / 'sub').mkdir()
    write(tmp_path, '<launch><log message="child"/></launch>', 'sub/child.launch.xml')
    parent = write(tmp_path, '<launch><include file="sub/child.launch.xml"/></launch>',
                   'sub/parent.launch.xml')
    monkeypatch.chdir(tmp_path)
    assert logs(describe_launch(parent)) == ['child']
    monkeypatch.chdir(tmp_path / 'sub')
    with pytest.raises(LaunchError, match='included launch file not found'):
        describe_launch(parent)


def test_include_errors(tmp_path: Path) -> None:
    err = error_of(tmp_path, '<launch>\n<include file="$(dirname)/nope.launch.xml"/>\n</launch>')
    assert err.line == 2 and 'included launch file not found' in err.message
    with pytest.raises(LaunchError) as info:
        describe_launch(DATA / 'cycle_a.launch.xml')
    assert info.value.message == ('include cycle: cycle_a.launch.xml -> cycle_b.launch.xml -> '
                                  'cycle_a.launch.xml')
    assert info.value.file == str(DATA / 'cycle_b.launch.xml') and info.value.line == 3
    err = error_of(tmp_path, f'<launch><include file="{DATA / "include_child.launch.xml"}"/>'
                   '</launch>', who='ignored_here')
    assert err.message == ("Included launch description missing required argument 'who' "
                           "(description: ''), given: []")


# ---------------------------------------------------------------------- arguments & conditions


def test_arguments_required_choices_and_show_args(tmp_path: Path) -> None:
    text = """
        <launch>
          <arg name="mode" description="how to run">
            <choice value="sim"/>
            <choice value="real"/>
          </arg>
          <arg name="rate" default="$(eval '5 * 2')"/>
          <log message="$(var mode) $(var rate)"/>
        </launch>"""
    err = error_of(tmp_path, text)
    assert err.message == 'Required launch argument "mode" was not provided.' and err.line == 2
    err = error_of(tmp_path, text, mode='fake')
    assert err.message == ('Argument "mode" provided value "fake" is not valid. '
                           "Valid options are: ['sim', 'real']")
    assert logs(describe_text(tmp_path, text, mode='real')) == ['real 10']
    shown = launch_arguments(tmp_path / 'test.launch.xml')
    assert [(a.name, a.default, a.description, a.choices) for a in shown] == [
        ('mode', None, 'how to run', ['sim', 'real']), ('rate', '10', '', None)]


def test_parse_launch_arguments() -> None:
    assert parse_launch_arguments(['a:=1', 'b:=x:=y', 'c:=']) == {'a': '1', 'b': 'x:=y', 'c': ''}
    with pytest.raises(LaunchError) as info:
        parse_launch_arguments(['robot_name=x'])
    assert info.value.message == ("malformed launch argument 'robot_name=x', expected format "
                                  "'<name>:=<value>'")


@pytest.mark.parametrize(('condition', 'started'), [
    ('if="true"', True), ('if="1"', True), ('if=" TRUE "', True), ('if="false"', False),
    ('if="0"', False), ('unless="true"', False), ('unless="0"', True),
    ('if="$(var on)"', True), ('unless="$(not $(var on))"', True),
])
def test_conditions(tmp_path: Path, condition: str, started: bool) -> None:
    plan = describe_text(tmp_path, f"""
        <launch>
          <let name="on" value="true"/>
          <group {condition}><executable cmd="echo grouped"/></group>
          <executable cmd="echo direct" {condition}/>
          <log message="logged" {condition}/>
        </launch>""")
    assert len(plan.processes()) == (2 if started else 0)
    assert logs(plan) == (['logged'] if started else [])


def test_condition_errors(tmp_path: Path) -> None:
    err = error_of(tmp_path, '<launch>\n<log message="x" if="maybe"/>\n</launch>')
    assert err.line == 2 and "expected one of: ['true', '1', 'false', '0']" in err.message
    err = error_of(tmp_path, '<launch>\n<log message="x" if="true" unless="true"/>\n</launch>')
    assert err.message == "if and unless conditions can't be used simultaneously"


# --------------------------------------------------------------------------- substitutions


@pytest.mark.parametrize(('expression', 'expected'), [
    ('$(var word)', 'hello'),
    ('$(var missing fallback)', 'fallback'),
    ('$(env RL_SUBST_TEST)', 'from-env'),
    ('$(env RL_SUBST_UNSET default)', 'default'),
    ("$(eval '2 * pi > 6')", 'True'),
    ("$(eval 'sqrt(16)')", '4.0'),
    ("$(command 'echo hi there')", 'hi there\n'),
    ('$(equals $(anon x) $(anon x))', 'true'),
    ('$(equals $(anon x) $(anon y))', 'false'),
    ('$(find-exec sh)', 'SH'),
    ('$(find-pkg-share robot_lab)', 'SHARE'),
    ('$(find-pkg-prefix robot_lab)', 'PREFIX'),
    ('$(exec-in-pkg robot_node robot_lab)', 'ROBOT_NODE'),
    ('$(file-content $(dirname)/content.txt)', 'inside\n'),
    ('$(if true yes no)/$(if 0 yes no)', 'yes/no'),
    ('$(not true) $(not 0)', 'false true'),
    ('$(and true 1) $(and true false) $(or false 0) $(or 0 true)', 'true false false true'),
    ('$(equals 1.0 1) $(equals true 1) $(equals a b) $(equals abc abc)', 'true true false true'),
    ('$(var $(var name_of_word))', 'hello'),
    ("$(eval '\"$(var word)\" + \" \" + \"world\"')", 'hello world'),
    ('$(eval "\'a b\' == \'a b\'")', 'True'),
    ('plain \\$(var word) text', 'plain $(var word) text'),
    ('$(filename)', 'FILE'),
])
def test_substitutions(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, expression: str,
                       expected: str) -> None:
    monkeypatch.setenv('RL_SUBST_TEST', 'from-env')
    monkeypatch.delenv('RL_SUBST_UNSET', raising=False)
    (tmp_path / 'content.txt').write_text('inside\n')
    plan = describe_text(tmp_path, f"""
        <launch>
          <let name="word" value="hello"/>
          <let name="name_of_word" value="word"/>
          <log message="{expression.replace('"', '&quot;')}"/>
        </launch>""")
    expected = {
        'SH': exe_on_path('sh'), 'SHARE': str(share()), 'PREFIX': str(package_prefix('robot_lab')),
        'ROBOT_NODE': exe('robot_node'), 'FILE': str(tmp_path / 'test.launch.xml'),
    }.get(expected, expected)
    assert logs(plan) == [expected]


@pytest.mark.parametrize(('expression', 'message'), [
    ('$(optenv X)', 'Unknown substitution: optenv'),
    ('$(var nope)', "launch configuration 'nope' does not exist"),
    ('$(env RL_SUBST_UNSET)', "environment variable 'RL_SUBST_UNSET' does not exist"),
    ('$(find-exec no_such_program_rl)', "executable 'no_such_program_rl' not found on the PATH"),
    ('$(var a b c)', 'var substitution expects 1 or 2 arguments'),
    ("$(command 'false')", 'executed command failed. Command: false'),
    ('$(not maybe)', "Cannot convert value 'maybe' to 'bool'"),
    ('$(var x', 'expected ")" to close $(var'),
])
def test_substitution_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, expression: str,
                             message: str) -> None:
    monkeypatch.delenv('RL_SUBST_UNSET', raising=False)
    err = error_of(tmp_path, f'<launch>\n\n<log message="{expression}"/>\n</launch>')
    assert message in err.message
    assert err.file == str(tmp_path / 'test.launch.xml') and err.line == 3


# ------------------------------------------------------------------------------ file errors


@pytest.mark.parametrize(('text', 'line', 'message'), [
    ('<robot>\n</robot>', 1, "Expected 'launch' as root tag"),
    ('<launch>\n  <nodes pkg="x"/>\n</launch>', 2, 'Unrecognized entity of the type: nodes'),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor_node" nmae="s"/>\n</launch>', 2,
     "Unexpected attribute(s) found in `node`: {'nmae'}"),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor_node">\n    <parm name="a" value="1"/>\n'
     '  </node>\n</launch>', 2, "Unexpected nested tag(s) found in `node`: {'parm'}"),
    ('<launch>\n  <node pkg="robot_lab"/>\n</launch>', 2,
     "Attribute 'exec' of type '<class 'str'>' not found in Entity 'node'"),
    ('<launch>\n  <log message="a">\n</launch>', 3, 'malformed XML: mismatched tag'),
    ('<launch>\n  <node pkg="no_such_pkg_rl" exec="x"/>\n</launch>', 2,
     "Package 'no_such_pkg_rl' not found"),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor"/>\n</launch>', 2,
     "executable 'sensor' not found on the libexec directory"),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor_node" name="1bad"/>\n</launch>', 2,
     "Invalid node name '1bad': node name must not start with a number"),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor_node" on_exit="restart"/>\n</launch>', 2,
     'Attribute on_exit of Entity node expected to be shutdown but got `restart`'),
    ('<launch>\n  <group scoped="maybe"/>\n</launch>', 2,
     "Attribute 'scoped' of Entity 'group' expected to be of type '<class 'bool'>'"),
    ('<launch>\n  <node pkg="robot_lab" exec="sensor_node">\n'
     '    <param name="a" value="1" from="f.yaml"/>\n  </node>\n</launch>', 2,
     'name and from attributes are mutually exclusive'),
])
def test_xml_errors_name_file_and_line(tmp_path: Path, text: str, line: int,
                                       message: str) -> None:
    err = error_of(tmp_path, text)
    assert message in err.message
    assert (err.file, err.line) == (str(tmp_path / 'test.launch.xml'), line)


def test_unknown_executable_lists_what_the_package_has(tmp_path: Path) -> None:
    err = error_of(tmp_path, '<launch>\n  <node pkg="robot_lab" exec="sensor"/>\n</launch>')
    assert err.fix is not None
    assert 'controller_node' in err.fix and 'sensor_node' in err.fix and 'robot_node' in err.fix


def test_unknown_launch_file_in_package() -> None:
    with pytest.raises(LaunchError) as info:
        describe_launch('robot_lab', 'nope.launch.xml')
    assert "file 'nope.launch.xml' was not found in the share directory of package " \
           "'robot_lab'" in info.value.message
    assert info.value.fix is not None and 'robot.launch.xml' in info.value.fix


# ------------------------------------------------------------------------------------ YAML


def test_yaml_frontend() -> None:
    plan = describe_launch(DATA / 'everything.launch.yaml')
    sensor, greeter = plan.processes()
    assert sensor.node_name == '/yaml_ns/sensor'
    assert sensor.cmd[-2:] == ['-r', '/sensor/temperature:=temperature']
    assert [temp_params(f)['/yaml_ns/sensor']['ros__parameters'] for f in sensor.param_files] == [
        {'sensor_rate': 5}, {'noise_level': 0.25}]
    assert sensor.env['ROBOT_LAB_TEST_A'] == 'a' and sensor.env['ROBOT_LAB_TEST_B'] == 'b'
    # a substitution's result stays one argument, spaces and all (launch's _parse_cmdline)
    assert greeter.cmd == ['echo', 'hello sim'] and greeter.label == 'greeter-2'
    assert 'ROBOT_LAB_TEST_B' not in greeter.env
    timer = plan.actions[2]
    assert isinstance(timer, TimerSpec) and timer.period == 1.5
    assert not any(isinstance(a, ShutdownAction) for a in plan.actions)
    with pytest.raises(LaunchError) as err_plan:
        describe_launch(DATA / 'everything.launch.yaml', args={'mode': 'other'})
    assert 'Valid options are' in err_plan.value.message


@pytest.mark.parametrize(('text', 'line', 'message'), [
    ('launch:\n- node:\n    pkg: robot_lab\n    exec: sensor_node\n    respawn: true\n', 2,
     "Attribute 'respawn' of Entity 'node' expected to be of type 'str', got 'bool'"),
    ('launch:\n- log:\n    message: a\n- nodes:\n    pkg: x\n', 4,
     'Unrecognized entity of the type: nodes'),
    ('launch:\n- log:\n    message: a\n    extra: 1\n', 2,
     "Unexpected key(s) found in `log`: {'extra'}"),
    ('launch:\n- log:\n  message: [a\n', 3, 'malformed YAML'),
    ('robot:\n- log:\n    message: a\n', 1, "Expected 'launch' as root tag"),
])
def test_yaml_errors_name_file_and_line(tmp_path: Path, text: str, line: int,
                                        message: str) -> None:
    err = error_of(tmp_path, text, 'test.launch.yaml')
    assert message in err.message
    assert (err.file, err.line) == (str(tmp_path / 'test.launch.yaml'), line)


# ---------------------------------------------------------------------------------- Python


def test_python_launch_api() -> None:
    before = list(sys.path)
    plan = describe_launch(DATA / 'python_api.launch.py')
    assert sys.path == before  # compat/ was on sys.path only while the file loaded
    names = [p.node_name for p in plan.processes()]
    assert names == ['/py/sensor', None, '/opaque_0', '/opaque_1', '/from_python', None]
    sensor, echo = plan.processes()[:2]
    assert sensor.cmd[:8] == [exe('sensor_node'), '--ros-args', '-r', '__node:=sensor',
                              '-r', '__ns:=/py', '--params-file',
                              str(share() / 'config' / 'robot_params.yaml')]
    assert temp_params(sensor.cmd[9]) == {
        '/py/sensor': {'ros__parameters': {'noise_level': 0.0, 'sensor_rate': 1}}}
    assert sensor.cmd[-2:] == ['-r', '/sensor/temperature:=temp']
    assert sensor.env['ROBOT_LAB_PY'] == 'set'
    assert echo.cmd == ['echo', '2', 'set'] and echo.label == 'echoer-2'
    assert echo.output == 'screen'
    assert sensor.source == f'{DATA / "python_api.launch.py"}:44'
    timer = plan.actions[-1]
    assert isinstance(timer, TimerSpec) and timer.period == 2.0
    assert [p.label for p in plan.processes()][-1] == 'controller_node-6'
    skipped = describe_launch(DATA / 'python_api.launch.py', args={'use_group': 'false'})
    assert next(p.node_name for p in skipped.processes()) == '/skipped'


def test_python_launch_file_errors() -> None:
    with pytest.raises(LaunchError) as info:
        describe_launch(DATA / 'python_raises.launch.py')
    assert info.value.message == "generate_launch_description() raised KeyError: 'missing'"
    assert (info.value.file, info.value.line) == (str(DATA / 'python_raises.launch.py'), 6)
    with pytest.raises(LaunchError) as info:
        describe_launch(DATA / 'python_no_generate.launch.py')
    assert "does not contain the required function 'generate_launch_description()'" in \
        info.value.message
    assert info.value.file == str(DATA / 'python_no_generate.launch.py')


def test_python_syntax_error_located(tmp_path: Path) -> None:
    err = error_of(tmp_path, 'def generate_launch_description(:\n    pass\n', 'bad.launch.py')
    assert err.message.startswith('SyntaxError') and err.line == 1


def test_real_launch_is_never_shadowed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = tmp_path / 'site' / 'launch'
    real.mkdir(parents=True)
    (real / '__init__.py').write_text('REAL = True\n\nclass LaunchDescription:\n'
                                      '    def __init__(self, entities=()):\n        pass\n')
    monkeypatch.syspath_prepend(str(tmp_path / 'site'))
    for name in [m for m in sys.modules if m == 'launch' or m.startswith('launch.')]:
        monkeypatch.delitem(sys.modules, name)
    path = write(tmp_path, """
        import launch
        assert launch.REAL
        def generate_launch_description():
            return launch.LaunchDescription()
        """, 'uses_real.launch.py')
    with pytest.raises(LaunchError) as info:
        describe_launch(path)
    assert 'a real ROS 2 `launch` is installed' in (info.value.fix or '')


def test_yaml_param_values_are_typed_as_written(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        launch:
        - let: {name: n, value: '7'}
        - node:
            pkg: robot_lab
            exec: sensor_node
            name: s
            param:
            - {name: quoted, value: '10'}
            - {name: number, value: 10}
            - {name: ratio, value: 0.5}
            - {name: flag, value: true}
            - {name: list, value: [1, 2]}
            - {name: subst, value: $(var n)}
            - {name: typed, value: $(var n), type: str}
        """, 'test.launch.yaml')
    values = {}
    for file in plan.processes()[0].param_files:
        values.update(temp_params(file)['/**']['ros__parameters'])
    assert values == {'quoted': '10', 'number': 10, 'ratio': 0.5, 'flag': True, 'list': [1, 2],
                      'subst': 7, 'typed': '7'}
    assert type(values['quoted']) is str and type(values['typed']) is str


def test_python_param_values_follow_launch_ros(tmp_path: Path) -> None:
    plan = describe_text(tmp_path, """
        from launch import LaunchDescription
        from launch.substitutions import LaunchConfiguration
        from launch_ros.actions import Node, SetParameter
        from launch_ros.parameter_descriptions import ParameterValue

        def generate_launch_description():
            n = LaunchConfiguration('n', default='7')
            return LaunchDescription([
                SetParameter(name='use_sim_time', value=True),
                Node(package='robot_lab', executable='sensor_node', name='s', namespace='ns',
                     parameters=[{
                         'plain': '10', 'number': 10, 'subst': n, 'joined': ['a', n],
                         'typed': ParameterValue(n, value_type=str),
                         'value_str': ParameterValue('10'), 'floats': [1, 2.5],
                         'group': {'x': 1, 'inner': {'y': 'z'}},
                     }]),
            ])
        """, 'test.launch.py')
    (spec,) = plan.processes()
    assert spec.cmd[6:8] == ['-p', 'use_sim_time:=True']
    assert temp_params(spec.param_files[0]) == {'/ns/s': {'ros__parameters': {
        'plain': '10', 'number': 10, 'subst': 7, 'joined': 'a7', 'typed': '7',
        'value_str': '10', 'floats': [1.0, 2.5], 'group.x': 1, 'group.inner.y': 'z'}}}


def test_param_file_with_substitutions(tmp_path: Path) -> None:
    template = tmp_path / 'template.yaml'
    template.write_text('/**:\n  ros__parameters:\n    robot_name: $(var who)\n')
    plan = describe_text(tmp_path, f"""
        <launch>
          <let name="who" value="robot_gamma"/>
          <node pkg="robot_lab" exec="robot_node" name="r">
            <param from="{template}" allow_substs="true"/>
            <param from="{template}"/>
          </node>
        </launch>""")
    substituted, as_is = plan.processes()[0].param_files
    assert temp_params(substituted) == {'/**': {'ros__parameters': {'robot_name': 'robot_gamma'}}}
    assert as_is == str(template)
