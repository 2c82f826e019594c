"""robot_lab.params against rcl_yaml_param_parser: the same files accepted, the same refused.

Every rule is checked twice: robot_lab's message (file, line, fix), and real rcl (the
wheel's rclpy parses `--params-file` in rclpy.init, no DDS participant) agreeing.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import yaml

from robot_lab.errors import ParamFileError
from robot_lab.params import (
    dump_params,
    load_param_file,
    node_parameters,
    parse_value,
    write_param_file,
)

DATA = Path(__file__).resolve().parent / 'data' / 'launch'
REPO = Path(__file__).resolve().parents[1]


def rcl_error(path: Path) -> str | None:
    """What real rcl says about a parameter file (None: accepted)."""
    import rclpy

    context = rclpy.Context()
    try:
        rclpy.init(args=['x', '--ros-args', '--params-file', str(path)], context=context)
    except Exception as err:
        return str(err)
    context.try_shutdown()
    return None


def write(tmp_path: Path, text: str, name: str = 'params.yaml') -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_seed_flat_file_refused_with_nested_form_shown() -> None:
    path = DATA / 'robot_params.yaml'
    with pytest.raises(ParamFileError) as info:
        load_param_file(path)
    err = info.value
    assert err.file == str(path) and err.line == 2
    assert err.message == 'Cannot have a value before ros__parameters at line 2'
    assert err.fix is not None
    assert '/**: {ros__parameters: {sensor_rate: 10, noise_level: 0.1' in err.fix
    text = str(err)
    assert text.startswith(f'{path}:2: ') and 'robot_params.yaml' in text
    rcl = rcl_error(path)
    assert rcl is not None and 'Cannot have a value before ros__parameters at line 2' in rcl


def test_nested_form_shown_in_the_fix_is_accepted(tmp_path: Path) -> None:
    with pytest.raises(ParamFileError) as info:
        load_param_file(DATA / 'flat_params.yaml')
    assert info.value.fix is not None
    nested = info.value.fix.split('"')[1]
    path = write(tmp_path, nested + '\n')
    assert load_param_file(path) == {'/**': {
        'sensor_rate': 10, 'noise_level': 0.1, 'control_rate': 20, 'temp_threshold': 25.0}}
    assert rcl_error(path) is None


def test_shipped_config_is_nested_and_accepted() -> None:
    path = REPO / 'config' / 'robot_params.yaml'
    params = load_param_file(path)
    assert params['/**']['sensor_rate'] == 10
    assert params['/**']['temp_threshold'] == 25.0
    assert rcl_error(path) is None


@pytest.mark.parametrize(('text', 'line', 'message'), [
    ('ros__parameters:\n  a: 1\n', 1, 'There are no node names before ros__parameters at line 1'),
    ('/**:\n  ros__parameters:\n    l: [1, 2.0]\n', 3,
     "Sequence should be of same type. Value type 'double' do not belong at line_num 3"),
    ('/**:\n  ros__parameters:\n    l: [true, 1]\n', 3,
     "Sequence should be of same type. Value type 'integer' do not belong at line_num 3"),
    ('/**:\n  ros__parameters:\n    l: [a, 1]\n', 3,
     "Sequence should be of same type. Value type 'integer' do not belong at line_num 3"),
    ('node:\n  a: 1\n', 2, 'Cannot have a value before ros__parameters at line 2'),
    ('/**:\n  ros__parameters:\n    x: &a 1\n    y: *a\n', 4,
     'Will not support aliasing at line 4'),
])
def test_rcl_rules(tmp_path: Path, text: str, line: int, message: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ParamFileError) as info:
        load_param_file(path)
    assert info.value.message == message
    assert info.value.line == line and info.value.file == str(path)
    rcl = rcl_error(path)
    assert rcl is not None and message in rcl


def test_unreadable_yaml_names_the_line(tmp_path: Path) -> None:
    path = write(tmp_path, '/**:\n  ros__parameters:\n    a: [1\n    b: 2\n')
    with pytest.raises(ParamFileError) as info:
        load_param_file(path)
    assert info.value.message.startswith('Error parsing a event near line 3')
    rcl = rcl_error(path)
    assert rcl is not None and 'Error parsing a event near line 3' in rcl


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(ParamFileError) as info:
        load_param_file(tmp_path / 'nope.yaml')
    assert info.value.file == str(tmp_path / 'nope.yaml')
    assert 'not found' in info.value.message


def test_values_names_and_namespaces(tmp_path: Path) -> None:
    path = write(tmp_path, (
        'robot1:\n'
        '  sensor:\n'
        '    ros__parameters:\n'
        '      rate: 10\n'
        '      gains:\n'
        '        p: 1.5\n'
        '        deep:\n'
        '          on: yes\n'
        '      quoted: "10"\n'
        '      word: abc\n'
        '      ints: [1, 2, 3]\n'
        '      strs: [a, "b"]\n'
        '/other/node:\n'
        '  ros__parameters:\n'
        '    hex: 0x10\n'
        '    exp: 1e3\n'
        '    inf: -.inf\n'
        '    flag: off\n'
        '    y: y\n'
    ))
    params = load_param_file(path)
    assert params['/robot1/sensor'] == {
        'rate': 10, 'gains.p': 1.5, 'gains.deep.on': True, 'quoted': '10', 'word': 'abc',
        'ints': [1, 2, 3], 'strs': ['a', 'b'],
    }
    other = params['/other/node']
    assert other['hex'] == 16 and other['exp'] == 1000.0 and math.isinf(other['inf'])
    assert other['flag'] is False and other['y'] is True
    assert rcl_error(path) is None


def real_overrides(files: list[Path], name: str, namespace: str) -> dict[str, Any]:
    """The parameter values a real rclpy node gets from these --params-file arguments."""
    import rclpy

    args = ['x', '--ros-args']
    for file in files:
        args += ['--params-file', str(file)]
    context = rclpy.Context()
    rclpy.init(args=args, context=context)
    try:
        node = rclpy.create_node(name, namespace=namespace, context=context,
                                 automatically_declare_parameters_from_overrides=True)
        values = {k: p.value for k, p in node._parameters.items()
                  if k not in ('use_sim_time', 'start_type_description_service')}
        node.destroy_node()
    finally:
        context.try_shutdown()
    return values


def test_precedence_matches_rclpy(tmp_path: Path) -> None:
    """Later files win; sections apply in order of first appearance, so the usual layout
    (`/**` first, the node's own name after) lets the fully qualified name win."""
    usual = write(tmp_path, (
        '/**:\n  ros__parameters:\n    a: wild\n    c: wild\n'
        '/robot1/sensor:\n  ros__parameters:\n    a: exact\n    b: exact\n'
    ), 'usual.yaml')
    later = write(tmp_path, (
        '/robot1/*:\n  ros__parameters:\n    b: one_token\n'
        '/**:\n  ros__parameters:\n    c: wild_later\n    d: wild_later\n'
    ), 'later.yaml')
    expected = {'a': 'exact', 'b': 'one_token', 'c': 'wild_later', 'd': 'wild_later'}
    assert node_parameters([usual, later], '/robot1/sensor') == expected
    assert real_overrides([usual, later], 'sensor', '/robot1') == expected
    # a node the exact and one-token sections do not match gets the wildcard only
    assert node_parameters([usual, later], '/other') == {'a': 'wild', 'c': 'wild_later',
                                                          'd': 'wild_later'}
    # the exact section first: the wildcard, applied after it, wins (rclpy's order)
    reversed_order = write(tmp_path, (
        '/robot1/sensor:\n  ros__parameters:\n    a: exact\n'
        '/**:\n  ros__parameters:\n    a: wild\n'
    ), 'reversed.yaml')
    assert node_parameters([reversed_order], '/robot1/sensor') == {'a': 'wild'}
    assert real_overrides([reversed_order], 'sensor', '/robot1') == {'a': 'wild'}


@pytest.mark.parametrize(('text', 'value'), [
    ('10', 10), ('-3', -3), ('0.5', 0.5), ('1e3', 1000.0), ('true', True), ('False', False),
    ('yes', True), ('off', False), ('abc', 'abc'), ('"10"', '10'), ("'true'", 'true'),
    ('[1, 2]', [1, 2]), ('[1.0, 2.5]', [1.0, 2.5]), ('[a, b]', ['a', 'b']), ('', ''),
    ('0x1f', 31), ('hello world', 'hello world'),
])
def test_parse_value_types_like_rcl(text: str, value: Any) -> None:
    assert parse_value(text) == value
    assert type(parse_value(text)) is type(value)


def test_parse_value_refuses_mixed_lists() -> None:
    with pytest.raises(ParamFileError, match='Sequence should be of same type'):
        parse_value('[1, a]')


def test_dump_params_is_what_param_dump_prints_and_rcl_reads(tmp_path: Path) -> None:
    text = dump_params({'/sensor': {'sensor_rate': 10, 'noise_level': 9.0, 'gains.p': 1.5,
                                    'names': ['a', 'b'], 'flag': True, 'label': 'yes'}})
    assert text.startswith('/sensor:\n  ros__parameters:\n    flag: true\n    gains:\n'
                           '      p: 1.5\n')
    path = write(tmp_path, text)
    assert load_param_file(path) == {'/sensor': {
        'sensor_rate': 10, 'noise_level': 9.0, 'gains.p': 1.5, 'names': ['a', 'b'],
        'flag': True, 'label': 'yes'}}
    assert rcl_error(path) is None


def test_write_param_file_like_launch_ros(tmp_path: Path) -> None:
    path = write_param_file({'robot_name': 'robot_alpha', 'g.x': 1}, '/ns/robot',
                            directory=tmp_path)
    assert path.name.startswith('launch_params_') and path.parent == tmp_path
    assert yaml.safe_load(path.read_text()) == {
        '/ns/robot': {'ros__parameters': {'robot_name': 'robot_alpha', 'g.x': 1}}}
    assert load_param_file(path) == {'/ns/robot': {'robot_name': 'robot_alpha', 'g.x': 1}}
    assert rcl_error(path) is None
