"""Writing rosbag2 folders (mcap or sqlite3) that `ros2 bag` and `rosbags` both open.

rosbags' Writer produces the files; this module adds what a recorder that may be killed
needs: `flush()` puts everything received so far on disk (an mcap chunk closed and
written, a sqlite3 transaction committed), so a SIGKILL loses at most one flush period.
It also stores what rosbag2 Jazzy stores per topic: the offered QoS profiles, the type
description hash (channel metadata `topic_type_hash` in mcap) and the message definition.
"""

from __future__ import annotations

import os
import sqlite3
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import BagError

if TYPE_CHECKING:
    from rclpy.duration import Duration
    from rclpy.qos import QoSProfile
    from rosbags.interfaces import Connection, Qos, QosTime
    from rosbags.typesys.store import Typestore

__all__ = ['STORAGE_IDS', 'BagWriter', 'TopicSpec', 'message_definition', 'qos_from_profile']

STORAGE_IDS = ('mcap', 'sqlite3')
_DISTRO = 'jazzy'


@dataclass
class TopicSpec:
    """One recorded topic as rosbag2 describes it (topic_metadata)."""

    name: str
    type: str
    offered_qos_profiles: list[Any]  # rosbags.interfaces.Qos
    type_description_hash: str = ''
    serialization_format: str = 'cdr'
    message_definition: str | None = None  # None: look it up (typestore, package share)


def qos_from_profile(profile: QoSProfile) -> Qos:
    """An rclpy QoSProfile (as a publisher offers it) -> rosbags Qos, for the metadata."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    def _time(duration: Duration) -> QosTime:
        ns = int(duration.nanoseconds)
        return QosTime(ns // 1_000_000_000, ns % 1_000_000_000)

    def _enum(kind: Any, value: Any) -> Any:
        try:
            return kind(int(value))
        except ValueError:
            return kind(kind.UNKNOWN)

    return Qos(
        _enum(QosHistory, profile.history),
        int(profile.depth),
        _enum(QosReliability, profile.reliability),
        _enum(QosDurability, profile.durability),
        _time(profile.deadline),
        _time(profile.lifespan),
        _enum(QosLiveliness, profile.liveliness),
        _time(profile.liveliness_lease_duration),
        bool(profile.avoid_ros_namespace_conventions),
    )


_TYPESTORE: Typestore | None = None


def _typestore() -> Typestore:
    global _TYPESTORE
    if _TYPESTORE is None:
        from rosbags.typesys import Stores, get_typestore

        _TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
    return _TYPESTORE


def _missing_types(store: Typestore, msgtype: str) -> list[str]:
    """The message types `msgtype` uses (itself included, directly or through the
    messages it uses) that the typestore does not know yet."""
    from rosbags.interfaces import Nodetype

    missing: list[str] = []
    seen: set[str] = set()
    pending = [msgtype]
    while pending:
        name = pending.pop()
        if name in seen:
            continue
        seen.add(name)
        if name not in store.fielddefs:
            missing.append(name)
            continue
        for _field, desc in store.fielddefs[name][1]:
            if desc[0] == Nodetype.NAME:
                pending.append(desc[1])
            elif desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                (kind, used), _count = desc[1]
                if kind == Nodetype.NAME and isinstance(used, str):
                    pending.append(used)
    return missing


def _register_from_share(msgtype: str) -> bool:
    """Teach the typestore a workspace's own message (and the messages it uses) from the
    installed .msg files; False when one of them is not installed here."""
    from rosbags.typesys import get_types_from_msg

    from robot_lab.errors import PackageNotFoundError
    from robot_lab.pkg.index import package_share

    store = _typestore()
    while missing := _missing_types(store, msgtype):
        name = missing[0]
        parts = name.split('/')
        if len(parts) != 3:
            return False
        package, _kind, leaf = parts
        try:
            text = (package_share(package) / 'msg' / f'{leaf}.msg').read_text()
        except (PackageNotFoundError, OSError):  # no definition to store
            return False
        store.register(get_types_from_msg(text, name))
        if name not in store.fielddefs:
            return False
    return True


def message_definition(msgtype: str) -> tuple[str, str]:
    """(definition text as rosbag2 stores it, RIHS01 hash), or ('', '') if unknown here."""
    store = _typestore()
    if not _register_from_share(msgtype):
        return '', ''
    msgdef, _ = store.generate_msgdef(msgtype, ros_version=2)
    return str(msgdef), str(store.hash_rihs01(msgtype))


def _file_name(file: Path, target: Path | None) -> Path:
    """Move a new storage file `<part>/<part>.ext` to rosbag2's `<bag>/<bag>_<n>.ext`."""
    renamed = target.with_suffix(file.suffix) if target is not None else \
        file.with_name(f'{file.stem}_0{file.suffix}')
    os.replace(file, renamed)
    return renamed


