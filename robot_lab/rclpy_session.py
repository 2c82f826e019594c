"""The ROS session of a process (one per Jupyter kernel): context, hidden node, executor.

Why not `rclpy.init()` in a notebook: it installs signal handlers, so a kernel interrupt
shuts ROS down, and a second run of the cell raises. `session()` is idempotent, installs
no signal handlers, and spins a background executor so callbacks run between cells.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import os
import re
import sys
import threading
import time
import types
from collections import deque
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from robot_lab.env import apply_ros_defaults
from robot_lab.errors import GraphError

if TYPE_CHECKING:
    from rclpy.context import Context
    from rclpy.executors import Executor
    from rclpy.node import Node
    from rclpy.task import Future

__all__ = ['Session', 'is_session_node', 'session', 'shutdown_sessions']

T = TypeVar('T')
N = TypeVar('N', bound='Node')

_LOCK = threading.Lock()
_SESSIONS: dict[int, Session] = {}
# A session's hidden node, `_robot_lab_<pid>_<domain>`: it has no parameter services.
_SESSION_NODE = re.compile(r'/_robot_lab_\d+_\d+')


def is_session_node(full_name: str) -> bool:
    """Whether `/name` is a robot_lab session's own node (any process's)."""
    return _SESSION_NODE.fullmatch(full_name) is not None


def _init_args() -> list[str] | None:
    """ROS arguments for this process's first init (rcl configures logging only then).

    In a Jupyter kernel, console logs of nodes spun in the background would be printed into
    whichever cell runs at that moment; there they go to /rosout only, where
    `robot_lab.console()` shows them.
    """
    if 'ipykernel' in sys.modules:
        return ['robot_lab_kernel', '--ros-args', '--disable-stdout-logs']
    return None


# A session's participant hears every other participant of its domain at once: their
# announcements and endpoint lists answer its own within milliseconds. Fast DDS leaves the
# UDP receive buffers at the system default (rmem_default, 208 KiB) under
# ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (rmw_fastrtps replaces the transports there, so a
# profile's listenSocketBufferSize does not reach them), and a cold `ros2 node list` beside
# a dozen participants on a busy host overflowed them: 0-1,100 datagrams dropped per
# command, each resent only when its writer next sends a heartbeat. The kernel caps the
# size at rmem_max; where that is the default nothing changes.
RECEIVE_BUFFER = 4 << 20


def widen_receive_buffers(size: int = RECEIVE_BUFFER) -> int:
    """Ask for `size`-byte receive buffers on this process's UDP sockets (all of them are
    DDS's in a kit process); return how many sockets were asked."""
    import socket

    from robot_lab.linux import procfs

    asked = 0
    for fd, target in procfs.fd_targets().items():
        if not target.startswith('socket:'):
            continue
        with contextlib.suppress(OSError, ValueError):  # closed meanwhile
            sock = socket.socket(fileno=os.dup(fd))
            try:
                if sock.type == socket.SOCK_DGRAM and sock.family in (socket.AF_INET,
                                                                       socket.AF_INET6):
                    if sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) < size:
                        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, size)
                    asked += 1
            finally:
                sock.close()
    return asked


def _domain_from_env() -> int:
    """ROS_DOMAIN_ID, or the user's own domain when it is unset (robot_lab/domain.py)."""
    from robot_lab.domain import domain_for

    return domain_for()


