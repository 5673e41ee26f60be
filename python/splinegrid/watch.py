"""A running WatchGrid call as a generator of revisions."""

from __future__ import annotations

import collections.abc
import contextlib
import threading
from typing import Any, Callable, Optional

import grpc

from splinegrid.errors import SplinegridError, _broke_off, _code
from splinegrid.retry import RetryPolicy
from splinegrid.v1 import grid_pb2


WATCH_AFTER_HEADER = "x-splinegrid-watch-after"  # where a WatchGrid stream begins
INCARNATION_HEADER = "x-splinegrid-incarnation"  # which creation of the id it watches


class RevisionWatch(collections.abc.Generator["grid_pb2.RevisionInfo", object, None]):
    """The revisions of a grid as they are stored: what :meth:`Client.watch` returns.

    A generator of ``RevisionInfo`` protos (``revision``, ``create_time``, ``origin``,
    ``parent_revision``, ``time``, ``step``): iterating blocks until the server stores the next
    revision, and ends when the grid is deleted or the watch is cancelled. ``close()`` (also by
    a ``with`` block or garbage collection) cancels the call; ``cancel()`` does the same from
    any other thread, and a ``next()`` blocked there then ends the iteration (StopIteration).
    A failed call raises :class:`SplinegridError` (e.g. ``NOT_FOUND``; ``UNIMPLEMENTED`` from a
    server without WatchGrid; ``UNAVAILABLE`` when the retries gave up). ``name`` is the grid's
    resource name.

    A call that breaks off (the replica died or stopped, a balancer reset the stream) is
    resumed inside ``next()``, under ``retry``, after the last revision received (or where the
    first call began, which the server states in its initial metadata): no revision is missed
    or repeated. When retention dropped revisions it had not received (more than
    ``--keep_revisions`` deformed ones stored while it was away), the server refuses the resumed
    call with OUT_OF_RANGE, which the iteration raises. The retries start afresh once
    a resumed call is up. When the resumed call finds the grid deleted, or another creation
    under its id, the iteration ends as a deletion ends it.
    """

    def __init__(self, open_call: Callable[[int], Any], name: str, after_revision: int = 0,
                 retry: Optional[RetryPolicy] = None,
                 pause: Optional[Callable[[float, threading.Event], bool]] = None) -> None:
        self._open = open_call
        self._pause = pause or (lambda wait, stop: stop.wait(wait))
        self._retry = retry or RetryPolicy(max_attempts=1)
        self._waits = self._retry.waits()
        self._after = after_revision  # the last revision received, or where the watch began
        self._incarnation = ""        # the creation watched, once a call has said
        self.name = name
        self._cancelled = threading.Event()
        self._done = False
        self._call = open_call(after_revision)

    def _same_creation(self) -> bool:
        """Takes in the current call's initial metadata (it has arrived, or the call is over):
        where the first call began (for -1) and which creation of the id is watched. False
        when the call watches another creation than the watch did."""
        metadata = dict(self._call.initial_metadata() or ())
        if self._after == -1:
            with contextlib.suppress(KeyError, ValueError):
                begins_after = int(metadata[WATCH_AFTER_HEADER])
                if begins_after >= 0:
                    self._after = begins_after
        incarnation = metadata.get(INCARNATION_HEADER, "")
        if not incarnation:
            return True
        if not self._incarnation:
            self._incarnation = incarnation
        return bool(incarnation == self._incarnation)

    def _resume(self, error: grpc.RpcError) -> bool:
        """Whether the call that ended with ``error`` is opened again (after a wait)."""
        if self._cancelled.is_set() or not _broke_off(error):
            return False
        if self._call.initial_metadata():  # the call was up: the retries start afresh
            self._waits = self._retry.waits()
        wait = next(self._waits, None)
        if wait is None or self._pause(wait, self._cancelled):
            return False
        self._call = self._open(self._after)
        if self._cancelled.is_set():  # cancel() raced with the reopening
            self._call.cancel()
        return True

    def send(self, value: object) -> grid_pb2.RevisionInfo:
        """The next revision (``value`` is ignored, as for ``next()``)."""
        while True:
            if self._done:
                raise StopIteration
            try:
                message = next(self._call)
            except StopIteration:
                self._done = True
                raise
            except grpc.RpcError as error:
                if not self._same_creation() or (self._incarnation and
                                                 _code(error) == grpc.StatusCode.NOT_FOUND):
                    # The grid was deleted (and maybe created again) while the call resumed:
                    # a NOT_FOUND after a call had found it (the server ends that call OK).
                    self._done = True
                    raise StopIteration from None
                if self._resume(error):
                    continue
                self._done = True
                if self._cancelled.is_set():
                    raise StopIteration from None
                raise SplinegridError.from_rpc_error(error) from error
            if not self._same_creation():
                self._call.cancel()
                self._done = True
                raise StopIteration
            info: grid_pb2.RevisionInfo = message.revision
            self._after = info.revision
            return info

    def throw(self, typ: Any, val: Any = None, tb: Any = None) -> grid_pb2.RevisionInfo:
        """Cancels the call and raises the exception (a generator that does not catch it)."""
        self.cancel()
        if val is None:
            val = typ() if isinstance(typ, type) else typ
        if tb is not None:
            val = val.with_traceback(tb)
        raise val

    def close(self) -> None:
        """Cancels the call; iterating afterwards ends at once."""
        self.cancel()

    def cancel(self) -> None:
        """Cancels the call; safe from any thread, also while another one iterates."""
        self._cancelled.set()
        self._done = True
        self._call.cancel()

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set()

    def __enter__(self) -> RevisionWatch:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __del__(self) -> None:
        if not self._done:
            with contextlib.suppress(Exception):
                self._call.cancel()
