"""The walks through the frame tree that tf2's BufferCore makes (walkToTopParent,
getLatestCommonTime, _chainAsVector), with their accumulators.

A lookup climbs from the source frame to the root, then from the target frame until it
meets that path: the transforms gathered on the way compose into the answer. The order of
the checks decides which error a broken tree gives, so it follows buffer_core.cpp step by
step (the text of each error included).
"""

from __future__ import annotations

from typing import Protocol

from robot_lab.tf2 import linear_math as lm
from robot_lab.tf2.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    LookupException,
    TransformException,
)
from robot_lab.tf2.time_cache import Cache, Problem, TF2Error, TransformStorage

MAX_GRAPH_DEPTH = 1000
_NEVER = 2**63 - 1  # TimePoint::max()

Outcome = tuple[TF2Error, str]

# The exception each error code raises (tf2_py maps the three extrapolation kinds to one).
RAISE: dict[TF2Error, type[TransformException]] = {
    TF2Error.CONNECTIVITY_ERROR: ConnectivityException,
    TF2Error.BACKWARD_EXTRAPOLATION_ERROR: ExtrapolationException,
    TF2Error.FORWARD_EXTRAPOLATION_ERROR: ExtrapolationException,
    TF2Error.NO_DATA_FOR_EXTRAPOLATION_ERROR: ExtrapolationException,
    TF2Error.EXTRAPOLATION_ERROR: ExtrapolationException,
    TF2Error.LOOKUP_ERROR: LookupException,
}


class Accumulator(Protocol):
    def gather(self, cache: Cache, time: int, problem: Problem) -> int: ...
    def accum(self, source: bool) -> None: ...
    def finalize(self, end: str, time: int) -> None: ...


class TransformAccum:
    """Composes the transforms met on both sides of the walk."""

    def __init__(self) -> None:
        self.st: TransformStorage | None = None
        self.time = 0
        self.source_vec, self.source_quat = lm.ZERO, lm.IDENTITY
        self.target_vec, self.target_quat = lm.ZERO, lm.IDENTITY
        self.result_vec, self.result_quat = lm.ZERO, lm.IDENTITY

    def gather(self, cache: Cache, time: int, problem: Problem) -> int:
        self.st = cache.get_data(time, problem)
        return 0 if self.st is None else self.st.frame_id

    def accum(self, source: bool) -> None:
        st = self.st
        assert st is not None
        if source:
            self.source_vec = lm.add(lm.rotate(st.rotation, self.source_vec), st.translation)
            self.source_quat = lm.multiply(st.rotation, self.source_quat)
        else:
            self.target_vec = lm.add(lm.rotate(st.rotation, self.target_vec), st.translation)
            self.target_quat = lm.multiply(st.rotation, self.target_quat)

    def finalize(self, end: str, time: int) -> None:
        if end == 'target_parent_of_source':
            self.result_vec, self.result_quat = self.source_vec, self.source_quat
        elif end in ('source_parent_of_target', 'full_path'):
            inv_quat = lm.inverse(self.target_quat)
            inv_vec = lm.rotate(inv_quat, lm.negate(self.target_vec))
            if end == 'source_parent_of_target':
                self.result_vec, self.result_quat = inv_vec, inv_quat
            else:
                self.result_vec = lm.add(lm.rotate(inv_quat, self.source_vec), inv_vec)
                self.result_quat = lm.multiply(inv_quat, self.source_quat)
        self.time = time


class CanTransformAccum:
    """Only follows parents: whether a walk would succeed."""

    def gather(self, cache: Cache, time: int, problem: Problem) -> int:
        return cache.get_parent(time, problem)

    def accum(self, source: bool) -> None:
        pass

    def finalize(self, end: str, time: int) -> None:
        pass


