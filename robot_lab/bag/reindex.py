"""Recovering a bag whose recorder was killed: `ros2 bag reindex`, plus MCAP repair.

A SIGKILLed recorder leaves no metadata.yaml, and its MCAP file has no summary/footer
(and maybe half a record at the end). MCAP is a sequence of self-describing records, so
the file is read record by record up to the last complete one; every complete chunk's
messages are kept, the file is rewritten complete (sorted, indexed) and metadata.yaml
is rebuilt. A sqlite3 file keeps every committed transaction: only metadata.yaml is
rebuilt from its tables (sqlite rolls back the half-written transaction on open).
"""

from __future__ import annotations

import os
import shutil
import sqlite3
import struct
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robot_lab.bag.read import bag_files
from robot_lab.bag.writer import BagWriter, TopicSpec
from robot_lab.errors import BagError

__all__ = ['ReindexReport', 'reindex']

_MAGIC = b'\x89MCAP0\r\n'


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
    schemas: dict[int, tuple[str, str, str]] = field(default_factory=dict)  # id -> name, enc, data
    channels: dict[int, tuple[int, str, str, dict[str, str]]] = field(default_factory=dict)
    messages: list[tuple[int, int, bytes]] = field(default_factory=list)  # log time, channel, data
    good_end: int = 0


def _string(buf: bytes, pos: int) -> tuple[str, int]:
    (size,) = struct.unpack_from('<I', buf, pos)
    pos += 4
    return buf[pos:pos + size].decode(), pos + size


def _records(buf: bytes, pos: int, end: int, scan: _Scan, top: bool) -> None:
    """Parse records in buf[pos:end]; at top level remember where the last whole one ended."""
    while pos + 9 <= end:
        op = buf[pos]
        (size,) = struct.unpack_from('<Q', buf, pos + 1)
        body = pos + 9
        if body + size > end:
            return  # a record cut off by the kill
        rec = buf[body:body + size]
        if op == 0x02:  # footer: nothing after it
            if top:
                scan.good_end = body + size
            return
        try:
            _record(op, rec, scan)
        except (struct.error, UnicodeDecodeError, ValueError):
            return  # garbage from here on
        pos = body + size
        if top:
            scan.good_end = pos


def _record(op: int, rec: bytes, scan: _Scan) -> None:
    if op == 0x03:
        (sid,) = struct.unpack_from('<H', rec, 0)
        name, p = _string(rec, 2)
        encoding, p = _string(rec, p)
        (size,) = struct.unpack_from('<I', rec, p)
        scan.schemas[sid] = (name, encoding, rec[p + 4:p + 4 + size].decode())
    elif op == 0x04:
        cid, sid = struct.unpack_from('<HH', rec, 0)
        topic, p = _string(rec, 4)
        encoding, p = _string(rec, p)
        (size,) = struct.unpack_from('<I', rec, p)
        p += 4
        stop = p + size
        meta: dict[str, str] = {}
        while p < stop:
            key, p = _string(rec, p)
            meta[key], p = _string(rec, p)
        scan.channels[cid] = (sid, topic, encoding, meta)
    elif op == 0x05:
        cid, _seq, log_time, _pub = struct.unpack_from('<HIQQ', rec, 0)
        scan.messages.append((log_time, cid, rec[22:]))
    elif op == 0x06:
        _start, _end, _raw_size, _crc = struct.unpack_from('<QQQI', rec, 0)
        compression, p = _string(rec, 28)
        (size,) = struct.unpack_from('<Q', rec, p)
        data = rec[p + 8:p + 8 + size]
        if compression == 'zstd':
            from rosbags.rosbag2 import storage_mcap

            data = storage_mcap.zstd.decompress(data)  # type: ignore[attr-defined]
        elif compression:
            raise BagError(
                f"MCAP chunk compression '{compression}' cannot be recovered here",
                fix='re-record without compression',
            )
        _records(data, 0, len(data), scan, top=False)


