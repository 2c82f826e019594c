"""A pytest plugin that makes a student's node wrong on purpose, for `check.tests_catch`.

`python -m pytest -p robot_lab.grading.check.wrong_node …` with ROBOT_LAB_WRONG_NODE set
to `{"node": "module:Class", "topic": "/cmd_vel", "message": {...}}`: every instance of
that node class answers each message it receives with that one fixed message on `topic`,
whatever the message said. The student's tests then run against a node that ignores its
input; tests that still pass cannot tell a right node from a wrong one.
"""

from __future__ import annotations

import importlib
import json
import os
from typing import Any

import pytest

ENV = 'ROBOT_LAB_WRONG_NODE'


def _make_wrong(cls: Any, topic: str, values: dict[str, Any]) -> None:
    from robot_lab.messages import message_from_yaml

    original_init = cls.__init__

    def wrong_init(self: Any, *args: Any, **kwargs: Any) -> None:
        original_init(self, *args, **kwargs)
        publishers = [p for p in self.publishers if p.topic_name == topic]
        if not publishers:
            return  # nothing to answer on: the student's own tests will say so

        def answer(_msg: Any, publisher: Any = publishers[0]) -> None:
            # looked up at call time: a test may have replaced `publish` to catch it
            publisher.publish(message_from_yaml(publisher.msg_type, values))

        for subscription in self.subscriptions:
            subscription.callback = answer

    cls.__init__ = wrong_init


@pytest.hookimpl(tryfirst=True)
def pytest_configure(config: pytest.Config) -> None:
    spec = os.environ.get(ENV)
    if not spec:
        return
    wrong = json.loads(spec)
    module, _, name = str(wrong['node']).partition(':')
    _make_wrong(getattr(importlib.import_module(module), name), str(wrong['topic']),
                dict(wrong['message']))
