"""tf2_ros's Buffer: the BufferCore plus ROS time, waits and the `tf2_frames` service
(tf2_ros_py/tf2_ros/buffer.py and buffer_interface.py, with their signatures).

A lookup with a timeout waits on the caller's thread, as upstream's does (so a node's own
executor thread must not be the one waiting: the listener's callbacks run in a reentrant
group, or the tutorials' timer would block them). Upstream re-checks every 20 ms; here the
wait is on a condition each new transform notifies, so an answer comes as soon as the data
does and a long wait costs no CPU. The timeout is still measured on the system clock, and a
jump back of over 3 s (a bag looping) still ends it. `wait_for_transform_async` resolves a
Future when new data makes the transform possible.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from copy import deepcopy
from typing import Any, ClassVar

from rclpy.clock import Clock, JumpThreshold
from rclpy.duration import Duration
from rclpy.logging import get_logger
from rclpy.task import Future

from robot_lab.tf2.buffer_core import BufferCore

# Upstream's default timeout, `Duration()`: no wait.
NO_WAIT = Duration()

__all__ = [
    'Buffer',
    'BufferInterface',
    'ConvertRegistration',
    'NotImplementedException',
    'Stamped',
    'TransformRegistration',
    'TypeException',
    'convert',
]


class TypeException(Exception):  # noqa: N818 (upstream's name)
    """No transform function registered for a message type."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class NotImplementedException(Exception):  # noqa: N818 (upstream's name)
    def __init__(self) -> None:
        super().__init__('CanTransform or LookupTransform not implemented')
        self.errstr = 'CanTransform or LookupTransform not implemented'


class TransformRegistration:
    """message type -> do_transform function (tf2_geometry_msgs registers its own)."""

    _type_map: ClassVar[dict[Any, Callable[[Any, Any], Any]]] = {}

    def print_me(self) -> None:
        print(TransformRegistration._type_map)

    def add(self, key: Any, callback: Callable[[Any, Any], Any]) -> None:
        TransformRegistration._type_map[key] = callback

    def get(self, key: Any) -> Callable[[Any, Any], Any]:
        if key not in TransformRegistration._type_map:
            raise TypeException(f'Type {key} is not loaded or supported')
        return TransformRegistration._type_map[key]


class ConvertRegistration:
    _to_msg: ClassVar[dict[Any, Callable[[Any], Any]]] = {}
    _from_msg: ClassVar[dict[Any, Callable[[Any], Any]]] = {}
    _convert: ClassVar[dict[Any, Callable[[Any], Any]]] = {}

    def add_from_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._from_msg[key] = callback

    def add_to_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._to_msg[key] = callback

    def add_convert(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._convert[key] = callback

    @staticmethod
    def _get(table: dict[Any, Callable[[Any], Any]], key: Any) -> Callable[[Any], Any]:
        if key not in table:
            raise TypeException(f'Type {key} is not loaded or supported')
        return table[key]

    def get_from_msg(self, key: Any) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._from_msg, key)

    def get_to_msg(self, key: Any) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._to_msg, key)

    def get_convert(self, key: Any) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._convert, key)


def convert(a: Any, b_type: Any) -> Any:
    c = ConvertRegistration()
    try:
        return c.get_convert((type(a), b_type))(a)
    except TypeException:
        if type(a) is b_type:
            return deepcopy(a)
        return c.get_from_msg(b_type)(c.get_to_msg(type(a))(a))


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:  # noqa: N802 (upstream's name)
    from std_msgs.msg import Header
    obj.header = Header(frame_id=frame_id, stamp=stamp)
    return obj


