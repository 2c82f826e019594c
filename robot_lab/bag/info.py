"""What is in a bag, as data (`bag_info`) and as `ros2 bag info` prints it (`format_info`).

Like rosbag2's Info: a folder is described by its metadata.yaml (size = the folder's
size); a single .mcap/.db3 file by what its storage says about itself.
"""

from __future__ import annotations

import sqlite3
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robot_lab.bag.read import STORAGE_SUFFIXES, open_bag
from robot_lab.bag.services import event_topic, is_service_event, service_name
from robot_lab.errors import BagError

__all__ = ['BagInfo', 'ServiceInfo', 'TopicInfo', 'bag_info', 'format_info', 'format_verbose',
           'service_info']

_INDENT = 19  # rosbag2: the longest label ("Topic information: ") is 19 characters


@dataclass
class TopicInfo:
    """One topic of a bag (rosbag2's TopicInformation)."""

    name: str
    type: str
    count: int
    serialization_format: str = 'cdr'
    offered_qos_profiles: list[dict[str, Any]] = field(default_factory=list)
    type_description_hash: str = ''


@dataclass
class BagInfo:
    """A bag's metadata: files, size, storage, time span, and per-topic counts."""

    path: Path
    files: list[str]
    size: int
    storage_id: str
    ros_distro: str
    start_ns: int
    duration_ns: int
    message_count: int
    topics: list[TopicInfo]
    version: int = 9

    @property
    def end_ns(self) -> int:
        return self.start_ns + self.duration_ns

    @property
    def duration(self) -> float:
        """Seconds between the first and the last message."""
        return self.duration_ns / 1e9

    def topic(self, name: str) -> TopicInfo:
        for info in self.topics:
            if info.name == name:
                return info
        have = ', '.join(t.name for t in self.topics) or 'none'
        raise BagError(f"Topic '{name}' is not in bag '{self.path}'", fix=f'topics: {have}')

    def __str__(self) -> str:
        return format_info(self)


def _qos_list(raw: Any) -> list[dict[str, Any]]:
    if isinstance(raw, str):  # metadata version < 9 stores a YAML string
        raw = yaml.safe_load(raw) if raw.strip() else []
    return list(raw or [])


def _from_metadata(path: Path) -> BagInfo:
    meta_path = path / 'metadata.yaml'
    try:
        doc = yaml.safe_load(meta_path.read_text())
        meta = doc['rosbag2_bagfile_information']
        topics = [
            TopicInfo(
                name=t['topic_metadata']['name'],
                type=t['topic_metadata']['type'],
                count=int(t['message_count']),
                serialization_format=t['topic_metadata'].get('serialization_format', 'cdr'),
                offered_qos_profiles=_qos_list(t['topic_metadata'].get('offered_qos_profiles')),
                type_description_hash=t['topic_metadata'].get('type_description_hash', ''),
            )
            for t in meta.get('topics_with_message_count') or []
        ]
        size = sum(p.stat().st_size for p in path.rglob('*') if p.is_file())
        return BagInfo(
            path=path,
            files=[str(f) for f in meta.get('relative_file_paths') or []],
            size=size,
            storage_id=str(meta.get('storage_identifier', '')),
            ros_distro=str(meta.get('ros_distro') or 'unknown'),
            start_ns=int(meta['starting_time']['nanoseconds_since_epoch']),
            duration_ns=int(meta['duration']['nanoseconds']),
            message_count=int(meta['message_count']),
            topics=topics,
            version=int(meta.get('version', 0)),
        )
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as exc:
        raise BagError(
            f'Exception on parsing info file: {exc!r}',
            file=meta_path,
            fix=f'rebuild it from the storage files with `robot-lab bag reindex {path}`',
        ) from None


def _sqlite_distro(path: Path) -> str:
    try:
        with sqlite3.connect(f'file:{path}?mode=ro', uri=True) as db:
            row = db.execute('SELECT ros_distro FROM schema').fetchone()
            return str(row[0]) if row else 'unknown'
    except sqlite3.Error:
        return 'unknown'


