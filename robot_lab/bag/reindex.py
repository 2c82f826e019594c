"""Recovering a bag whose recorder was killed: `ros2 bag reindex`, plus MCAP repair.

A SIGKILLed recorder leaves no metadata.yaml, and its MCAP file has no summary/footer
(and maybe half a record at the end). Each .mcap file of the bag (one, or a split bag's
`<bag>_0.mcap`, `<bag>_1.mcap`, …) is read with the `mcap` library: a complete file through
its summary, an unfinished one with the non-seeking stream reader up to its last complete
record; an unfinished file is rewritten complete (sorted, indexed). A sqlite3 file keeps
every committed transaction (sqlite rolls back the half-written one on open). metadata.yaml
is then rebuilt from all files, in rosbag2's order.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import sqlite3
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robot_lab.bag.read import bag_files
from robot_lab.bag.writer import BagWriter, TopicSpec, write_metadata
from robot_lab.errors import BagError

__all__ = ['ReindexReport', 'reindex']


@dataclass
class ReindexReport:
    """What reindex found: messages recovered per topic, and bytes that were cut off."""

    path: Path
    storage_id: str
    counts: dict[str, int] = field(default_factory=dict)
    truncated_bytes: int = 0

    @property
    def message_count(self) -> int:
        return sum(self.counts.values())


@dataclass
class _Scan:
    """One storage file's topics (in file order), messages per file, and what was cut off."""

    specs: list[TopicSpec] = field(default_factory=list)
    messages: list[tuple[int, str, bytes]] = field(default_factory=list)  # time, topic, data
    complete: bool = True
    truncated_bytes: int = 0
    ros_distro: str = ''  # from the file's `rosbag2` metadata record, as rosbag2 reads it
    per_topic: dict[str, tuple[int, int, int]] | None = None  # from the summary: count, times


def _spec(topic: str, schema: Any, encoding: str, meta: dict[str, str]) -> TopicSpec:
    from rosbags.rosbag2.metadata import parse_qos

    return TopicSpec(
        name=topic, type=schema.name,
        offered_qos_profiles=parse_qos(meta.get('offered_qos_profiles', '')),
        type_description_hash=meta.get('topic_type_hash', ''),
        serialization_format=encoding or 'cdr',
        message_definition=schema.data.decode(errors='replace'),
    )


def _from_summary(f: Any, summary: Any, scan: _Scan) -> None:
    """A complete file: topics, counts and times from its summary, without reading data."""
    from mcap.reader import make_reader

    stats = summary.statistics
    counts = stats.channel_message_counts
    scan.per_topic = {}
    for cid, channel in sorted(summary.channels.items()):
        schema = summary.schemas.get(channel.schema_id)
        if schema is None:
            continue
        if channel.topic not in scan.per_topic:
            scan.specs.append(_spec(channel.topic, schema, channel.message_encoding,
                                    dict(channel.metadata)))
            scan.per_topic[channel.topic] = (0, stats.message_start_time,
                                             stats.message_end_time)
        count, lo, hi = scan.per_topic[channel.topic]
        scan.per_topic[channel.topic] = (count + int(counts.get(cid, 0)), lo, hi)
    f.seek(0)
    for record in make_reader(f).iter_metadata():
        if record.name == 'rosbag2':
            with contextlib.suppress(yaml.YAMLError, AttributeError):
                meta = yaml.safe_load(record.metadata.get('serialized_metadata', ''))
                scan.ros_distro = str(meta.get('ros_distro') or '')


def _scan_mcap(path: Path) -> _Scan:
    """Read a .mcap file with the mcap library; an unfinished one up to its last record."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap.records import Channel, Message, Metadata, Schema
    from mcap.stream_reader import StreamReader

    scan = _Scan()
    size = path.stat().st_size
    with path.open('rb') as f:
        magic = f.read(8)
        if b'\x89MCAP0\r\n'.startswith(magic) and size < 64:
            # Killed just after a split opened the file: nothing of it reached the disk.
            return _Scan(complete=False, truncated_bytes=size)
        if magic != b'\x89MCAP0\r\n':
            raise BagError(
                f"'{path}' is not an MCAP file (no MCAP magic at its start)",
                fix='reindex needs the .mcap file that `bag record` was writing',
            )
        f.seek(0)
        try:
            summary = make_reader(f).get_summary()
        except Exception:  # no footer, or a summary cut short: read it as a stream
            summary = None
        scan.complete = summary is not None
        if summary is not None and summary.statistics is not None:
            _from_summary(f, summary, scan)
            return scan
        f.seek(0)
        schemas: dict[int, Any] = {}
        topics: dict[int, str] = {}
        good_end = 8
        try:
            for record in StreamReader(f).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    schema = schemas.get(record.schema_id)
                    if schema is None or record.id in topics:
                        continue
                    topics[record.id] = record.topic
                    if record.topic not in {s.name for s in scan.specs}:
                        scan.specs.append(
                            _spec(record.topic, schema, record.message_encoding,
                                  dict(record.metadata)))
                elif isinstance(record, Metadata) and record.name == 'rosbag2':
                    with contextlib.suppress(yaml.YAMLError, AttributeError):
                        meta = yaml.safe_load(record.metadata.get('serialized_metadata', ''))
                        scan.ros_distro = str(meta.get('ros_distro') or '')
                elif isinstance(record, Message) and record.channel_id in topics:
                    scan.messages.append(
                        (record.log_time, topics[record.channel_id], bytes(record.data)))
                good_end = f.tell()
        except (McapError, EOFError, ValueError, OSError) as exc:
            if scan.complete:
                raise BagError(f"'{path}' cannot be read: {exc}",
                               fix='the file is damaged; record the bag again') from None
        except Exception:  # a record cut off by the kill: keep what came before it
            pass
    scan.truncated_bytes = 0 if scan.complete else max(0, size - good_end)
    return scan


def _rewrite_mcap(folder: Path, file: Path, scan: _Scan) -> None:
    """Write an unfinished file's messages again as a complete, indexed .mcap file."""
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        staging = Path(tmp) / folder.name
        writer = BagWriter(staging, 'mcap')
        for spec in scan.specs:
            writer.add_topic(TopicSpec(**vars(spec)))
        for stamp, topic, data in sorted(scan.messages, key=lambda m: m[0]):
            writer.write(writer.connections[topic], stamp, data)
        writer.close()
        os.replace(staging / f'{folder.name}_0.mcap', file)
        shutil.rmtree(staging, ignore_errors=True)