class Walker:
    """The walks; the buffer supplies its frames (`frame_cache`, `frame_name`)."""

    def frame_cache(self, number: int) -> Cache | None:
        raise NotImplementedError

    def frame_name(self, number: int) -> str:
        raise NotImplementedError

    def frames(self) -> list[tuple[str, Cache | None]]:
        raise NotImplementedError

    def parent_name(self, number: int) -> str:
        raise NotImplementedError

    def frames_as_string(self) -> str:
        """allFramesAsString: `Frame c exists with parent p.` per frame with data."""
        out = []
        for name, cache in self.frames():
            if cache is None:
                continue
            latest = cache.get_data(0)
            parent = latest.frame_id if latest is not None else 0
            out.append(f'Frame {name} exists with parent {self.parent_name(parent)}.\n')
        return ''.join(out)

    def _loop_error(self) -> Outcome:
        return (TF2Error.LOOKUP_ERROR,
                f'The tf tree is invalid because it contains a loop.\n{self.frames_as_string()}\n')

    def _connectivity(self, source_id: int, target_id: int) -> Outcome:
        return (TF2Error.CONNECTIVITY_ERROR,
                f"Could not find a connection between '{self.frame_name(target_id)}' and "
                f"'{self.frame_name(source_id)}' because they are not part of the same tree."
                'Tf has two or more unconnected trees.')

    def _ending(self, source_id: int, target_id: int) -> str:
        return (f', when looking up transform from frame [{self.frame_name(source_id)}] '
                f'to frame [{self.frame_name(target_id)}]')

    def walk_to_top_parent(self, f: Accumulator, time: int, target_id: int, source_id: int,
                           chain: list[int] | None = None) -> Outcome:
        if chain is not None:
            chain.clear()
        if source_id == target_id:
            f.finalize('identity', time)
            return TF2Error.NO_ERROR, ''
        if time == 0:
            code, time, text = self.latest_common_time(target_id, source_id)
            if code != TF2Error.NO_ERROR:
                return code, text
        frame = top_parent = source_id
        depth = 0
        source_problem = Problem()
        extrapolation_might_have_occurred = False
        while frame != 0:
            cache = self.frame_cache(frame)
            if chain is not None:
                chain.append(frame)
            if cache is None:
                top_parent = frame
                break
            parent = f.gather(cache, time, source_problem)
            if parent == 0:
                top_parent = frame
                extrapolation_might_have_occurred = True
                break
            if frame == target_id:
                f.finalize('target_parent_of_source', time)
                return TF2Error.NO_ERROR, ''
            f.accum(True)
            top_parent = frame
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error()

        frame = target_id
        depth = 0
        reverse_chain: list[int] = []
        problem = Problem()
        while frame != top_parent:
            cache = self.frame_cache(frame)
            if chain is not None:
                reverse_chain.append(frame)
            if cache is None:
                break
            parent = f.gather(cache, time, problem)
            if parent == 0:
                return problem.code, problem.text + self._ending(source_id, target_id)
            if frame == source_id:
                f.finalize('source_parent_of_target', time)
                if chain is not None:
                    chain[:] = reverse_chain
                return TF2Error.NO_ERROR, ''
            f.accum(False)
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error()

        if frame != top_parent:
            if extrapolation_might_have_occurred:
                return source_problem.code, source_problem.text + self._ending(source_id,
                                                                               target_id)
            return self._connectivity(source_id, target_id)
        f.finalize('full_path', time)
        if chain is not None:
            _join_chains(chain, reverse_chain)
        return TF2Error.NO_ERROR, ''

    def latest_common_time(self, target_id: int, source_id: int) -> tuple[TF2Error, int, str]:
        """getLatestCommonTime: the newest time every dynamic link of the chain has."""
        if source_id == 0 or target_id == 0:
            return TF2Error.LOOKUP_ERROR, 0, ''
        if source_id == target_id:
            cache = self.frame_cache(source_id)
            return TF2Error.NO_ERROR, cache.latest_stamp() if cache is not None else 0, ''
        lct: list[tuple[int, int]] = []
        frame, depth, common = source_id, 0, _NEVER
        while frame != 0:
            cache = self.frame_cache(frame)
            if cache is None:
                break
            stamp, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if stamp != 0:
                common = min(stamp, common)
            lct.append((stamp, parent))
            frame = parent
            if frame == target_id:
                return TF2Error.NO_ERROR, 0 if common == _NEVER else common, ''
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                code, text = self._loop_error()
                return code, 0, text

        frame, depth, common = target_id, 0, _NEVER
        common_parent = 0
        parents = {parent for _, parent in lct}
        while True:
            cache = self.frame_cache(frame)
            if cache is None:
                break
            stamp, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if stamp != 0:
                common = min(stamp, common)
            if parent in parents:
                common_parent = parent
                break
            frame = parent
            if frame == source_id:
                return TF2Error.NO_ERROR, 0 if common == _NEVER else common, ''
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                code, text = self._loop_error()
                return code, 0, text

        if common_parent == 0:
            code, text = self._connectivity(source_id, target_id)
            return code, 0, text
        for stamp, parent in lct:
            if stamp != 0:
                common = min(common, stamp)
            if parent == common_parent:
                break
        return TF2Error.NO_ERROR, 0 if common == _NEVER else common, ''

    def chain_as_vector(self, target: str, target_time: int, source: str, source_time: int,
                        fixed: str) -> list[str]:
        """_chainAsVector: the frames a full lookup passes through."""
        ids = {name: self.frame_number(name) for name in (target, source, fixed)}
        source_chain: list[int] = []
        code, text = self.walk_to_top_parent(TransformAccum(), source_time, ids[fixed],
                                             ids[source], source_chain)
        if code != TF2Error.NO_ERROR:
            raise RAISE.get(code, TransformException)(text)
        if source_time != target_time:
            target_chain: list[int] = []
            code, text = self.walk_to_top_parent(TransformAccum(), target_time, ids[target],
                                                 ids[fixed], target_chain)
            if code != TF2Error.NO_ERROR:
                raise RAISE.get(code, TransformException)(text)
            _join_chains(source_chain, target_chain, reverse=False)
        return [self.frame_name(number) for number in source_chain]

    def frame_number(self, name: str) -> int:
        raise NotImplementedError


def _join_chains(chain: list[int], other: list[int], reverse: bool = True) -> None:
    """The pruning of two chains at their common part, as walkToTopParent does it (`other`'s
    kept part appended reversed) and _chainAsVector (appended in order, `reverse=False`)."""
    m, n = len(other), len(chain)
    while m > 0 and n > 0:
        m -= 1
        n -= 1
        if chain[n] != other[m]:
            break
    if n > 0:
        del chain[n - 1:]
    if m < len(other):
        kept = other[:m + 1]
        chain.extend(reversed(kept) if reverse else kept)