class Session:
    """A live connection to the ROS graph of one domain.

    `node` is a hidden node (its name starts with `_`, so `node list` never shows it);
    use it for subscriptions, clients and graph queries. `executor` spins it in a daemon
    thread; add your own nodes with `add_node` (they get a thread of their own).

    Why single-threaded executors: rclpy's MultiThreadedExecutor (4 threads here before)
    rebuilds its wait set again and again while its pool takes up a callback, 1600-4000
    times a second for 30 messages a second; two subscriptions at 10 and 20 Hz cost
    46-99 % of a core with it, 2.5 % with one thread (bench/bench_session.py).
    Nothing of the kit waits, inside a callback of `node`, for an answer `node` itself
    must deliver, so one thread is enough there. Your nodes' callbacks may (a timer
    calling `robot_lab.param_get`), so they spin on a second thread and the hidden node
    stays free to answer them.
    """

    def __init__(self, domain_id: int) -> None:
        defer_code_generator()  # a kernel generates no message code either
        from rclpy.parameter import Parameter

        apply_ros_defaults()
        guard_action_clients()
        self.domain_id = domain_id
        self._closing = False  # close() has begun: a dying spin thread is expected
        self.context, self._owns_context = self._context_for(domain_id)
        self.node = self.hidden_node(
            f'{os.getpid()}_{domain_id}',
            # No ~/get_type_description service either: nobody asks a hidden node for its
            # types, and creating it imports numpy (0.05 CPU-s of each cold command).
            parameter_overrides=[Parameter('start_type_description_service', value=False)],
        )
        widen_receive_buffers()  # the participant's sockets exist once it has a node
        # When discovery began: graph queries wait out the first announcements after it.
        self.created = time.monotonic()
        self.executor = self._new_executor()
        self.executor.add_node(self.node)
        # Users' nodes (add_node): made on first use.
        self._nodes_lock = threading.Lock()
        self._nodes_executor: Executor | None = None
        self._nodes_thread: threading.Thread | None = None
        # Exceptions raised by the callbacks of the nodes added with add_node, latest last.
        self.callback_errors: deque[BaseException | None] = deque(maxlen=10)
        self._thread = self._start_spinning(self.executor, 'executor')

    def hidden_node(self, name: str, **options: Any) -> Node:
        """A node of the kit's own on this session's context, `_robot_lab_<name>`: hidden
        (the leading `_`), so node lists, graph pictures and checks leave it out; no
        parameter services and no /rosout, since nobody asks it anything."""
        import rclpy

        return rclpy.create_node(f'_robot_lab_{name}', context=self.context,
                                 start_parameter_services=False, enable_rosout=False,
                                 **options)

    def _new_executor(self) -> Executor:
        from rclpy.executors import SingleThreadedExecutor

        return SingleThreadedExecutor(context=self.context)

    def _start_spinning(self, executor: Executor, role: str) -> threading.Thread:
        thread = threading.Thread(target=self._spin, args=(executor,),
                                  name=f'robot_lab-{role}-{self.domain_id}', daemon=True)
        thread.start()
        return thread

    @staticmethod
    def _context_for(domain_id: int) -> tuple[Context, bool]:
        """Reuse the default context when it is ours to use; else make a private one."""
        import rclpy
        from rclpy.context import Context
        from rclpy.signals import SignalHandlerOptions

        default = rclpy.utilities.get_default_context()
        if default.ok():
            if default.get_domain_id() == domain_id:
                return default, False  # the user (or an earlier session) initialised it
        elif not _SESSIONS:
            # First session: the default context, so students' rclpy.create_node() joins it.
            try:
                rclpy.init(args=_init_args(), domain_id=domain_id,
                           signal_handler_options=SignalHandlerOptions.NO)
                return default, True
            except RuntimeError:
                pass  # a default context that was shut down cannot be initialised again
        context = Context()
        context.init(args=_init_args(), domain_id=domain_id)
        return context, True

    def _spin(self, executor: Executor) -> None:
        from rclpy.exceptions import InvalidHandle
        from rclpy.executors import ExternalShutdownException

        while True:
            try:
                executor.spin()
                return
            except ExternalShutdownException:
                return
            except InvalidHandle:
                # rclpy race: an entity with event handlers was destroyed from another thread
                # while the executor built its wait set. Waiting again skips it; dying here
                # would leave the kernel's session without callbacks.
                continue
            except Exception:
                # close() shuts the executor down while this thread may be building its
                # wait set (rclpy then meets the destroyed guard condition as None): that
                # is the end of spinning, not an error worth a traceback at exit.
                if self.context.ok() and not self._closing:
                    if executor is self._nodes_executor:
                        self._callback_failed(sys.exc_info()[1])
                        return
                    raise
                return

    def _callback_failed(self, err: BaseException | None) -> None:
        """A callback of a user's node raised: the thread ends, as `rclpy.spin(node)` would.

        Kept for the checks (they name the line), and printed trimmed to the user's frames:
        rclpy's executor frames say nothing about the mistake.
        """
        from robot_lab.notebook_cell import their_traceback

        self.callback_errors.append(err)
        shown = their_traceback(err) if err is not None else []
        if shown:
            print('A callback of your node raised (it stops spinning until a node is added '
                  'again):', *shown, sep='\n', file=sys.stderr)

    @property
    def ok(self) -> bool:
        return bool(self.context.ok()) and self._thread.is_alive()

    def add_node(self, node: N) -> N:
        """Spin `node` (created with this session's context) in the background too.

        A callback of `node` that raises stops its thread, as `rclpy.spin(node)` would
        (the traceback is printed); the hidden node and the widgets keep working, and the
        next `add_node` spins the nodes again.
        """
        with self._nodes_lock:
            if self._nodes_executor is None:
                self._nodes_executor = self._new_executor()
            self._nodes_executor.add_node(node)
            if self._nodes_thread is None or not self._nodes_thread.is_alive():
                self._nodes_thread = self._start_spinning(self._nodes_executor, 'nodes')
        return node

    def remove_node(self, node: Node) -> None:
        """Stop spinning `node`; on return its executor no longer holds it.

        An executor keeps the handles of its last wait set in use until that wait ends, and
        rclpy defers `destroy_node()` of a handle in use: a node destroyed at once would
        keep its publishers alive a moment longer, long enough for a new node's publisher
        of another type on the same topic to fail (`incompatible type`). A task queued
        after the removal runs once the executor has left that wait.
        """
        with self._nodes_lock:
            if self._nodes_executor is not None and node in self._nodes_executor.get_nodes():
                executor, thread = self._nodes_executor, self._nodes_thread
            else:
                executor, thread = self.executor, self._thread
        if node not in executor.get_nodes():
            return
        executor.remove_node(node)
        if thread is None or not thread.is_alive() or threading.current_thread() is thread:
            return  # nobody spins it (or this is its callback): nothing holds it after this
        left_wait = threading.Event()
        executor.create_task(left_wait.set)
        left_wait.wait(2.0)

    def wait_future(self, future: Future, timeout: float, what: str) -> Any:
        """Wait for an rclpy future spun by the background executor; never hangs."""
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        if not done.wait(timeout):
            future.cancel()
            if threading.current_thread() is self._thread:
                raise GraphError(
                    f'{what}: no answer within {timeout:g} s, waited for inside a callback '
                    'of the session node, which cannot answer until that callback returns',
                    fix='make the call from a cell or a thread of your own, or from a node '
                    'added with session.add_node()')
            raise GraphError(f'{what}: no answer within {timeout:g} s')
        exc = future.exception()
        if exc is not None:
            raise GraphError(f'{what}: {exc}')
        return future.result()

    def run_in_executor(self, fn: Callable[[], T], timeout: float = 5.0) -> T:
        """Run `fn` once on the executor thread (for rclpy calls that must not race)."""
        from rclpy.task import Future

        if threading.current_thread() is self._thread:
            return fn()  # already there (a callback): waiting for itself would hang

        future: Future = Future()

        def _call() -> None:
            try:
                future.set_result(fn())
            except Exception as exc:
                future.set_exception(exc)

        guard = self.node.create_guard_condition(_call)
        try:
            guard.trigger()
            result: T = self.wait_future(future, timeout, 'executor call')
            return result
        finally:
            self.node.destroy_guard_condition(guard)

    def close(self) -> None:
        """Stop the executor and, if this session created it, the context."""
        self._closing = True
        # Best effort: at interpreter exit rclpy may already be half torn down.
        executors = [self.executor, self._nodes_executor]
        for executor in executors:
            if executor is not None:
                with contextlib.suppress(Exception):
                    executor.shutdown(timeout_sec=2.0)
        with contextlib.suppress(Exception):
            self.node.destroy_node()
        if self._owns_context:
            self.context.try_shutdown()
        for thread in (self._thread, self._nodes_thread):
            if thread is not None:
                thread.join(timeout=2.0)


