"""Which recorded topics and services a playback publishes: rosbag2's play filter.

Topics and services (their `_service_event` topics) are filtered apart: `--topics` names
topics to play, `--services` services; `--exclude-topics`/`--exclude-services` leave some
out; `--regex` and `--exclude-regex` match whole names (std::regex_match), for both. An
unset list selects everything of its kind, as rosbag2_transport's allow_topic decides.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from robot_lab.bag.services import event_topic, is_service_event
from robot_lab.errors import BagError

__all__ = ['Selection']


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