def _scan_sqlite(file: Path) -> tuple[list[TopicSpec], dict[str, tuple[int, int, int]], str]:
    """Topics of a .db3 file, (count, first, last) per topic, and its ros_distro."""
    try:
        db = sqlite3.connect(str(file))
        try:
            distro = ''
            with contextlib.suppress(sqlite3.Error):  # no schema table before Humble
                row = db.execute('SELECT ros_distro FROM schema').fetchone()
                distro = str(row[0] or '') if row else ''
            # Older rosbag2 schemas lack type_description_hash (Humble) or even
            # offered_qos_profiles (Foxy and before): read what the file has.
            have = {row[1] for row in db.execute('PRAGMA table_info(topics)')}
            optional = [c if c in have else "''" for c in
                        ('offered_qos_profiles', 'type_description_hash')]
            topics = db.execute(
                'SELECT id, name, type, serialization_format, '
                f'{optional[0]}, {optional[1]} FROM topics ORDER BY id'
            ).fetchall()
            stats = {
                row[0]: row[1:]
                for row in db.execute(
                    'SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp) '
                    'FROM messages GROUP BY topic_id'
                )
            }
        finally:
            db.close()
    except sqlite3.Error as exc:
        raise BagError(
            f"'{file}' is not a readable rosbag2 sqlite3 database ({exc})",
            fix='reindex needs the .db3 file that `bag record -s sqlite3` was writing',
        ) from None
    specs, counts = [], {}
    for tid, name, mtype, fmt, qos_text, type_hash in topics:
        count, lo, hi = stats.get(tid, (0, 0, 0))
        specs.append(TopicSpec(name=name, type=mtype,
                               offered_qos_profiles=yaml.safe_load(qos_text) if qos_text else [],
                               type_description_hash=type_hash or '',
                               serialization_format=fmt or 'cdr', message_definition=''))
        counts[name] = (int(count), int(lo or 0), int(hi or 0))
    return specs, counts, distro


def _file_number(path: Path) -> tuple[int, str]:
    match = re.search(r'_(\d+)$', path.stem)
    return (int(match.group(1)) if match else -1, path.name)


def reindex(bag: str | Path) -> ReindexReport:
    """Rebuild metadata.yaml (and repair an unfinished .mcap) of a bag folder."""
    folder = Path(bag)
    if not folder.is_dir():
        raise BagError(
            f"'{folder}' is not a directory: Must specify a bag directory",
            fix='give the folder that holds the .mcap/.db3 file',
        )
    files = bag_files(folder)
    if not files:
        raise BagError(
            f"'{folder}' holds no .mcap or .db3 file: nothing to reindex",
            fix='give the folder `robot-lab bag record` was writing',
        )
    kinds = {f.suffix for f in files}
    if len(kinds) > 1:
        raise BagError(
            f"'{folder}' holds both .mcap and .db3 files: one bag has one storage kind",
            fix='move the files of the other bag out, one bag per folder',
        )
    files.sort(key=_file_number)  # <bag>_0, <bag>_1, …, <bag>_10 in number order
    storage = 'mcap' if files[0].suffix == '.mcap' else 'sqlite3'
    report = ReindexReport(folder, storage)
    specs: dict[str, TopicSpec] = {}
    entries: list[dict[str, Any]] = []
    distro, latest = '', -1  # rosbag2: the distro of the file that starts last
    for leftover in folder.glob(f'.{folder.name}_*.part'):  # a split's staging, if killed
        shutil.rmtree(leftover, ignore_errors=True)
    for file in files:
        per_topic: dict[str, tuple[int, int, int]] = {}
        if storage == 'mcap':
            scan = _scan_mcap(file)
            if not scan.complete:
                _rewrite_mcap(folder, file, scan)
                report.truncated_bytes += scan.truncated_bytes
            file_specs, file_distro = scan.specs, scan.ros_distro
            per_topic = dict(scan.per_topic or {})
            for stamp, topic, _data in scan.messages:
                count, lo, hi = per_topic.get(topic, (0, stamp, stamp))
                per_topic[topic] = (count + 1, min(lo, stamp), max(hi, stamp))
        else:
            file_specs, per_topic, file_distro = _scan_sqlite(file)
        for spec in file_specs:
            specs.setdefault(spec.name, spec)
            report.counts.setdefault(spec.name, 0)
        live = [v for v in per_topic.values() if v[0]]
        for topic, (count, _lo, _hi) in per_topic.items():
            report.counts[topic] = report.counts.get(topic, 0) + count
        entries.append({'path': file.name, 'count': sum(v[0] for v in live),
                        'start': min((v[1] for v in live), default=None),
                        'end': max((v[2] for v in live), default=0)})
        if file_distro and (entries[-1]['start'] or 0) > latest:
            distro, latest = file_distro, entries[-1]['start'] or 0
    write_metadata(folder, storage, list(specs.values()), report.counts, entries, distro)
    return report