def session(domain_id: int | None = None) -> Session:
    """The process's session for `domain_id` (default: ROS_DOMAIN_ID), created once.

    Safe to call from every notebook cell; a session whose context died (someone called
    rclpy.shutdown()) is replaced.
    """
    domain = _domain_from_env() if domain_id is None else domain_id
    with _LOCK:
        existing = _SESSIONS.get(domain)
        if existing is not None and existing.ok:
            return existing
        if existing is not None:
            existing.close()
            del _SESSIONS[domain]
        created = Session(domain)
        _SESSIONS[domain] = created
        return created


@atexit.register
def shutdown_sessions() -> None:
    """Close every session (registered at exit: the kernel leaves no DDS participant)."""
    with _LOCK:
        for sess in list(_SESSIONS.values()):
            sess.close()
        _SESSIONS.clear()


def defer_code_generator() -> None:
    """Import rosidl_generator_py without its code generator, which loads on first use.

    Every message class imports the package for `import_type_support`, and the package
    imports the generator as well (empy, lark, the IDL parser: 0.07 s of CPU). A `ros2`
    command generates no code; it gets the function alone (the same one) and `generate_py`
    only if something asks for it.
    """
    if 'rosidl_generator_py' in sys.modules:
        return
    spec = importlib.util.find_spec('rosidl_generator_py')
    if spec is None or spec.submodule_search_locations is None:
        return
    package = importlib.util.module_from_spec(spec)
    sys.modules['rosidl_generator_py'] = package
    support = importlib.import_module('rosidl_generator_py.import_type_support_impl')
    package.import_type_support = support.import_type_support  # type: ignore[attr-defined]
    package.__all__ = ['import_type_support', 'generate_py']  # type: ignore[attr-defined]

    def generator(name: str) -> Any:
        if name != 'generate_py':
            raise AttributeError(f"module 'rosidl_generator_py' has no attribute {name!r}")
        return importlib.import_module('rosidl_generator_py.generate_py_impl').generate_py

    package.__getattr__ = generator  # type: ignore[method-assign]