def _scan_mcap(path: Path) -> _Scan:
    buf = path.read_bytes()
    if not buf.startswith(_MAGIC):
        raise BagError(
            f"'{path}' is not an MCAP file (no MCAP magic at its start)",
            fix='reindex needs the .mcap file that `bag record` was writing',
        )
    scan = _Scan(good_end=len(_MAGIC))
    _records(buf, len(_MAGIC), len(buf), scan, top=True)
    scan.good_end = len(buf) - scan.good_end
    return scan


def _reindex_mcap(folder: Path, file: Path) -> ReindexReport:
    from rosbags.rosbag2.metadata import parse_qos

    scan = _scan_mcap(file)
    report = ReindexReport(folder, 'mcap', truncated_bytes=scan.good_end)
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        staging = Path(tmp) / folder.name
        writer = BagWriter(staging, 'mcap')
        conns: dict[int, Any] = {}
        for cid, (sid, topic, encoding, meta) in sorted(scan.channels.items()):
            name, _enc, text = scan.schemas.get(sid, ('', '', ''))
            if not name:
                continue
            spec = TopicSpec(
                name=topic, type=name,
                offered_qos_profiles=parse_qos(meta.get('offered_qos_profiles', '')),
                type_description_hash=meta.get('topic_type_hash', ''),
                serialization_format=encoding or 'cdr',
                message_definition=text,
            )
            conns[cid] = writer.add_topic(spec)
            report.counts.setdefault(topic, 0)
        for stamp, cid, data in sorted(scan.messages, key=lambda m: m[0]):
            conn = conns.get(cid)
            if conn is None:
                continue
            writer.write(conn, stamp, data)
            report.counts[conn.topic] += 1
        writer.close()
        produced = staging / f'{folder.name}_0.mcap'  # BagWriter names it as rosbag2 does
        os.replace(produced, file)
        meta_doc = yaml.safe_load((staging / 'metadata.yaml').read_text())
        info = meta_doc['rosbag2_bagfile_information']
        info['relative_file_paths'] = [file.name]
        for entry in info.get('files') or []:
            entry['path'] = file.name
        _write_metadata(folder, meta_doc)
        shutil.rmtree(staging, ignore_errors=True)
    return report


def _reindex_sqlite(folder: Path, file: Path) -> ReindexReport:
    report = ReindexReport(folder, 'sqlite3')
    try:
        db = sqlite3.connect(str(file))
        try:
            topics = db.execute(
                'SELECT id, name, type, serialization_format, offered_qos_profiles, '
                'type_description_hash FROM topics ORDER BY id'
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
    entries = []
    first, last = 2**63 - 1, 0
    for tid, name, mtype, fmt, qos_text, type_hash in topics:
        count, lo, hi = stats.get(tid, (0, None, None))
        report.counts[name] = int(count)
        if lo is not None:
            first, last = min(first, lo), max(last, hi)
        entries.append({
            'topic_metadata': {
                'name': name,
                'type': mtype,
                'serialization_format': fmt,
                'offered_qos_profiles': yaml.safe_load(qos_text) if qos_text else [],
                'type_description_hash': type_hash or '',
            },
            'message_count': int(count),
        })
    total = report.message_count
    start = first if total else 0
    duration = last - first if total else 0
    doc = {
        'rosbag2_bagfile_information': {
            'version': 9,
            'storage_identifier': 'sqlite3',
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': total,
            'topics_with_message_count': entries,
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [file.name],
            'files': [{
                'path': file.name,
                'starting_time': {'nanoseconds_since_epoch': start},
                'duration': {'nanoseconds': duration},
                'message_count': total,
            }],
            'custom_data': None,
            'ros_distro': 'jazzy',
        }
    }
    _write_metadata(folder, doc)
    return report


def _write_metadata(folder: Path, doc: dict[str, Any]) -> None:
    tmp = folder / 'metadata.yaml.tmp'
    tmp.write_text(yaml.safe_dump(doc, sort_keys=False, default_flow_style=False))
    os.replace(tmp, folder / 'metadata.yaml')


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
    if len(files) > 1:
        raise BagError(
            f"'{folder}' holds {len(files)} storage files; split bags are not supported here",
            fix='move the extra files out, one bag per folder',
        )
    file = files[0]
    if file.suffix == '.mcap':
        return _reindex_mcap(folder, file)
    return _reindex_sqlite(folder, file)
