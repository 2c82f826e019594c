"""`bag info --verbose` and `-t` on rosbag2's own bag with service events (tests/data/rosbag2).

The expected lines are the ones rosbag2's test_rosbag2_info_end_to_end.cpp expects of the
same files: topics without the service-event topics, then each service's request and
response counts (distinct client and sequence number).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import REPO, run_cli

DATA = REPO / 'tests' / 'data' / 'rosbag2'


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_verbose_counts_service_requests_and_responses(storage: str) -> None:
    bag = DATA / f'bag_with_topics_and_service_events_{storage}'
    out = run_cli('bag', 'info', '--verbose', str(bag))
    assert out.returncode == 0, out.stderr
    text = out.stdout
    suffix = 'mcap' if storage == 'mcap' else 'db3'
    assert f'\nFiles:             bag_with_topics_and_service_events.{suffix}\n' in text
    assert f'\nStorage id:        {storage}\nROS Distro:        unknown\n' in text
    assert '\nDuration:          0.0706' in text and '(1699345836.' in text
    assert '\nMessages:          2\nTopic information: ' in text
    assert ('Topic: /test_topic1 | Type: test_msgs/msg/Strings | Count: 1 | '
            'Serialization Format: cdr\n') in text
    assert '/_service_event' not in text
    assert text.endswith(
        'Service:           2\n'
        'Service information: Service: /test_service1 | Type: test_msgs/srv/BasicTypes | '
        'Request Count: 2 | Response Count: 2 | Serialization Format: cdr\n'
        '                     Service: /test_service2 | Type: test_msgs/srv/BasicTypes | '
        'Request Count: 2 | Response Count: 2 | Serialization Format: cdr\n\n')


def test_plain_info_counts_events_and_topic_names_skip_them(tmp_path: Path) -> None:
    bag = DATA / 'bag_with_topics_and_service_events_mcap'
    plain = run_cli('bag', 'info', str(bag)).stdout
    assert plain.endswith(
        'Service:           2\n'
        'Service information: Service: /test_service1 | Type: test_msgs/srv/BasicTypes | '
        'Event Count: 4 | Serialization Format: cdr\n'
        '                     Service: /test_service2 | Type: test_msgs/srv/BasicTypes | '
        'Event Count: 4 | Serialization Format: cdr\n')
    names = run_cli('bag', 'info', '-t', str(bag))
    assert names.stdout.split() == ['/events/write_split', '/test_topic1', '/test_topic2']
    both = run_cli('bag', 'info', '-t', '-v', str(bag)).stdout
    assert both.startswith("Warning! You have set both the '-t' and '-v' parameters. "
                           "The '-t' parameter will be ignored.\n\nFiles:")