def guard_action_clients() -> None:
    """Close a window in older rclpy's ActionClient where an answer gets lost.

    It sends a goal (result, cancel) request and only then notes its sequence number; an
    executor on another thread (the kit's, a kernel's) that takes the answer in between
    drops it ("Ignoring unexpected goal response. There may be more than one action
    server"), and the goal's future never completes (CI: `send_goal --feedback` printed
    nothing more). Upstream closed it with a lock per client around sending-and-noting and
    around taking the answers (ros2/rclpy#1308; Jazzy 7.1.6, #1517). An rclpy without it
    gets the same here, from outside; one that has it is left as it is
    (`action_client_has_lock`). Neither holds a lock while the answer is handled, so a
    student's feedback or done callback may send another goal from any thread. Applied
    once, to every ActionClient of the process, students' own included: now if
    rclpy.action is imported, else when it is (a process that makes no action client, most
    `ros2` commands, then never imports it).
    """
    module = sys.modules.get('rclpy.action.client')
    if module is not None:
        _guard(module.ActionClient)
    elif not any(isinstance(finder, _GuardOnImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _GuardOnImport())


# What the upstream fix locks: the three requests and the take of their answers.
_SENDING = ('send_goal_async', '_cancel_goal_async', '_get_result_async')


def action_client_has_lock(ActionClient: Any) -> bool:  # noqa: N803 - the class
    """Whether this rclpy's ActionClient sends and takes under a lock of its own (#1308).

    Read from the methods' code, not the version: the PyPI wheel ros-rclpy 7.1.6 ships
    rclpy 7.1.5's sources (its egg-info and package.xml say 7.1.5), without the fix.
    """
    def names(method: str) -> tuple[str, ...]:
        code = getattr(getattr(ActionClient, method, None), '__code__', None)
        return () if code is None else tuple(code.co_names)

    return all('_lock' in names(method) for method in (*_SENDING, 'take_data'))


class _GuardOnImport(importlib.abc.MetaPathFinder):
    """Guards ActionClient right after `rclpy.action.client` is executed."""

    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: types.ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if fullname != 'rclpy.action.client':
            return None
        with contextlib.suppress(ValueError):
            sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        loader = None if spec is None else spec.loader
        if spec is None or not isinstance(loader, importlib.abc.Loader):
            return spec
        run = loader.exec_module

        def exec_module(module: types.ModuleType) -> None:
            run(module)
            _guard(module.ActionClient)

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


def _guard(ActionClient: Any) -> None:  # noqa: N803 - the class
    """Send-and-note and take under one lock per client, as upstream's fix does."""
    if getattr(ActionClient, '_robot_lab_guarded', False):
        return
    ActionClient._robot_lab_guarded = True  # checked: upstream's lock, or the kit's below
    ActionClient._robot_lab_wrapped = not action_client_has_lock(ActionClient)
    if not ActionClient._robot_lab_wrapped:
        return

    def locked(method: Callable[..., T]) -> Callable[..., T]:
        @functools.wraps(method)
        def wrapper(self: Any, *args: Any, **kwargs: Any) -> T:
            lock = self.__dict__.setdefault('_robot_lab_lock', threading.RLock())
            with lock:
                return method(self, *args, **kwargs)
        return wrapper

    for name in (*_SENDING, 'take_data'):
        setattr(ActionClient, name, locked(getattr(ActionClient, name)))
