"""Which topics and services a bag takes (recording) or publishes (playback), as rosbag2.

Topics and services (their `_service_event` topics) are filtered apart: `--topics` names
topics to play, `--services` services; `--exclude-topics`/`--exclude-services` leave some
out; `--regex` and `--exclude-regex` match whole names (std::regex_match), for both. An
unset list selects everything of its kind, as rosbag2_transport's allow_topic decides.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from robot_lab.bag.services import event_topic, is_service_event, service_name
from robot_lab.errors import BagError

__all__ = ['RecordFilter', 'Selection']


def _absolute(names: Iterable[str] | None) -> list[str] | None:
    return None if names is None else [n if n.startswith('/') else '/' + n for n in names]


def _compiled(pattern: str, option: str) -> re.Pattern[str] | None:
    if not pattern:
        return None
    try:
        return re.compile(pattern)
    except re.error as exc:
        raise BagError(f"Invalid regular expression for {option}: '{pattern}' ({exc})",
                       fix=f'quote it in the shell, e.g. {option} "/sensor/.*"') from None


@dataclass(frozen=True)
class Selection:
    """The play filter; `allows(topic, type)` says whether a recorded topic plays."""

    topics: list[str] | None = None  # None: every topic
    services: list[str] | None = None  # service *event* topics; None: every service
    exclude_topics: frozenset[str] = field(default_factory=frozenset)
    exclude_services: frozenset[str] = field(default_factory=frozenset)
    regex: re.Pattern[str] | None = None
    exclude_regex: re.Pattern[str] | None = None

    @classmethod
    def of(cls, topics: Iterable[str] | None = None, services: Iterable[str] | None = None,
           exclude_topics: Iterable[str] = (), exclude_services: Iterable[str] = (),
           regex: str = '', exclude_regex: str = '') -> Selection:
        return cls(
            topics=_absolute(topics),
            services=None if services is None else [event_topic(s) for s in services],
            exclude_topics=frozenset(_absolute(exclude_topics) or ()),
            exclude_services=frozenset(event_topic(s) for s in exclude_services),
            regex=_compiled(regex, '--regex'),
            exclude_regex=_compiled(exclude_regex, '--exclude-regex'),
        )

    def allows(self, topic: str, msgtype: str) -> bool:
        service = is_service_event(topic, msgtype)
        if topic in (self.exclude_services if service else self.exclude_topics):
            return False
        if self.exclude_regex is not None and self.exclude_regex.fullmatch(topic):
            return False
        include = self.services if service else self.topics  # empty counts as unset
        if not include and self.regex is None:
            return True
        if include and topic in include:
            return True
        return self.regex is not None and self.regex.fullmatch(topic) is not None


def _hidden(topic: str) -> bool:
    return any(part.startswith('_') for part in topic.split('/'))


@dataclass(frozen=True)
class RecordFilter:
    """Which discovered topics a recording takes: rosbag2_transport's TopicFilter.

    Regular expressions *search* here (`-e sensor` takes /sensor/temperature), unlike
    play's; `all_topics` overrides the lists; hidden topics need `include_hidden`, even
    when listed; service event topics are selected by the service options only.
    """

    topics: frozenset[str] = frozenset()
    services: frozenset[str] = frozenset()  # service event topics
    topic_types: frozenset[str] = frozenset()
    all_topics: bool = False
    all_services: bool = False
    regex: re.Pattern[str] | None = None
    exclude_regex: re.Pattern[str] | None = None
    exclude_topic_types: frozenset[str] = frozenset()
    exclude_topics: frozenset[str] = frozenset()
    exclude_services: frozenset[str] = frozenset()
    include_hidden: bool = False

    @classmethod
    def of(cls, topics: Iterable[str] = (), services: Iterable[str] = (),
           topic_types: Iterable[str] = (), all_topics: bool = False,
           all_services: bool = False, regex: str = '', exclude_regex: str = '',
           exclude_topic_types: Iterable[str] = (), exclude_topics: Iterable[str] = (),
           exclude_services: Iterable[str] = (), include_hidden: bool = False) -> RecordFilter:
        return cls(frozenset(_absolute(topics) or ()),
                   frozenset(event_topic(s) for s in services), frozenset(topic_types),
                   all_topics, all_services, _compiled(regex, '--regex'),
                   _compiled(exclude_regex, '--exclude-regex'),
                   frozenset(exclude_topic_types), frozenset(_absolute(exclude_topics) or ()),
                   frozenset(event_topic(s) for s in exclude_services), include_hidden)

    @property
    def open_ended(self) -> bool:
        """New topics may match at any time (not only a fixed list of names)."""
        return bool(self.all_topics or self.all_services or self.topic_types or self.regex)

    def hidden_listed(self) -> list[str]:
        """Listed hidden topics that are not recorded without `include_hidden`."""
        return [] if self.include_hidden else sorted(t for t in self.topics if _hidden(t))

    def takes(self, topic: str, msgtype: str) -> bool:
        if is_service_event(topic, msgtype):
            name = service_name(topic)
            if not self.all_services and topic not in self.services and not (
                    self.regex is not None and self.regex.search(name)):
                return False
            return topic not in self.exclude_services and not (
                self.exclude_regex is not None and self.exclude_regex.search(name))
        if not self.all_topics and topic not in self.topics \
                and msgtype not in self.topic_types \
                and not (self.regex is not None and self.regex.search(topic)):
            return False
        if msgtype in self.exclude_topic_types or topic in self.exclude_topics:
            return False
        if self.exclude_regex is not None and self.exclude_regex.search(topic):
            return False
        return self.include_hidden or not _hidden(topic)
