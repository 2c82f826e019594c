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
from typing import Any

from robot_lab.errors import BagError

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


def qos_from_profile(profile: Any) -> Any:
    """An rclpy QoSProfile (as a publisher offers it) -> rosbags Qos, for the metadata."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    def _time(duration: Any) -> Any:
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


_TYPESTORE: Any = None


def _typestore() -> Any:
    global _TYPESTORE
    if _TYPESTORE is None:
        from rosbags.typesys import Stores, get_typestore

        _TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
    return _TYPESTORE


def _register_from_share(msgtype: str) -> bool:
    """Teach the typestore a workspace's own message from its installed .msg file."""
    from rosbags.typesys import get_types_from_msg

    from robot_lab.pkg.index import package_share

    store = _typestore()
    pending = [msgtype]
    for _ in range(50):  # a message and the messages it uses, until all are known
        if not pending:
            return True
        name = pending.pop()
        package, _kind, leaf = name.split('/')
        try:
            text = (package_share(package) / 'msg' / f'{leaf}.msg').read_text()
        except Exception:  # package or file missing: no definition to store
            return False
        store.register(get_types_from_msg(text, name))
        try:
            store.generate_msgdef(msgtype, ros_version=2)
        except Exception as exc:
            missing = str(exc).split("'")
            dep = next((m for m in missing if m.count('/') == 2), None)
            if dep is None or dep == name:
                return False
            pending.extend([name, dep])
    return False


def message_definition(msgtype: str) -> tuple[str, str]:
    """(definition text as rosbag2 stores it, RIHS01 hash), or ('', '') if unknown here."""
    store = _typestore()
    if msgtype not in store.fielddefs and not _register_from_share(msgtype):
        return '', ''
    try:
        msgdef, _ = store.generate_msgdef(msgtype, ros_version=2)
        return str(msgdef), str(store.hash_rihs01(msgtype))
    except Exception:
        return '', ''


def _first_file_name(file: Path) -> Path:
    """Rename a new storage file `<bag>.ext` to rosbag2's `<bag>_0.ext`; the new path."""
    renamed = file.with_name(f'{file.stem}_0{file.suffix}')
    os.replace(file, renamed)
    return renamed


def _mcap_storage_class() -> type:
    from io import BytesIO

    from rosbags.rosbag2.storage_mcap import Channel, McapWriter, write_channel, write_string

    class FlushingMcapWriter(McapWriter):  # type: ignore[misc]
        """rosbags' mcap storage plus rosbag2's `topic_type_hash` and on-demand flushing."""

        type_hashes: dict[str, str] = {}

        def __init__(self, path: Path, compression: Any) -> None:
            super().__init__(path, compression)
            # rosbag2 names the first file <bag>_0.mcap (rosbags: <bag>.mcap); metadata.yaml
            # lists self.path. The open handle survives the rename.
            self.path = _first_file_name(self.path)

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

    class CommittingSqlite3Writer(Sqlite3Writer):  # type: ignore[misc]
        """rosbags' sqlite3 storage, stamped with the distro the data came from."""

        def __init__(self, path: Path, compression: Any) -> None:
            super().__init__(path, compression)
            # The recorder opens the bag in the caller's thread and writes in its own.
            self.conn.commit()
            self.conn.close()
            self.path = _first_file_name(self.path)  # <bag>_0.db3, as rosbag2 names it
            self.conn = sqlite3.connect(f'file:{self.path}', uri=True, check_same_thread=False)
            self.cursor = self.conn.cursor()
            self.cursor.execute('UPDATE schema SET ros_distro = ?', (_DISTRO,))
            self.conn.commit()

        def close(self, version: int, metadata: str) -> None:
            super().close(version, _as_distro(metadata))

    return CommittingSqlite3Writer


class BagWriter:
    """A rosbag2 folder being written: topics, messages, flushes, and a final close."""

    def __init__(self, path: str | Path, storage: str = 'mcap') -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        if storage not in STORAGE_IDS:
            raise BagError(
                f"Unknown storage id '{storage}'", fix=f'use one of: {", ".join(STORAGE_IDS)}'
            )
        self.path = Path(path)
        if self.path.exists():
            raise BagError(
                f"Output folder '{self.path}' already exists.",
                fix='choose another name with -o/--output, or delete the old bag first',
            )
        self.storage = storage
        self._type_hashes: dict[str, str] = {}
        plugin = StoragePlugin.MCAP if storage == 'mcap' else StoragePlugin.SQLITE3
        mcap_cls: Any = _mcap_storage_class()
        mcap_cls.type_hashes = self._type_hashes
        plugins = dict(Writer.STORAGE_PLUGINS)
        plugins[StoragePlugin.MCAP] = mcap_cls
        plugins[StoragePlugin.SQLITE3] = _sqlite_storage_class()
        writer_cls: Any = type('RobotLabWriter', (Writer,), {'STORAGE_PLUGINS': plugins})
        self._writer = writer_cls(self.path, version=9, storage_plugin=plugin)
        try:
            self._writer.open()
        except Exception as exc:
            raise BagError(
                f"Could not create bag folder '{self.path}': {exc}",
                fix='check that the parent folder exists and is writable',
            ) from None
        self.connections: dict[str, Any] = {}
        self.closed = False

    def add_topic(self, spec: TopicSpec) -> Any:
        """Register a topic before its first message; returns its connection."""
        if spec.message_definition is not None:
            msgdef, rihs01 = spec.message_definition, ''
        else:
            msgdef, rihs01 = message_definition(spec.type)
        type_hash = spec.type_description_hash or rihs01
        self._type_hashes[spec.name] = type_hash
        conn = self._writer.add_connection(
            spec.name,
            spec.type,
            msgdef=msgdef,
            rihs01=type_hash or 'RIHS01_' + '0' * 64,
            serialization_format=spec.serialization_format,
            offered_qos_profiles=spec.offered_qos_profiles,
        )
        self.connections[spec.name] = conn
        return conn

    def write(self, connection: Any, timestamp_ns: int, data: bytes) -> None:
        self._writer.write(connection, timestamp_ns, data)

    def flush(self) -> None:
        """Everything written so far goes to the file (survives a SIGKILL of this process)."""
        storage = self._writer.storage
        if storage is None:
            return
        if self.storage == 'mcap':
            storage.flush()
        else:
            storage.conn.commit()

    def close(self) -> None:
        """Finish the storage file (mcap summary, sqlite metadata) and write metadata.yaml."""
        if self.closed:
            return
        self.closed = True
        self._writer.close()
        _set_ros_distro(self.path / 'metadata.yaml')


def _as_distro(text: str) -> str:
    return text.replace('ros_distro: rosbags', f'ros_distro: {_DISTRO}')


def _set_ros_distro(metadata: Path) -> None:
    """rosbags writes `ros_distro: rosbags`; rosbag2 writes the distro the data came from."""
    text = metadata.read_text()
    patched = _as_distro(text)
    if patched != text:
        tmp = metadata.with_suffix('.yaml.tmp')
        tmp.write_text(patched)
        os.replace(tmp, metadata)
