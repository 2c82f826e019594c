"""Which QoS a played-back topic offers: rosbag2's rule, and `--qos-profile-overrides-path`.

rosbag2 (rosbag2_transport's player, rosbag2_storage's `adapt_offer_to_recorded_offers`)
picks, per topic: the user's override if the overrides file names the topic; else, if every
recorded publisher offered the same compatibility policies (reliability, durability,
deadline, liveliness, lease duration), that profile with the default history (keep last
10); else (mixed offers, or none recorded) the rosbag2 default, reliable + volatile. So a
bag recorded from a transient-local map publisher plays transient-local (a late
subscriber still gets the map), and one recorded from a best-effort sensor plays
best-effort, just as the original publisher did.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import BagError

if TYPE_CHECKING:
    from rclpy.qos import QoSProfile

__all__ = ['DEEP_HISTORY', 'DEFAULT_DEPTH', 'adapt_offer', 'deep_history', 'load_overrides',
           'profile_from_recorded', 'publisher_qos']

DEFAULT_DEPTH = 10  # rmw_qos_profile_default.depth: rosbag2's Rosbag2QoS() and default_history()
# Reliable volatile topics: the player's history up to this deep (a subscriber may fall this
# far behind before the player waits for it). Waiting for acknowledgements alone costs up
# to a heartbeat period per wait: bench_bag measured the split test bag under load taking
# more than 300 s with depth 10.
DEEP_HISTORY = 1000
_INFINITE_NS = 2**63 - 1
# What Foxy-era rmw implementations wrote for "infinite"; rosbag2 reads them as infinite.
_FOXY_INFINITE = {(0x7FFFFFFF, 0xFFFFFFFF), (0x7FFFFFFF, 0x7FFFFFFF),
                  (0x7FFFFFFFFFFFFFFF // 1_000_000_000, 0x7FFFFFFFFFFFFFFF % 1_000_000_000)}
_DURATIONS = ('deadline', 'lifespan', 'liveliness_lease_duration')
_POLICIES = ('history', 'reliability', 'durability', 'liveliness')
_VALUES = ('depth', 'avoid_ros_namespace_conventions')


def _get(profile: object, key: str) -> Any:
    return profile.get(key) if isinstance(profile, Mapping) else getattr(profile, key, None)


def _duration_ns(value: object) -> int:
    """A recorded duration ({sec, nsec} or rosbags QosTime) in ns; infinite stays infinite."""
    if value is None:
        return 0
    sec, nsec = int(_get(value, 'sec') or 0), int(_get(value, 'nsec') or 0)
    if (sec, nsec) in _FOXY_INFINITE:
        return _INFINITE_NS
    return min(_INFINITE_NS, sec * 1_000_000_000 + nsec)


def _policy(kind: Any, value: Any) -> Any:
    """A recorded policy (v9 name, v<9 integer, or a rosbags enum) -> the rclpy enum."""
    if value is None:
        return kind.SYSTEM_DEFAULT
    name = getattr(value, 'name', None)
    if isinstance(name, str):
        value = name
    if isinstance(value, str):
        try:
            return kind.get_from_short_key(value.lower())
        except KeyError:
            return kind.UNKNOWN
    try:
        return kind(int(value))
    except ValueError:
        return kind.UNKNOWN


def profile_from_recorded(profile: object) -> QoSProfile:
    """One offered profile from a bag's metadata (dict or rosbags Qos) -> rclpy QoSProfile."""
    from rclpy.duration import Duration
    from rclpy.qos import (
        DurabilityPolicy,
        HistoryPolicy,
        LivelinessPolicy,
        QoSProfile,
        ReliabilityPolicy,
    )

    return QoSProfile(
        history=_policy(HistoryPolicy, _get(profile, 'history')),
        depth=int(_get(profile, 'depth') or 0),
        reliability=_policy(ReliabilityPolicy, _get(profile, 'reliability')),
        durability=_policy(DurabilityPolicy, _get(profile, 'durability')),
        deadline=Duration(nanoseconds=_duration_ns(_get(profile, 'deadline'))),
        lifespan=Duration(nanoseconds=_duration_ns(_get(profile, 'lifespan'))),
        liveliness=_policy(LivelinessPolicy, _get(profile, 'liveliness')),
        liveliness_lease_duration=Duration(
            nanoseconds=_duration_ns(_get(profile, 'liveliness_lease_duration'))
        ),
        avoid_ros_namespace_conventions=bool(_get(profile, 'avoid_ros_namespace_conventions')),
    )


def _rosbag2_default() -> QoSProfile:
    from rclpy.qos import QoSProfile

    return QoSProfile(depth=DEFAULT_DEPTH)  # reliable, volatile, keep last 10


def _compatibility(profile: QoSProfile) -> tuple[object, ...]:
    # History and lifespan are local to the publisher: rosbag2 leaves them out of the check.
    return (
        profile.reliability, profile.durability, profile.deadline.nanoseconds,
        profile.liveliness, profile.liveliness_lease_duration.nanoseconds,
    )