def _mcap_distro(path: Path) -> str:
    """ros_distro from the file's `rosbag2` metadata record (rosbag2 stores it there)."""
    try:
        from mcap.reader import make_reader

        with path.open('rb') as f:
            for record in make_reader(f).iter_metadata():
                if record.name == 'rosbag2':
                    meta = yaml.safe_load(record.metadata.get('serialized_metadata', '')) or {}
                    return str(meta.get('ros_distro') or 'unknown')
    except Exception:  # no mcap library or no record: rosbag2 says unknown
        pass
    return 'unknown'


def _from_file(path: Path) -> BagInfo:
    with open_bag(path) as reader:
        count = int(reader.message_count)
        topics = [
            TopicInfo(
                name=c.topic,
                type=c.msgtype,
                count=int(c.msgcount),
                serialization_format=c.ext.serialization_format,
                type_description_hash=c.digest or '',
            )
            for c in reader.connections
        ]
        start = int(reader.start_time) if count else 0
        # rosbags reports end exclusive (last + 1 ns); rosbag2 reports last - first.
        duration = max(0, int(reader.duration) - 1) if count else 0
        distro = reader.ros_distro
    storage = STORAGE_SUFFIXES[path.suffix]
    if not distro:
        distro = _sqlite_distro(path) if storage == 'sqlite3' else _mcap_distro(path)
    return BagInfo(
        path=path,
        files=[str(path)],
        size=path.stat().st_size,
        storage_id=storage,
        ros_distro=str(distro),
        start_ns=start,
        duration_ns=duration,
        message_count=count,
        topics=topics,
    )


def bag_info(bag: str | Path) -> BagInfo:
    """Metadata of a bag folder or a single .mcap/.db3 file (`ros2 bag info`'s data)."""
    path = Path(bag)
    if path.is_dir() and (path / 'metadata.yaml').is_file():
        return _from_metadata(path)
    with open_bag(path):  # a clear error for a missing, foreign or unfinished bag
        pass
    return _from_file(path)


def _file_size(size: int) -> str:
    value = float(size)
    units = ('B', 'KiB', 'MiB', 'GiB', 'TiB')
    index = 0
    while value >= 1024 and index < 4:
        value /= 1024
        index += 1
    return f'{value:.0f} {units[index]}' if index == 0 else f'{value:.1f} {units[index]}'


def _seconds(ns: int) -> str:
    return f'{ns // 1_000_000_000}.{ns % 1_000_000_000:09d}'