class BufferInterface:
    """transform()/transform_full() over a subclass's lookups."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(self, object_stamped: Any, target_frame: str,
                  timeout: Duration = NO_WAIT, new_type: Any = None) -> Any:
        do_transform = self.registration.get(type(object_stamped))
        res = do_transform(object_stamped, self.lookup_transform(
            target_frame, object_stamped.header.frame_id, object_stamped.header.stamp,
            timeout))
        return res if new_type is None else convert(res, new_type)

    def transform_full(self, object_stamped: Any, target_frame: str, target_time: Any,
                       fixed_frame: str, timeout: Duration = NO_WAIT,
                       new_type: Any = None) -> Any:
        do_transform = self.registration.get(type(object_stamped))
        res = do_transform(object_stamped, self.lookup_transform_full(
            target_frame, target_time, object_stamped.header.frame_id,
            object_stamped.header.stamp, fixed_frame, timeout))
        return res if new_type is None else convert(res, new_type)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Duration = NO_WAIT) -> Any:
        raise NotImplementedException()

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str,
                              timeout: Duration = NO_WAIT) -> Any:
        raise NotImplementedException()

    def can_transform(self, target_frame: str, source_frame: str, time: Any,
                      timeout: Duration = NO_WAIT) -> Any:
        raise NotImplementedException()

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str,
                           timeout: Duration = NO_WAIT) -> Any:
        raise NotImplementedException()


class Buffer(BufferCore, BufferInterface):
    """tf2_ros.Buffer: `Buffer(cache_time=None, node=None)`; with a node, a `tf2_frames`
    service answers the frames as YAML, and a jump back in time clears the buffer."""

    def __init__(self, cache_time: Duration | None = None, node: Any = None) -> None:
        self._new_data = threading.Condition()  # notified for every transform set
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self._new_data_callbacks: list[Callable[[], None]] = []
        self._callbacks_to_remove: list[Callable[[], None]] = []
        self._callbacks_lock = threading.RLock()
        if node is not None:
            from tf2_msgs.srv import FrameGraph
            self.srv = node.create_service(FrameGraph, 'tf2_frames', self.__get_frames)
            self.clock = node.get_clock()
        else:
            self.clock = Clock()
        threshold = JumpThreshold(min_forward=None, min_backward=Duration(seconds=-1),
                                  on_clock_change=True)
        self.jump_handle = self.clock.create_jump_callback(
            threshold, post_callback=self.time_jump_callback)

    def __get_frames(self, req: Any, res: Any) -> Any:
        from tf2_msgs.srv import FrameGraph
        return FrameGraph.Response(frame_yaml=self.all_frames_as_yaml())

    def time_jump_callback(self, time_jump: Any) -> None:
        get_logger('tf2_buffer').warning(
            'Detected jump back in time. Clearing tf buffer.')
        self.clear()

    def set_transform(self, transform: Any, authority: str) -> None:
        super().set_transform(transform, authority)
        self._new_data_arrived()

    def set_transform_static(self, transform: Any, authority: str) -> None:
        super().set_transform_static(transform, authority)
        self._new_data_arrived()

    def _new_data_arrived(self) -> None:
        with self._new_data:
            self._new_data.notify_all()
        self._call_new_data_callbacks()

    def _wait_until(self, ready: Callable[[], bool], seconds_left: Callable[[], float]) -> None:
        """Until `ready()`, re-checked whenever a transform is set, or `seconds_left()` is
        no longer positive. `ready` runs under the condition's lock, so a transform set
        between a check and the wait still wakes it."""
        with self._new_data:
            while not ready():
                left = seconds_left()
                if left <= 0:
                    return
                self._new_data.wait(left)

    def _call_new_data_callbacks(self) -> None:
        if not self._new_data_callbacks:
            return
        with self._callbacks_lock:
            for callback in list(self._new_data_callbacks):
                callback()
            for callback in self._callbacks_to_remove:
                if callback in self._new_data_callbacks:
                    self._new_data_callbacks.remove(callback)
            self._callbacks_to_remove.clear()

    def _remove_callback(self, callback: Callable[[], None]) -> None:
        with self._callbacks_lock:
            self._callbacks_to_remove.append(callback)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Duration = NO_WAIT) -> Any:
        """The transform from `source_frame` to `target_frame` (time 0: the latest),
        waiting up to `timeout` for it."""
        self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    async def lookup_transform_async(self, target_frame: str, source_frame: str,
                                     time: Any) -> Any:
        await self.wait_for_transform_async(target_frame, source_frame, time)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str,
                              timeout: Duration = NO_WAIT) -> Any:
        """Time travel: source at `source_time`, target at `target_time`, through
        `fixed_frame`, which is taken as not moving."""
        self.can_transform_full(target_frame, target_time, source_frame, source_time,
                                fixed_frame, timeout)
        return self.lookup_transform_full_core(target_frame, target_time, source_frame,
                                               source_time, fixed_frame)

    async def lookup_transform_full_async(self, target_frame: str, target_time: Any,
                                          source_frame: str, source_time: Any,
                                          fixed_frame: str) -> Any:
        await self.wait_for_transform_full_async(target_frame, target_time, source_frame,
                                                 source_time, fixed_frame)
        return self.lookup_transform_full_core(target_frame, target_time, source_frame,
                                               source_time, fixed_frame)

    def _wait(self, check: Callable[[], tuple[int, str]], timeout: Duration) -> None:
        """Until `check()` succeeds or `timeout` passes on the system clock, as upstream's
        loop; a jump back of over 3 s ends it (upstream: big jumps are likely bag loops)."""
        if timeout == Duration():
            return
        clock = Clock()
        start = clock.now()
        end = start + timeout

        def seconds_left() -> float:
            now = clock.now()
            if now + Duration(seconds=3.0) < start:
                return 0.0
            return float((end - now).nanoseconds) / 1e9

        self._wait_until(lambda: bool(check()[0]), seconds_left)

    def can_transform(self, target_frame: str, source_frame: str, time: Any,
                      timeout: Duration = NO_WAIT, return_debug_tuple: bool = False) -> Any:
        """1 or 0 (upstream's ints), or (1|0, why) with `return_debug_tuple=True`."""
        def check() -> tuple[int, str]:
            return self.can_transform_core(target_frame, source_frame, time)
        self._wait(check, timeout)
        result = check()
        return result if return_debug_tuple else result[0]

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str, timeout: Duration = NO_WAIT,
                           return_debug_tuple: bool = False) -> Any:
        def check() -> tuple[int, str]:
            return self.can_transform_full_core(target_frame, target_time, source_frame,
                                                source_time, fixed_frame)
        self._wait(check, timeout)
        result = check()
        return result if return_debug_tuple else result[0]

    def _future_when(self, check: Callable[[], tuple[int, str]],
                     lookup: Callable[[], Any]) -> Future:
        fut = Future()
        if check()[0]:
            fut.set_result(lookup())
            return fut

        def on_new_data() -> None:
            try:
                if not fut.done() and check()[0]:
                    fut.set_result(lookup())
            except BaseException as exc:  # the waiter gets it, as upstream
                fut.set_exception(exc)

        with self._callbacks_lock:
            self._new_data_callbacks.append(on_new_data)
        fut.add_done_callback(lambda _: self._remove_callback(on_new_data))
        return fut

    def wait_for_transform_async(self, target_frame: str, source_frame: str,
                                 time: Any) -> Future:
        """A Future done (with the transform) once it can be looked up."""
        return self._future_when(
            lambda: self.can_transform_core(target_frame, source_frame, time),
            lambda: self.lookup_transform(target_frame, source_frame, time))

    def wait_for_transform_full_async(self, target_frame: str, target_time: Any,
                                      source_frame: str, source_time: Any,
                                      fixed_frame: str) -> Future:
        return self._future_when(
            lambda: self.can_transform_full_core(target_frame, target_time, source_frame,
                                                 source_time, fixed_frame),
            lambda: self.lookup_transform_full_core(target_frame, target_time, source_frame,
                                                    source_time, fixed_frame))