def _mcap_storage_class() -> type:
    from io import BytesIO

    from rosbags.rosbag2.storage_mcap import Channel, McapWriter, write_channel, write_string

    class FlushingMcapWriter(McapWriter):
        """rosbags' mcap storage plus rosbag2's `topic_type_hash` and on-demand flushing."""

        type_hashes: dict[str, str] = {}
        target: Path | None = None  # where the file goes: <bag>/<bag>_<n> (no suffix)

        def __init__(self, path: Path, compression: Any) -> None:
            super().__init__(path, compression)
            # rosbag2 names the files <bag>_0.mcap, <bag>_1.mcap, … (rosbags: <bag>.mcap).
            # The open handle survives the rename.
            self.path = _file_name(self.path, self.target)

        def add_connection(self, connection: Any, offered_qos_profiles: str) -> None:
            # The same channel record rosbag2_storage_mcap writes: two metadata entries.
            metadata = BytesIO()
            write_string(metadata, 'offered_qos_profiles')
            write_string(metadata, offered_qos_profiles)
            write_string(metadata, 'topic_type_hash')
            write_string(metadata, self.type_hashes.get(connection.topic, ''))
            channel = Channel(
                connection.id,
                connection.msgtype,
                connection.topic,
                connection.ext.serialization_format,
                metadata.getvalue(),
            )
            self.channels.append(channel)
            self.channel_stats[connection.id] = 0
            write_channel(self.chunk.bio, channel, self.schemas)

        def flush(self) -> None:
            if self.chunk.msgs:
                self.close_chunk()
            self.bio.flush()

        def close(self, version: int, metadata: str) -> None:
            super().close(version, _as_distro(metadata))

    return FlushingMcapWriter


def _sqlite_storage_class() -> type:
    from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer

    class CommittingSqlite3Writer(Sqlite3Writer):
        """rosbags' sqlite3 storage, stamped with the distro the data came from."""

        target: Path | None = None

        def __init__(self, path: Path, compression: Any) -> None:
            super().__init__(path, compression)
            # The recorder opens the bag in the caller's thread and writes in its own.
            self.conn.commit()
            self.conn.close()
            self.path = _file_name(self.path, self.target)  # <bag>_<n>.db3, as rosbag2
            self.conn = sqlite3.connect(f'file:{self.path}', uri=True, check_same_thread=False)
            self.cursor = self.conn.cursor()
            self.cursor.execute('UPDATE schema SET ros_distro = ?', (_DISTRO,))
            self.conn.commit()

        def close(self, version: int, metadata: str) -> None:
            super().close(version, _as_distro(metadata))

    return CommittingSqlite3Writer


