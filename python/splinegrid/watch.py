"""A running WatchGrid call as a generator of revisions."""

from __future__ import annotations

import collections.abc
import contextlib
import threading
from typing import Any, Callable, Optional

import grpc

from splinegrid.errors import SplinegridError, _code
from splinegrid.retry import RetryPolicy
from splinegrid.v1 import grid_pb2


class RevisionWatch(collections.abc.Generator["grid_pb2.RevisionInfo", object, None]):
    """The revisions of a grid as they are stored: what :meth:`Client.watch` returns.

    A generator of ``RevisionInfo`` protos (``revision``, ``create_time``, ``origin``,
    ``parent_revision``, ``time``, ``step``): iterating blocks until the server stores the next
    revision, and ends when the server ends the stream (the grid was deleted, or the server is
    stopping) or the watch is cancelled. ``close()`` (also by a ``with`` block or garbage
    collection) cancels the call; ``cancel()`` does the same from any other thread, and a
    ``next()`` blocked there then ends the iteration (StopIteration). A failed call raises
    :class:`SplinegridError` (e.g. ``NOT_FOUND``; ``UNIMPLEMENTED`` from a server without
    WatchGrid). ``name`` is the grid's resource name. A call that fails with UNAVAILABLE
    before its first message is opened again under ``retry`` (inside ``next()``).
    """

    def __init__(self, open_call: Callable[[], Any], name: str,
                 retry: Optional[RetryPolicy] = None,
                 pause: Optional[Callable[[float, threading.Event], bool]] = None) -> None:
        self._open = open_call
        self._pause = pause or (lambda wait, stop: stop.wait(wait))
        self._waits = (retry or RetryPolicy(max_attempts=1)).waits()
        self._received = False  # a message arrived: no more retries
        self.name = name
        self._cancelled = threading.Event()
        self._done = False
        self._call = open_call()

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
                if (_code(error) == grpc.StatusCode.UNAVAILABLE and not self._received
                        and not self._cancelled.is_set()):
                    wait = next(self._waits, None)
                    if wait is not None:
                        if self._pause(wait, self._cancelled):  # cancelled while waiting
                            self._done = True
                            raise StopIteration from None
                        self._call = self._open()
                        if self._cancelled.is_set():  # cancel() raced with the reopening
                            self._call.cancel()
                        continue
                self._done = True
                if self._cancelled.is_set() and _code(error) == grpc.StatusCode.CANCELLED:
                    raise StopIteration from None
                raise SplinegridError.from_rpc_error(error) from error
            self._received = True
            info: grid_pb2.RevisionInfo = message.revision
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