def _time_point(ns: int) -> str:
    local = time.localtime(ns // 1_000_000_000)
    day = f'{local.tm_mday:2d}'  # %e: space-padded day of the month
    date = time.strftime(f'%b {day} %Y', local)
    clock = time.strftime('%H:%M:%S', local) + f'.{ns % 1_000_000_000:09d}'
    return f'{date} {clock} ({_seconds(ns)})'


def _is_service_event(topic: TopicInfo) -> bool:
    return is_service_event(topic.name, topic.type)


@dataclass
class ServiceInfo:
    """A recorded service (its `_service_event` topic): requests and responses seen."""

    name: str
    type: str
    request_count: int
    response_count: int
    serialization_format: str = 'cdr'


def _event_key(data: bytes) -> tuple[int, bytes, int]:
    """(event_type, client_gid, sequence_number) from a service event's CDR bytes.

    Every `<Srv>_Event` starts with service_msgs/ServiceEventInfo: uint8 event_type,
    builtin_interfaces/Time stamp, uint8[16] client_gid, int64 sequence_number.
    """
    import struct

    little = data[1] == 1  # CDR encapsulation: 0x0001 little endian, 0x0000 big endian
    seq = struct.unpack_from('<q' if little else '>q', data, 4 + 32)[0]
    return data[4], bytes(data[4 + 12:4 + 28]), int(seq)


def service_info(bag: str | Path) -> list[ServiceInfo]:
    """Request/response counts per recorded service, as `ros2 bag info --verbose` counts them
    (distinct client and sequence number; sent and received events count once)."""
    from robot_lab.bag.read import bag_messages

    out: list[ServiceInfo] = []
    with open_bag(bag) as reader:
        conns = [c for c in reader.connections
                 if _is_service_event(TopicInfo(c.topic, c.msgtype, 0))]
        seen: dict[str, tuple[set[tuple[bytes, int]], set[tuple[bytes, int]]]] = {}
        for conn in conns:
            if conn.topic not in seen:
                seen[conn.topic] = (set(), set())
                out.append(ServiceInfo(service_name(conn.topic),
                                       conn.msgtype[: -len('_Event')], 0, 0,
                                       conn.ext.serialization_format))
        for conn, _stamp, data in bag_messages(reader, conns):
            try:
                kind, gid, seq = _event_key(bytes(data))
            except Exception:  # a truncated event: rosbag2 would fail; skip it here
                continue
            requests, responses = seen[conn.topic]
            if kind in (0, 1):  # REQUEST_SENT, REQUEST_RECEIVED
                requests.add((gid, seq))
            elif kind in (2, 3):  # RESPONSE_SENT, RESPONSE_RECEIVED
                responses.add((gid, seq))
    for item in out:
        requests, responses = seen[event_topic(item.name)]
        item.request_count, item.response_count = len(requests), len(responses)
    return out


def format_verbose(info: BagInfo, services: list[ServiceInfo]) -> str:
    """`ros2 bag info --verbose`: the topic part, then request/response counts per service."""
    lines = format_info(info).split('\n')
    while not lines[-1].startswith('Service:'):
        lines.pop()
    lines.pop()  # the metadata's own service lines are replaced by the counted ones
    lines.append('Service:           ' + str(len(services)))
    text = [
        f'Service: {s.name} | Type: {s.type} | Request Count: {s.request_count} | '
        f'Response Count: {s.response_count} | Serialization Format: '
        f'{s.serialization_format}'
        for s in services
    ]
    head = 'Service information: '
    lines.append(head + (text[0] if text else ''))
    lines.extend(' ' * len(head) + t for t in text[1:])
    return '\n'.join(lines) + ('\n' if text else '')  # rosbag2 ends the list with endl


def format_info(info: BagInfo) -> str:
    """The text `ros2 bag info` prints (Jazzy layout), without the final newline."""
    pad = ' ' * _INDENT
    topics = [t for t in info.topics if not _is_service_event(t)]
    services = [t for t in info.topics if _is_service_event(t)]
    lines = ['']
    files = info.files or ['']
    lines.append('Files:             ' + files[0])
    lines.extend(pad + f for f in files[1:])
    lines.append('Bag size:          ' + _file_size(info.size))
    lines.append('Storage id:        ' + info.storage_id)
    lines.append('ROS Distro:        ' + (info.ros_distro or 'unknown'))
    lines.append('Duration:          ' + _seconds(info.duration_ns) + 's')
    lines.append('Start:             ' + _time_point(info.start_ns))
    lines.append('End:               ' + _time_point(info.end_ns))
    lines.append(
        'Messages:          ' + str(info.message_count - sum(s.count for s in services))
    )

    def topic_line(t: TopicInfo) -> str:
        return (
            f'Topic: {t.name} | Type: {t.type} | Count: {t.count} | '
            f'Serialization Format: {t.serialization_format}'
        )

    if topics:
        lines.append('Topic information: ' + topic_line(topics[0]))
        lines.extend(pad + topic_line(t) for t in topics[1:])
    else:
        lines.append('Topic information: ')
    lines.append('Service:           ' + str(len(services)))
    service_lines = [
        f'Service: {service_name(s.name)} | '
        f'Type: {s.type[: -len("_Event")]} | Event Count: {s.count} | '
        f'Serialization Format: {s.serialization_format}'
        for s in services
    ]
    if service_lines:
        lines.append('Service information: ' + service_lines[0])
        lines.extend(' ' * (_INDENT + 2) + s for s in service_lines[1:])
    else:
        lines.append('Service information: ')
    return '\n'.join(lines)