class BagWriter:
    """A rosbag2 folder being written: topics, messages, flushes, splits and a final close.

    With `max_bag_size` (bytes) or `max_bag_duration` (seconds) the bag is split as
    rosbag2's SequentialWriter splits it: a new `<bag>_<n>` file once the current one
    reaches the size, or once a message is more than the duration after the file's first.
    Each file is a complete storage file; metadata.yaml lists them all.
    """

    MIN_SPLIT_SIZE = {'mcap': 1024, 'sqlite3': 86016}  # rosbag2's minimum split file sizes

    def __init__(self, path: str | Path, storage: str = 'mcap', *, max_bag_size: int = 0,
                 max_bag_duration: float = 0, custom_data: dict[str, str] | None = None) -> None:
        if storage not in STORAGE_IDS:
            raise BagError(
                f"Unknown storage id '{storage}'", fix=f'use one of: {", ".join(STORAGE_IDS)}'
            )
        if max_bag_size and max_bag_size < self.MIN_SPLIT_SIZE[storage]:
            raise BagError(
                'Invalid bag splitting size given. Please provide a value greater than '
                f'{self.MIN_SPLIT_SIZE[storage]}. Specified value of {max_bag_size}',
                fix=f'--max-bag-size {self.MIN_SPLIT_SIZE[storage]} or more (bytes)')
        self.path = Path(path)
        if self.path.exists():
            raise BagError(
                f"Output folder '{self.path}' already exists.",
                fix='choose another name with -o/--output, or delete the old bag first',
            )
        self.storage = storage
        self.custom_data = dict(custom_data or {})
        self.max_bag_size = int(max_bag_size)
        self.max_bag_duration_ns = int(max_bag_duration * 1e9)
        self._type_hashes: dict[str, str] = {}
        self._specs: list[TopicSpec] = []
        self.counts: dict[str, int] = {}
        self.files: list[dict[str, Any]] = []  # per file: path, start, end, count
        self.connections: dict[str, Connection] = {}
        self.closed = False
        try:
            self.path.mkdir(parents=False)
        except OSError as exc:
            raise BagError(
                f"Could not create bag folder '{self.path}': {exc.strerror}",
                fix='check that the parent folder exists and is writable',
            ) from None
        self._writer: Any = None
        self._open_file()

    def _open_file(self) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        index = len(self.files)
        target = self.path / f'{self.path.name}_{index}'
        staging = self.path / f'.{self.path.name}_{index}.part'
        plugin = StoragePlugin.MCAP if self.storage == 'mcap' else StoragePlugin.SQLITE3
        mcap_cls: Any = _mcap_storage_class()
        mcap_cls.type_hashes = self._type_hashes
        sqlite_cls: Any = _sqlite_storage_class()
        mcap_cls.target = sqlite_cls.target = target
        plugins = dict(Writer.STORAGE_PLUGINS)
        plugins[StoragePlugin.MCAP] = mcap_cls
        plugins[StoragePlugin.SQLITE3] = sqlite_cls
        writer_cls: Any = type('RobotLabWriter', (Writer,), {'STORAGE_PLUGINS': plugins})
        self._writer = writer_cls(staging, version=9, storage_plugin=plugin)
        self._writer.open()
        self._staging = staging
        self._file = Path(self._writer.storage.path)
        self._unflushed = 0
        self.files.append({'path': self._file.name, 'start': None, 'end': 0, 'count': 0})
        for spec in self._specs:
            self._add(spec)

    def _add(self, spec: TopicSpec) -> Connection:
        if spec.message_definition is not None:
            msgdef, rihs01 = spec.message_definition, ''
        else:
            msgdef, rihs01 = message_definition(spec.type)
            spec.message_definition = msgdef
        type_hash = spec.type_description_hash or rihs01
        spec.type_description_hash = type_hash
        self._type_hashes[spec.name] = type_hash
        conn: Connection = self._writer.add_connection(
            spec.name,
            spec.type,
            msgdef=msgdef,
            rihs01=type_hash or 'RIHS01_' + '0' * 64,
            serialization_format=spec.serialization_format,
            offered_qos_profiles=spec.offered_qos_profiles,
        )
        self.connections[spec.name] = conn
        return conn

    def add_topic(self, spec: TopicSpec) -> Connection:
        """Register a topic before its first message; returns its connection."""
        self._specs.append(spec)
        self.counts.setdefault(spec.name, 0)
        return self._add(spec)

    def _should_split(self, timestamp_ns: int) -> bool:
        current = self.files[-1]
        if not current['count']:
            return False
        if self.max_bag_size and \
                self._file.stat().st_size + self._unflushed >= self.max_bag_size:
            return True
        return bool(self.max_bag_duration_ns) and \
            timestamp_ns - current['start'] > self.max_bag_duration_ns

    def _close_file(self) -> None:
        import shutil

        self._writer.close()
        shutil.rmtree(self._staging, ignore_errors=True)

    def write(self, connection: Connection, timestamp_ns: int, data: bytes) -> None:
        if self._should_split(timestamp_ns):
            self._close_file()
            self._open_file()
        self._writer.write(self.connections[connection.topic], timestamp_ns, data)
        self._unflushed += len(data) + 31  # a message record's header and channel/time fields
        current = self.files[-1]
        current['start'] = timestamp_ns if current['start'] is None \
            else min(current['start'], timestamp_ns)
        current['end'] = max(current['end'], timestamp_ns)
        current['count'] += 1
        self.counts[connection.topic] += 1

    def flush(self) -> None:
        """Everything written so far goes to the file (survives a SIGKILL of this process)."""
        storage = self._writer.storage
        if storage is None:
            return
        if self.storage == 'mcap':
            storage.flush()
        else:
            storage.conn.commit()
        self._unflushed = 0

    def close(self) -> None:
        """Finish the storage file (mcap summary, sqlite metadata) and write metadata.yaml."""
        if self.closed:
            return
        self.closed = True
        self._close_file()
        write_metadata(self.path, self.storage, self._specs, self.counts, self.files,
                       custom_data=self.custom_data)