def adapt_offer(topic: str, recorded: Sequence[object],
                warn: Callable[[str], None] | None = None) -> QoSProfile:
    """rosbag2's `adapt_offer_to_recorded_offers`: the rclpy QoSProfile to publish with."""
    from rclpy.qos import HistoryPolicy

    if not recorded:
        return _rosbag2_default()
    profiles = [profile_from_recorded(p) for p in recorded]
    if all(_compatibility(p) == _compatibility(profiles[0]) for p in profiles[1:]):
        chosen = profiles[0]
        chosen.history = HistoryPolicy.KEEP_LAST
        chosen.depth = DEFAULT_DEPTH
        return chosen
    if warn is not None:
        warn(f'Not all original publishers on topic {topic} offered the same QoS profiles. '
             'Rosbag2 cannot yet choose an adapted profile to offer for this mixed case. '
             'Falling back to the rosbag2_storage default publisher offer.')
    return _rosbag2_default()


def publisher_qos(topic: str, recorded: Sequence[object], overrides: Mapping[str, QoSProfile],
                  log: Callable[[str, str], None] | None = None) -> QoSProfile:
    """rosbag2's `publisher_qos_for_topic`: the override, else the adapted recorded offer."""
    if topic in overrides:
        if log is not None:
            log('INFO', f'Overriding QoS profile for topic {topic}')
        return overrides[topic]
    return adapt_offer(topic, recorded, None if log is None else lambda t: log('WARN', t))


def _override(path: Path, topic: str, entry: object) -> QoSProfile:
    """One topic's profile from an overrides file, checked as ros2bag checks it."""
    from rclpy.duration import Duration
    from rclpy.qos import (
        DurabilityPolicy,
        HistoryPolicy,
        LivelinessPolicy,
        QoSProfile,
        ReliabilityPolicy,
    )

    kinds = {'history': HistoryPolicy, 'reliability': ReliabilityPolicy,
             'durability': DurabilityPolicy, 'liveliness': LivelinessPolicy}
    where = f"'{path}', topic '{topic}'"
    if not isinstance(entry, Mapping):
        raise BagError(f'{where}: expected a map of QoS policies, got {entry!r}',
                       fix='e.g. "/chatter: {reliability: best_effort, durability: volatile}"')
    fields: dict[str, Any] = {}
    for key, value in entry.items():
        if key in _DURATIONS:
            if not isinstance(value, Mapping) or 'sec' not in value or 'nsec' not in value:
                raise BagError(
                    f'{where}: Time overrides must include both seconds (sec) and '
                    f'nanoseconds (nsec). ({key})', fix=f'{key}: {{sec: 0, nsec: 0}}')
            ns = int(value['sec']) * 1_000_000_000 + int(value['nsec'])
            if ns < 0:
                raise BagError(f'{where}: Time duration may not be a negative value. ({key})',
                               fix='use 0 or more')
            fields[key] = Duration(nanoseconds=_duration_ns(value))
        elif key in _POLICIES:
            try:
                fields[key] = kinds[key].get_from_short_key(str(value).lower())
            except KeyError:
                choices = ', '.join(m.name.lower() for m in kinds[key])
                raise BagError(f"{where}: '{value}' is not a valid {key}",
                               fix=f'use one of: {choices}') from None
        elif key in _VALUES:
            if key == 'depth' and (not isinstance(value, int) or value < 0):
                raise BagError(f'{where}: `depth` may not be a negative value.',
                               fix='depth: 10')
            fields[key] = value
        else:
            raise BagError(f'{where}: Unexpected key `{key}` for QoS profile.',
                           fix='keys: ' + ', '.join(_POLICIES + _VALUES + _DURATIONS))
    from rclpy.qos import InvalidQoSProfileException

    try:
        return QoSProfile(**fields)
    except InvalidQoSProfileException as exc:
        raise BagError(f'{where}: {exc.args[-1]}',
                       fix='add e.g. "history: keep_last" and "depth: 10"') from None


def load_overrides(path: str | Path) -> dict[str, QoSProfile]:
    """Read a `--qos-profile-overrides-path` file: {topic: {policy: value, ...}} -> profiles."""
    import yaml

    file = Path(path)
    try:
        doc = yaml.safe_load(file.read_text())
    except OSError as exc:
        raise BagError(f"Cannot read QoS overrides file '{file}': {exc.strerror}",
                       fix='give the path of an existing YAML file') from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, 'problem_mark', None)
        line = f', line {mark.line + 1}' if mark is not None else ''
        raise BagError(f"QoS overrides file '{file}'{line} is not valid YAML",
                       fix='fix the YAML syntax') from None
    if doc is None:
        return {}
    if not isinstance(doc, Mapping):
        raise BagError(f"QoS overrides file '{file}' must map topic names to profiles",
                       fix='e.g. "/chatter: {reliability: reliable, durability: volatile}"')
    return {str(topic): _override(file, str(topic), entry) for topic, entry in doc.items()}


def deep_history(offered: QoSProfile, messages: int) -> QoSProfile:
    """The player's profile for a topic of `messages` messages: what the recorded QoS
    offers, with a history deep enough (<= DEEP_HISTORY) that a reliable subscriber falling
    behind does not lose messages to overwriting. The depth is no part of QoS matching; a
    transient-local topic keeps its depth, since late joiners get the whole history (and
    so does an override: the user chose that depth)."""
    import copy

    from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

    if (offered.reliability != ReliabilityPolicy.RELIABLE
            or offered.history != HistoryPolicy.KEEP_LAST
            or offered.durability != DurabilityPolicy.VOLATILE):
        return offered
    profile = copy.copy(offered)
    profile.depth = max(offered.depth, min(messages, DEEP_HISTORY))
    return profile
