"""Opening a bag (a rosbag2 folder, or one `.mcap`/`.db3` file) and reading its messages.

`ros2 bag info/play` accept both a folder and a single storage file; so does everything
here. Failures become one-line BagErrors that say what is wrong with the bag and what to
run next (`robot-lab bag reindex` after a killed recording), not a rosbags traceback.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import BagError, GraphError

if TYPE_CHECKING:
    from rosbags.interfaces import Connection
    from rosbags.rosbag2 import Reader

__all__ = [
    'STORAGE_SUFFIXES',
    'TopicColumns',
    'bag_files',
    'bag_messages',
    'decode',
    'open_bag',
    'read_topic',
]

STORAGE_SUFFIXES = {'.mcap': 'mcap', '.db3': 'sqlite3'}


def bag_files(path: Path) -> list[Path]:
    """The storage files of a bag folder (or the file itself)."""
    if path.is_file():
        return [path]
    return sorted(p for p in path.iterdir() if p.suffix in STORAGE_SUFFIXES and p.is_file())


def _check_path(path: Path) -> None:
    if not path.exists():
        raise BagError(
            f"Bag path '{path}' does not exist!",
            fix='give the folder `robot-lab bag record` made (or a .mcap/.db3 file in it)',
        )
    if path.is_file():
        if path.suffix not in STORAGE_SUFFIXES:
            raise BagError(
                f"'{path}' is not a rosbag2 file (expected a .mcap or .db3 file)",
                fix='give a rosbag2 folder, or the .mcap/.db3 file inside it',
            )
        return
    if (path / 'metadata.yaml').is_file():
        return
    if bag_files(path):
        raise BagError(
            f"'{path}' has no metadata.yaml: its recording is still running, or was killed "
            'before it finished',
            fix=f'rebuild it from the storage file with `robot-lab bag reindex {path}`',
        )
    raise BagError(
        f"'{path}' is not a rosbag2 bag: no metadata.yaml and no .mcap or .db3 file in it",
        fix='give the folder `robot-lab bag record` made',
    )


def _explain(path: Path, exc: Exception) -> BagError:
    text = str(exc).rstrip('.')
    where = path
    if text == 'File magic is invalid' or 'seems to be empty' in text:
        return BagError(
            f"'{where}' is not an MCAP file ({text})",
            fix='give a bag folder or a .mcap/.db3 file written by `bag record`',
        )
    if 'magic' in text.lower() or 'footer' in text.lower() or 'summary' in text.lower():
        folder = path if path.is_dir() else path.parent
        return BagError(
            f"'{where}' is incomplete: the MCAP file has no footer/summary ({text}); "
            'the recorder was killed before it closed the file',
            fix=f'recover what was written with `robot-lab bag reindex {folder}`',
        )
    if text.startswith('Serialization format'):  # rosbags: {'fmt'} is not supported
        formats = text.split('{', 1)[-1].split('}', 1)[0].replace("'", '')
        return BagError(
            f"Could not find converter for format {formats} (bag '{where}')",
            fix='only bags serialized as cdr (what rmw_fastrtps and rmw_cyclonedds write) '
            'can be read and played',
        )
    if 'profile is not ros2' in text.lower():
        return BagError(
            f"'{where}' is an MCAP file, but not a ROS 2 one (profile is not 'ros2')",
            fix='only rosbag2 bags can be read/played here',
        )
    if 'file is not a database' in text.lower() or 'no such table' in text.lower():
        return BagError(
            f"'{where}' is not a rosbag2 sqlite3 database ({text})",
            fix='give a .db3 file written by `ros2 bag record -s sqlite3`',
        )
    if 'missing' in text.lower():
        return BagError(
            f"'{where}': {text}",
            fix=f'the storage files moved or were deleted; `robot-lab bag reindex {where}` '
            'rebuilds metadata.yaml from the files that are there',
        )
    return BagError(
        f"Cannot read bag '{where}': {text}",
        fix=f'if a recording was interrupted, try `robot-lab bag reindex {where}`',
    )


@contextmanager
def open_bag(path: str | Path) -> Iterator[Any]:
    """An open rosbags Reader for a bag folder or a single .mcap/.db3 file."""
    import sqlite3

    from rosbags.rosbag2 import Reader
    from rosbags.rosbag2.errors import ReaderError

    bag = Path(path)
    _check_path(bag)
    try:
        reader = Reader(bag)
        reader.open()
    except (ReaderError, OSError, sqlite3.DatabaseError, KeyError, ValueError) as exc:
        raise _explain(bag, exc) from None
    try:
        yield reader
    finally:
        reader.close()


def bag_messages(reader: Reader, connections: Sequence[Connection], start: int | None = None,
                 stop: int | None = None) -> Iterator[tuple[Connection, int, bytes]]:
    """(connection, timestamp ns, CDR bytes) of `connections`, in time order.

    Like rosbags' `reader.messages()`, except that a storage file's topic is matched to
    the metadata's by name and type only, as rosbag2 does. rosbags also demands equal
    offered-QoS text: rosbag2's own talker test bags (metadata version 4, mcap and
    sqlite3) list deadline 0 in metadata.yaml and infinite in the storage, so rosbags
    yielded 0 of their 20 messages (and the kit played none).
    """
    import heapq

    storages = getattr(reader.storage, 'storages', None)
    if storages is None:  # a single .mcap/.db3 file: no metadata.yaml to disagree with
        yield from reader.messages(connections=connections, start=start, stop=stop)
        return
    wanted = {(c.topic, c.msgtype): c for c in connections}
    decompress = _zstd_decompress() if reader.compression_mode == 'message' else None
    streams = []
    for storage in storages:
        mine = [c for c in storage.connections if (c.topic, c.msgtype) in wanted]
        if mine:
            streams.append(storage.messages(mine, start, stop))
    # Split files are in time order one after the other; merging also copes with overlap.
    for conn, stamp, data in heapq.merge(*streams, key=lambda item: item[1]):
        yield (wanted[(conn.topic, conn.msgtype)], stamp,
               decompress(data) if decompress is not None else data)


def _zstd_decompress() -> Callable[[bytes], bytes]:
    """zstd.decompress as rosbags imports it (the stdlib's from 3.14, else the backport)."""
    import importlib

    try:
        module = importlib.import_module('compression.zstd')
    except ImportError:
        module = importlib.import_module('backports.zstd')
    decompress: Callable[[bytes], bytes] = module.decompress
    return decompress


def decode(msgtype: str, data: bytes, bag: Path | str = '', topic: str = '') -> Any:
    """CDR bytes from a bag -> the rclpy message (this environment's generated class)."""
    from rclpy.serialization import deserialize_message

    return deserialize_message(data, message_class_for(msgtype, bag, topic))


def message_class_for(msgtype: str, bag: Path | str = '', topic: str = '') -> Any:
    """The message class of a bag's topic type; unknown types name the package to build."""
    from robot_lab.messages import message_class

    try:
        return message_class(msgtype)
    except GraphError:
        package = msgtype.split('/')[0]
        raise BagError(
            f"Topic '{topic}' in bag '{bag}' has message type '{msgtype}', which is not "
            'known in this environment',
            fix=f"build and source the package '{package}' that defines it "
            '(`robot-lab build`), or leave the topic out (--topics)',
        ) from None


@dataclass
class TopicColumns:
    """One topic of a bag as columns: receive times and one list per field path.

    `t` is seconds since the bag's first message (what a plot's x axis wants);
    `stamps_ns` are the recorded receive times (ns since the epoch).
    """

    topic: str
    type: str
    t: list[float] = field(default_factory=list)
    stamps_ns: list[int] = field(default_factory=list)
    columns: dict[str, list[Any]] = field(default_factory=dict)

    def __getitem__(self, name: str) -> list[Any]:
        if name in ('t', 'time'):
            return self.t
        return self.columns[name]

    def __len__(self) -> int:
        return len(self.t)


def read_topic(
    bag: str | Path, topic: str, fields: Sequence[str] | str = ('data',)
) -> TopicColumns:
    """Read one topic of a bag into columns for plotting, e.g. temperature over time.

    Field paths are those of robot_lab.messages.field_value / robot_lab.plot
    (`data`, `linear.x`, `linear/x`).
    """
    from robot_lab.messages import field_value

    paths = [fields] if isinstance(fields, str) else list(fields)
    name = topic if topic.startswith('/') else '/' + topic
    with open_bag(bag) as reader:
        conns = [c for c in reader.connections if c.topic == name]
        if not conns:
            have = ', '.join(sorted({c.topic for c in reader.connections})) or 'none'
            raise BagError(
                f"Topic '{name}' is not in bag '{bag}'", fix=f'topics in this bag: {have}'
            )
        msgtype = conns[0].msgtype
        cls = message_class_for(msgtype, bag, name)
        from rclpy.serialization import deserialize_message

        start = reader.start_time
        out = TopicColumns(name, msgtype, columns={p: [] for p in paths})
        for _conn, stamp, data in bag_messages(reader, conns):
            msg = deserialize_message(bytes(data), cls)
            out.stamps_ns.append(stamp)
            out.t.append((stamp - start) / 1e9)
            for p in paths:
                try:
                    out.columns[p].append(field_value(msg, p))
                except GraphError as exc:
                    raise BagError(exc.message, fix=exc.fix) from None
        return out