def _qos_dicts(profiles: list[Any]) -> list[dict[str, Any]]:
    """Offered profiles as rosbag2 (metadata version 9) writes them, in its key order."""
    out = []
    for p in profiles:
        if isinstance(p, dict):
            out.append(p)
            continue

        def _time(t: QosTime) -> dict[str, int]:
            return {'sec': int(t.sec), 'nsec': int(t.nsec)}

        out.append({
            'history': p.history.name.lower(), 'depth': int(p.depth),
            'reliability': p.reliability.name.lower(), 'durability': p.durability.name.lower(),
            'deadline': _time(p.deadline), 'lifespan': _time(p.lifespan),
            'liveliness': p.liveliness.name.lower(),
            'liveliness_lease_duration': _time(p.liveliness_lease_duration),
            'avoid_ros_namespace_conventions': bool(p.avoid_ros_namespace_conventions),
        })
    return out


def write_metadata(folder: Path, storage: str, specs: list[TopicSpec], counts: dict[str, int],
                   files: list[dict[str, Any]], ros_distro: str = _DISTRO,
                   custom_data: dict[str, str] | None = None) -> None:
    """metadata.yaml with rosbag2's keys in rosbag2's order (rosbag2_storage/yaml.hpp).

    `files`: per storage file, its `path`, first/last message `start`/`end` (ns) and `count`.
    """
    import yaml

    def span(items: list[dict[str, Any]]) -> tuple[int, int]:
        starts = [f['start'] for f in items if f['count']]
        if not starts:
            return 0, 0
        return min(starts), max(f['end'] for f in items if f['count']) - min(starts)

    start, duration = span(files)
    doc = {'rosbag2_bagfile_information': {
        'version': 9,
        'storage_identifier': storage,
        'duration': {'nanoseconds': duration},
        'starting_time': {'nanoseconds_since_epoch': start},
        'message_count': sum(f['count'] for f in files),
        'topics_with_message_count': [
            {'topic_metadata': {
                'name': s.name, 'type': s.type,
                'serialization_format': s.serialization_format,
                'offered_qos_profiles': _qos_dicts(list(s.offered_qos_profiles)),
                'type_description_hash': s.type_description_hash,
            }, 'message_count': counts.get(s.name, 0)}
            for s in specs
        ],
        'compression_format': '',
        'compression_mode': '',
        'relative_file_paths': [f['path'] for f in files],
        'files': [
            {'path': f['path'],
             'starting_time': {'nanoseconds_since_epoch': span([f])[0]},
             'duration': {'nanoseconds': span([f])[1]},
             'message_count': f['count']}
            for f in files
        ],
        'custom_data': dict(custom_data) if custom_data else None,
        'ros_distro': ros_distro,
    }}
    tmp = folder / 'metadata.yaml.tmp'
    tmp.write_text(yaml.safe_dump(doc, sort_keys=False, default_flow_style=False))
    os.replace(tmp, folder / 'metadata.yaml')


def _as_distro(text: str) -> str:
    return text.replace('ros_distro: rosbags', f'ros_distro: {_DISTRO}')
