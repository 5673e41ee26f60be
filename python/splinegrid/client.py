"""A Python client of the splinegrid.v1 service (same semantics as the C++ client/client.h).

Conventions
-----------
Names
    A grid may be named ``"foo"`` or ``"grids/foo"``; both mean the resource ``grids/foo``.

Arrays
    Points are NumPy arrays shaped ``(nk, nj, ni, s)`` in C order, so the last index before the
    coordinate, ``i``, is the fastest in memory, exactly the service's packed layout
    ("coordinates interleaved, i fastest"). ``s`` is the number of coordinates, 2 or 3. The
    element ``points[k, j, i]`` is the point of grid index ``(i, j, k)``. Uploads also accept
    ``(nj, ni, s)`` (a surface, nk = 1) and ``(ni, s)`` (a curve); results are always 4-D (use
    ``points[0]`` for the ``(nj, ni, s)`` view of a 2-D block).

Deadlines
    Every call gets a deadline of ``timeout`` seconds from its start (each page of ``list``,
    each upload of ``import_plot3d`` and each batch of ``evaluate_points`` separately); its
    retries run within it.

Retries
    A call that fails with UNAVAILABLE (a replica died, a balancer had no upstream, the server
    is restarting) is made again after a growing, jittered wait (:class:`RetryPolicy`): every
    unary call, and streaming calls that fail before their first response (``evaluate``,
    ``export_grid``, ``watch``; uploads, whose only response comes at the end, are sent again
    whole). ``health`` is not retried. An attempt whose answer was lost may still have been
    carried out, so a retried call that stores something can meet its own earlier attempt:
    ``deform`` with a ``base_revision`` answers ABORTED (ask ``get(name, step=...)`` whether
    the step landed, as ``examples/pitching.py`` does); ``deform`` without one, ``fit`` and
    ``fair`` may store a second revision; imports and ``generate`` with an id answer
    ALREADY_EXISTS, ``delete`` NOT_FOUND. ``RetryPolicy(max_attempts=1)`` turns retrying off.

Routing
    Every call about a grid carries the metadata ``x-splinegrid-grid: <id>`` (the name
    without ``grids/``; for imports and ``generate`` the requested id, when given), which a
    balancer in front of several replicas hashes on.

Errors
    A failed call raises :class:`SplinegridError`, which keeps the gRPC status code name (e.g.
    ``"NOT_FOUND"``) and the server's message; it subclasses ``grpc.RpcError`` and chains the
    original error as ``__cause__``. A stream that ends inconsistently (missing or misplaced
    chunks) raises it with code ``"DATA_LOSS"``. Arguments that are wrong before any call is
    made raise ``ValueError``.

Results
    Resources come back as the generated protos (``Grid``, ``FitGridResponse``; their fields
    are documented in ``proto/splinegrid/v1/*.proto``); bulk numbers as NumPy arrays.

Bulk data (uploads, evaluation chunks, EvaluatePoints) is moved between wire bytes and NumPy
arrays without a step per value, see ``_wire``.
"""

from __future__ import annotations

import collections.abc
import contextlib
import math
import os
import random
import threading
import time
from dataclasses import dataclass
from typing import (Any, Callable, Iterable, Iterator, Mapping, NamedTuple, Optional, Sequence,
                    TypeVar, Union)

import grpc
import numpy as np
import numpy.typing as npt
from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid import records
from splinegrid.v1 import archive_pb2
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

__all__ = [
    "GRID_ROUTING_HEADER",
    "SERVICE",
    "ArchiveSummary",
    "BoundaryPoints",
    "Client",
    "EvaluatedBlock",
    "EvaluatedGrid",
    "EvaluatedPoints",
    "RetryPolicy",
    "RevisionWatch",
    "SplinegridError",
    "WallCurvatureLine",
    "grid_name",
]

SERVICE = "splinegrid.v1.SplineGrid"
GRID_ROUTING_HEADER = "x-splinegrid-grid"  # the grid a call is about, for a balancer to hash on
UPLOAD_CHUNK_BYTES = 1 << 20  # Plot3D bytes or point coordinates per upload message
MAX_RECEIVE_BYTES = 8 << 20
LIST_PAGE_SIZE = 500
POINTS_BATCH_BYTES = 3 << 20  # EvaluatePoints request or response size per call

_T = TypeVar("_T")
PathOrBytes = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview]
Triple = Sequence[int]  # (i, j) or (i, j, k)
Blocks = Union[None, int, Iterable[int]]

_FIELD_NAMES = {
    service_pb2.FIELD_POINTS: "points",
    service_pb2.FIELD_DU: "du",
    service_pb2.FIELD_DV: "dv",
    service_pb2.FIELD_DW: "dw",
}
_HEALTH_STATUS = ("UNKNOWN", "SERVING", "NOT_SERVING", "SERVICE_UNKNOWN")
_KINDS = {
    "wall": grid_pb2.BOUNDARY_KIND_WALL,
    "interface": grid_pb2.BOUNDARY_KIND_INTERFACE,
    "outer": grid_pb2.BOUNDARY_KIND_OUTER,
}
_FACES = {
    "imin": grid_pb2.BLOCK_FACE_I_MIN, "imax": grid_pb2.BLOCK_FACE_I_MAX,
    "jmin": grid_pb2.BLOCK_FACE_J_MIN, "jmax": grid_pb2.BLOCK_FACE_J_MAX,
    "kmin": grid_pb2.BLOCK_FACE_K_MIN, "kmax": grid_pb2.BLOCK_FACE_K_MAX,
}
_PROPAGATIONS = {
    "blend": service_pb2.PROPAGATION_BLEND,
    "transfinite": service_pb2.PROPAGATION_TRANSFINITE,
}
_LAYER_METHODS = {
    "offsets": service_pb2.LAYER_METHOD_OFFSETS,
    "transfinite": service_pb2.LAYER_METHOD_TRANSFINITE,
    "elliptic": service_pb2.LAYER_METHOD_ELLIPTIC,
}
MAX_CHECK_LEVEL = 4  # the server's highest fold-check level

# A face range: a grid_pb2.FaceRange, a (block, face, begin, end) tuple or a dict with those
# keys; face "imin" ... "kmax" (or the BlockFace value), begin/end (i, j[, k]) inclusive.
FaceRangeLike = Union[grid_pb2.FaceRange, tuple, Mapping[str, Any]]


class SplinegridError(grpc.RpcError):
    """A failed call: ``code`` is the gRPC status code name, ``message`` the server's message."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message

    @property
    def status_code(self) -> Optional[grpc.StatusCode]:
        """``code`` as a ``grpc.StatusCode`` (None if gRPC has no such code)."""
        return grpc.StatusCode.__members__.get(self.code)

    @classmethod
    def from_rpc_error(cls, error: grpc.RpcError) -> SplinegridError:
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        return cls(code.name, details or "")


@dataclass(frozen=True)
class RetryPolicy:
    """When and how often a call that failed with UNAVAILABLE is made again (the C++ client's
    ``RetryPolicy``). The n-th retry waits ``min(initial_backoff * multiplier**(n-1),
    max_backoff)`` seconds, scaled by a random factor uniform in ``[1 - jitter, 1 + jitter]``;
    a wait that would end at or past the call's deadline is not taken (the call raises its last
    error). The defaults wait about 0.05, 0.1, 0.2, 0.4 s: a call gives up after ~0.75 s of
    UNAVAILABLE."""

    max_attempts: int = 5          # attempts in all, the first included; 1 turns retrying off
    initial_backoff: float = 0.05  # seconds before the first retry
    max_backoff: float = 2.0       # longest wait between two attempts (before jitter)
    multiplier: float = 2.0        # growth of the wait per retry
    jitter: float = 0.2            # relative spread of each wait, in [0, 1]

    def __post_init__(self) -> None:
        if self.max_attempts < 1:
            raise ValueError(f"max_attempts = {self.max_attempts}; must be at least 1")
        if not (self.initial_backoff >= 0 and self.max_backoff >= 0 and self.multiplier >= 1
                and 0 <= self.jitter <= 1):
            raise ValueError(f"{self}: backoffs must be >= 0, multiplier >= 1, jitter in "
                             "[0, 1]")

    def waits(self) -> Iterator[float]:
        """The waits before the 2nd, 3rd, ... attempt (``max_attempts - 1`` of them)."""
        backoff = self.initial_backoff
        for _ in range(self.max_attempts - 1):
            yield min(backoff, self.max_backoff) * random.uniform(1 - self.jitter,
                                                                  1 + self.jitter)
            backoff = min(backoff * self.multiplier, self.max_backoff)


class ArchiveSummary(NamedTuple):
    """What :meth:`Client.export_grid` wrote: the archive's header (an ``ArchiveHeader``
    proto), its source chunk and revision records, and the file's size in bytes."""
    header: Any
    source_chunks: int
    revisions: int
    bytes: int


@dataclass
class EvaluatedBlock:
    """One evaluated block: ``points`` and, when asked for, ``du``/``dv``/``dw``.

    All arrays are shaped ``(nk, nj, ni, s)`` (C order, i fastest); the derivatives are
    dX/du, dX/dv, dX/dw with respect to the block's spline parameters.
    """

    block: int
    points: np.ndarray
    du: Optional[np.ndarray] = None
    dv: Optional[np.ndarray] = None
    dw: Optional[np.ndarray] = None


class EvaluatedGrid(list[EvaluatedBlock]):
    """The blocks of one evaluation in the order asked for: a list with two more attributes,
    the ``revision`` that was evaluated and ``spatial_dim`` (s)."""

    def __init__(self, revision: int, spatial_dim: int,
                 blocks: Iterable[EvaluatedBlock] = ()) -> None:
        super().__init__(blocks)
        self.revision = revision
        self.spatial_dim = spatial_dim


@dataclass
class EvaluatedPoints:
    """The result of :meth:`Client.evaluate_points`: arrays shaped ``(N, s)``."""

    revision: int
    points: np.ndarray
    du: Optional[np.ndarray] = None
    dv: Optional[np.ndarray] = None
    dw: Optional[np.ndarray] = None


class BoundaryPoints(NamedTuple):
    """New positions (or, with ``displacements=True``, displacements) of the points of one face
    range at refinement level ``level``, for :meth:`Client.deform`: ``coordinates`` is shaped
    ``(N, s)`` with the range's points at that level in point order (i fastest)."""
    range: FaceRangeLike
    coordinates: npt.ArrayLike
    level: int = 0
    displacements: bool = False


class RevisionWatch(collections.abc.Generator):
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
            return message.revision

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


class WallCurvatureLine(NamedTuple):
    """Curvature samples along one wall grid line (points start + t e_direction of a block)."""
    block: int
    direction: int           # 0 i, 1 j, 2 k
    start: tuple[int, int, int]
    arc_length: np.ndarray   # (n,)
    points: np.ndarray       # (n, spatial_dim)
    curvature: np.ndarray    # (n,), signed in 2-D (positive turning left)


def grid_name(name_or_id: str) -> str:
    """``"foo"`` or ``"grids/foo"`` -> ``"grids/foo"``."""
    return name_or_id if name_or_id.startswith("grids/") else f"grids/{name_or_id}"


class Client:
    """A connection to a splinegrid server (a plaintext or TLS channel to ``target``).

    Use it as a context manager, or call :meth:`close`. ``timeout`` is the deadline of every
    call in seconds; ``retry`` says how calls failing with UNAVAILABLE are retried within it
    (see the module's "Retries"; the channel also reconnects at that pace). ``stub`` is the
    generated ``SplineGridStub`` for anything not wrapped here (its calls get neither
    deadlines, retries, routing header, token nor error translation).

    Security (``serve --tokens``, ``--tls_cert``): ``token`` (default: the environment
    variable ``SPLINEGRID_TOKEN``) is sent with every call as ``authorization: Bearer TOKEN``.
    ``tls_ca`` (a PEM file: the CA the server's certificate must chain to), or ``tls=True``
    for the system's roots, makes the channel TLS; ``tls_cert`` and ``tls_key`` (PEM files)
    are this client's certificate for a server that requires one (mTLS); ``tls_server_name``
    is the name the server's certificate must carry when it is not the target's host.
    """

    def __init__(self, target: str = "localhost:50051", timeout: float = 120.0,
                 retry: Optional[RetryPolicy] = None, *, token: Optional[str] = None,
                 tls: bool = False, tls_ca: Optional[str] = None,
                 tls_cert: Optional[str] = None, tls_key: Optional[str] = None,
                 tls_server_name: Optional[str] = None) -> None:
        if not timeout > 0:
            raise ValueError(f"timeout = {timeout}; must be positive")
        if token is None:
            token = os.environ.get("SPLINEGRID_TOKEN", "")
        if token and not (token.isascii() and token.isprintable() and " " not in token):
            # Never repeat the token itself.
            raise ValueError("token: must be printable ASCII without blanks")
        if (tls_cert is None) != (tls_key is None):
            raise ValueError("tls_cert and tls_key: give both (a client certificate) or neither")
        self._auth = (("authorization", f"Bearer {token}"),) if token else ()
        self.target = target
        self.timeout = timeout
        self.retry = RetryPolicy() if retry is None else retry
        options = [("grpc.max_receive_message_length", MAX_RECEIVE_BYTES)]
        if self.retry.max_attempts > 1:
            # gRPC's own reconnect backoff starts at 1 s: a restarted server would be reached
            # only after the retries are spent. Reconnect at the retry policy's pace instead.
            options += [("grpc.initial_reconnect_backoff_ms",
                         max(1, int(self.retry.initial_backoff * 1000))),
                        ("grpc.max_reconnect_backoff_ms",
                         max(1, int(self.retry.max_backoff * 1000)))]
        if tls or tls_ca is not None or tls_cert is not None or tls_server_name is not None:
            credentials = grpc.ssl_channel_credentials(
                root_certificates=_read_pem(tls_ca, "tls_ca"),
                private_key=_read_pem(tls_key, "tls_key"),
                certificate_chain=_read_pem(tls_cert, "tls_cert"))
            if tls_server_name:
                options.append(("grpc.ssl_target_name_override", tls_server_name))
            self._channel = grpc.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(target, options=options)
        self.stub = service_grpc.SplineGridStub(self._channel)
        # The bulk methods exchange hand-encoded bytes (see _wire) instead of generated classes.
        self._import_grid = self._channel.stream_unary(
            f"/{SERVICE}/ImportGrid", request_serializer=_serialize,
            response_deserializer=grid_pb2.Grid.FromString)
        self._evaluate_grid = self._channel.unary_stream(
            f"/{SERVICE}/EvaluateGrid", request_serializer=_serialize,
            response_deserializer=_decode_evaluate_response)
        self._evaluate_points = self._channel.unary_unary(
            f"/{SERVICE}/EvaluatePoints", request_serializer=_serialize,
            response_deserializer=_decode_points_response)
        self._health_check = self._channel.unary_unary(
            "/grpc.health.v1.Health/Check", request_serializer=_encode_health_request,
            response_deserializer=_decode_health_response)
        # Archives pass as raw ArchiveRecord bytes (the payloads of the record file).
        self._export_grid = self._channel.unary_stream(
            f"/{SERVICE}/ExportGrid", request_serializer=_serialize,
            response_deserializer=_export_record_bytes)
        self._import_archive = self._channel.stream_unary(
            f"/{SERVICE}/ImportArchive", request_serializer=_serialize,
            response_deserializer=grid_pb2.Grid.FromString)

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # Calls: deadline, routing header, retries, error translation

    def _call(self, attempt: Callable[[_Attempt], _T], grid: str = "") -> _T:
        """Runs ``attempt`` (one try of a call, given its timeout and metadata) until it does not
        fail with UNAVAILABLE, it has responded (``_Attempt.responded``: a stream is not
        retried past its first message), or ``self.retry`` gives up; all attempts share the
        deadline ``self.timeout`` from now. grpc.RpcError -> SplinegridError (chained; the
        message says the attempt when there were retries)."""
        deadline = time.monotonic() + self.timeout
        metadata = self._metadata(grid)
        waits = self.retry.waits()
        attempts = 0
        while True:
            attempts += 1
            state = _Attempt(max(deadline - time.monotonic(), 1e-3), metadata)
            try:
                return attempt(state)
            except SplinegridError:
                raise
            except grpc.RpcError as error:
                wait = None
                if _code(error) == grpc.StatusCode.UNAVAILABLE and not state.responded:
                    wait = next(waits, None)
                if wait is None or time.monotonic() + wait >= deadline:
                    translated = SplinegridError.from_rpc_error(error)
                    if attempts > 1:
                        translated = SplinegridError(
                            translated.code, f"{translated.message} [attempt {attempts}; the "
                            "earlier ones failed with UNAVAILABLE]")
                    raise translated from error
            self._pause_before_retry(wait)

    def _metadata(self, grid: str) -> Optional[tuple]:
        """The metadata of a call about ``grid``: its routing header and the token."""
        return ((_routing_metadata(grid) or ()) + self._auth) or None

    def _pause_before_retry(self, wait: float, stop: Optional[threading.Event] = None) -> bool:
        """Waits ``wait`` seconds before the next attempt of a call, with a health check that
        waits for the channel to be connected meanwhile: gRPC takes in the outcome of a
        reconnection only while a call waits on the channel (otherwise its backup poller does,
        every 5 s), so a plain sleep would leave a restarted server unseen for seconds. Ends
        early, returning True, when ``stop`` is set."""
        until = time.monotonic() + wait
        probe = self._health_check.future("", timeout=wait, wait_for_ready=True)
        try:
            while not probe.done() and time.monotonic() < until:
                if stop is not None and stop.is_set():
                    return True
                with contextlib.suppress(grpc.FutureTimeoutError):
                    probe.exception(timeout=min(0.1, max(0.0, until - time.monotonic())))
        finally:
            probe.cancel()
        left = max(0.0, until - time.monotonic())
        if stop is not None:
            return stop.wait(left)
        time.sleep(left)
        return False

    def _unary(self, method: Callable[..., _T], request: Union[bytes, Message],
               grid: Optional[str] = None) -> _T:
        """One unary call with :meth:`_call`; ``grid`` (default: the request's) routes it."""
        if grid is None:
            grid = _routing_grid(request)
        return self._call(lambda a: method(request, timeout=a.timeout, metadata=a.metadata),
                          grid)

    # Import

    def import_plot3d(self, path_or_bytes: PathOrBytes, grid_id: str = "",
                      display_name: str = "",
                      planar_view: Optional[bool] = None) -> grid_pb2.Grid:
        """Uploads a Plot3D file (a path, or its bytes) as a new grid; returns it (BASIC view).

        The file goes in 1 MiB pieces after an ImportHeader. ``grid_id`` is the new name's last
        segment ("" lets the server pick). ``planar_view=True`` stores the 2-D view of a grid
        held as two planes (CFL3D style) and fails for any other grid; ``False`` stores the
        file as read. ``None`` means "planar exactly when the file is a two-plane grid": the
        upload is tried with True and, if the server answers INVALID_ARGUMENT because the file
        is not a two-plane grid, repeated with False. That costs a second upload for ordinary
        files; pass False (or True) when you know.
        """
        data = _read_bytes(path_or_bytes)
        if planar_view is not None:
            return self._import_plot3d(data, grid_id, display_name, planar_view)
        try:
            return self._import_plot3d(data, grid_id, display_name, True)
        except SplinegridError as error:
            message = error.message.lower()
            if error.code != "INVALID_ARGUMENT" or not ("two-plane" in message
                                                        or "planar" in message):
                raise
        return self._import_plot3d(data, grid_id, display_name, False)

    def _import_plot3d(self, data: memoryview, grid_id: str, display_name: str,
                       planar_view: bool) -> grid_pb2.Grid:
        header = service_pb2.ImportHeader(
            grid_id=_grid_id(grid_id), display_name=display_name,
            plot3d=service_pb2.Plot3dSource(total_bytes=len(data), planar_view=planar_view))

        def requests() -> Iterator[Union[bytes, Message]]:
            yield service_pb2.ImportGridRequest(header=header)
            for at in range(0, len(data), UPLOAD_CHUNK_BYTES):
                # ImportGridRequest.plot3d_chunk (field 2), without copying into a message.
                yield _wire.length_delimited(2, data[at:at + UPLOAD_CHUNK_BYTES].tobytes())

        return self._call(lambda a: self._import_grid(requests(), timeout=a.timeout,
                                                      metadata=a.metadata), header.grid_id)

    def import_points(self, blocks: Sequence[npt.ArrayLike], grid_id: str = "",
                      display_name: str = "") -> grid_pb2.Grid:
        """Uploads point blocks as a new grid; returns it (BASIC view).

        Each block is an array shaped ``(nk, nj, ni, s)``, ``(nj, ni, s)`` or ``(ni, s)`` (C
        order: i fastest; see the module docstring), with the same s (2 or 3) for all blocks.
        The coordinates go as PointChunk messages of at most 1 MiB of values each.
        """
        arrays = [_as_block(b, n) for n, b in enumerate(blocks)]
        if not arrays:
            raise ValueError("blocks is empty: a grid needs a block")
        s = arrays[0].shape[-1]
        if any(a.shape[-1] != s for a in arrays):
            raise ValueError("all blocks must have the same number of coordinates (last axis)")
        header = service_pb2.ImportHeader(
            grid_id=_grid_id(grid_id), display_name=display_name,
            points=service_pb2.PointsSource(
                spatial_dim=s,
                blocks=[grid_pb2.Extents(i=a.shape[2], j=a.shape[1], k=a.shape[0])
                        for a in arrays]))
        values_per_chunk = UPLOAD_CHUNK_BYTES // 8

        def requests() -> Iterator[Union[bytes, Message]]:
            yield service_pb2.ImportGridRequest(header=header)
            for b, array in enumerate(arrays):
                flat = array.reshape(-1)
                prefix = service_pb2.PointChunk(block=b).SerializeToString()
                for at in range(0, flat.size, values_per_chunk):
                    # PointChunk {block, coordinates} as ImportGridRequest.points (field 3).
                    chunk = prefix + _wire.packed_doubles(2, flat[at:at + values_per_chunk])
                    yield _wire.length_delimited(3, chunk)

        return self._call(lambda a: self._import_grid(requests(), timeout=a.timeout,
                                                      metadata=a.metadata), header.grid_id)

    # Fit and the grid resource

    def fit(self, name: str, control_counts: Optional[Triple] = None,
            tolerance: Optional[float] = None, order: int = 4,
            max_controls: int = 0,
            boundary_tolerances: Optional[dict[str, float]] = None,
            fairing: Union[None, str, float] = None,
            allow_folds: bool = False,
            ref_length: Optional[float] = None,
            face_kinds: Union[None, str, dict, list] = None) -> service_pb2.FitGridResponse:
        """Fits the grid's source points; the result is stored as a new revision.

        Give one of ``control_counts`` ``(a, b)`` or ``(a, b, c)`` (control points per
        direction i, j, k for every block; 0 or a missing entry: as many as points), a
        ``tolerance`` (largest deviation of every point, in the grid's length unit) or
        ``boundary_tolerances``, a dict with any of ``wall``, ``interface``, ``outer``,
        ``interior`` and ``edge`` (missing: the paper's 0.15e-3, 2e-3, 8e-3, no interior
        tolerance, edge 0.5; ``{}`` takes all defaults). The values given are lengths in the
        grid's unit; the defaults are fractions of the grid's reference length: ``ref_length``
        (implies ``boundary_tolerances={}`` when none is given; refused with ``tolerance`` or
        ``control_counts``, which are absolute), else detected by the server as the largest
        extent of a wall (an airfoil's chord; the bounding-box diagonal without walls), so a
        grid in chords, millimetres or inches is fitted alike. The report states it
        (``reference_length``, ``reference_length_description``) and the tolerances held
        (``tolerances``). With tolerances, knots are added until
        they are met or ``max_controls`` per direction (0 = no cap) is reached, and the fit is
        watertight across blocks. Neither: interpolate.

        ``fairing``: ``"tol"`` (the largest fairing weight within the tolerances) or a weight.

        ``face_kinds``: explicit boundary kinds of block faces, overriding the server's
        classification: a dict ``{(block, face): kind}``, a list of ``"BLOCK:FACE=KIND"``
        strings, or one such string with commas (as the CLI's ``--face``); FACE is ``imin``,
        ``imax``, ``jmin``, ``jmax``, ``kmin`` or ``kmax``, KIND ``wall``, ``interface`` or
        ``outer`` (there is no symmetry kind). Implies ``boundary_tolerances={}`` when none
        is given; refused with ``tolerance`` or ``control_counts``. A bad entry raises
        ValueError naming it.

        A fit whose cells fold at refinement levels 0-2 (after the server's repair, tolerance
        fits only) raises a FAILED_PRECONDITION error naming the cells and stores nothing,
        unless ``allow_folds`` is true: then the revision is stored and its ``report`` says
        ``quality_met = False`` with ``folded_cells``.

        Returns the FitGridResponse proto: ``revision``, ``num_points``,
        ``num_control_points``, ``compression_ratio``, ``max_deviation``, ``seconds``,
        ``blocks`` (one BlockFitSummary per block: deviation overall and per boundary kind,
        cell quality, tolerance outcome) and ``report`` (FitReport: tolerances met, cell
        validity at refinement levels 0-2, connectivity and gaps, fairing weight, wall
        curvature before and after fairing).
        """
        if ref_length is not None:
            if tolerance is not None or control_counts is not None:
                raise ValueError("ref_length applies to the tolerances by kind; tolerance and "
                                 "control_counts are absolute")
            if not float(ref_length) > 0.0:
                raise ValueError(f"ref_length = {ref_length}; give a positive length")
            if boundary_tolerances is None:
                boundary_tolerances = {}
        if face_kinds is not None:
            if tolerance is not None or control_counts is not None:
                raise ValueError("face_kinds apply to the tolerances by kind; tolerance and "
                                 "control_counts do not use kinds")
            if boundary_tolerances is None:
                boundary_tolerances = {}
        spec = _fit_spec(control_counts, tolerance, order, max_controls, boundary_tolerances,
                         fairing)
        if face_kinds is not None:
            spec.face_kinds.extend(_face_kinds(face_kinds))
        spec.allow_folds = bool(allow_folds)
        if ref_length is not None:
            spec.reference_length = float(ref_length)
        request = service_pb2.FitGridRequest(name=grid_name(name), spec=spec)
        return self._unary(self.stub.FitGrid, request)

    def fair(self, name: str, revision: int = 0,
             fairing: Union[None, str, float] = None,
             allow_folds: bool = False) -> service_pb2.FitGridResponse:
        """Refits revision ``revision`` (0: latest) with fairing and stores a new revision.
        A faired fit that folds cells is refused (FAILED_PRECONDITION) unless ``allow_folds``.

        ``fairing``: ``"tol"``, a weight, or None (the server's default: to tolerance for a
        revision fitted to tolerances). Returns the FitGridResponse of the new revision; its
        report compares the wall curvature with and without fairing.
        """
        request = service_pb2.FairGridRequest(name=grid_name(name), revision=revision,
                                              allow_folds=bool(allow_folds))
        if fairing is not None:
            request.fairing.CopyFrom(_fairing(fairing))
        return self._unary(self.stub.FairGrid, request)

    def generate(self, name: str = "", airfoil: Union[None, str, bytes,
                                                      "os.PathLike[str]"] = None,
                 points: Optional[npt.ArrayLike] = None,
                 stored_wall: Union[None, str, tuple] = None,
                 display_name: str = "", method: Optional[str] = None,
                 wall_points: Optional[int] = None, layers: Optional[int] = None,
                 first_height: Optional[float] = None, distance: Optional[float] = None,
                 orthogonalize: Optional[bool] = None,
                 fit_tolerance: Optional[float] = None,
                 control_counts: Optional[Triple] = None, tolerance: Optional[float] = None,
                 order: int = 4, max_controls: int = 0,
                 boundary_tolerances: Optional[dict[str, float]] = None,
                 fairing: Union[None, str, float] = None, allow_folds: bool = False
                 ) -> service_pb2.GenerateGridResponse:
        """Generates an O-grid around a profile, stores it as the new grid ``name`` ("" lets the
        server pick an id; ALREADY_EXISTS if taken) and fits it as revision 1. Nothing is
        stored on an error.

        The profile is one of ``airfoil`` (a Selig or Lednicer file: its path, or its text as a
        str with line breaks, or bytes), ``points`` (an ``(n, 2)`` array in Selig order:
        trailing edge, upper surface, leading edge, lower surface, trailing edge) or
        ``stored_wall``: a grid's name, or ``(name, block)`` or ``(name, block, revision)``
        (the wall points of that 2-D block's j = 0 edge, revision 0 = latest).

        Layers (None: the server's defaults, core/generate/profile_grid.h): ``method``
        ``"offsets"`` (curvature-controlled offsets, default), ``"transfinite"`` or
        ``"elliptic"`` (transfinite, smoothed by the elliptic equations coarse to fine; odd
        ``wall_points``, even ``layers``),
        ``wall_points`` (257; the first repeated as the last), ``layers`` (128 cells outward),
        ``first_height`` (1e-5, the profile's unit), ``distance`` (50, of the outer boundary
        from the wall), ``orthogonalize`` (transfinite: lines leave the wall normally; True),
        ``fit_tolerance`` (1e-4, of the profile spline to the points).

        The fit of revision 1 takes :meth:`fit`'s arguments; with none of ``control_counts``,
        ``tolerance``, ``boundary_tolerances`` and ``fairing`` the server interpolates the grid
        (exact; wall j = 0, outer j = max, the seam an interface). A fit that folds cells is
        refused (nothing stored) unless ``allow_folds``.

        Returns the GenerateGridResponse proto: ``grid`` (BASIC view, revision 1), ``report``
        (GenerationReport: ``parameters`` used, ``extents``, ``profile`` fit, ``growth_ratio``,
        ``retries``, ``quality`` with ``negative_cells``, ``first_height_min``/``max``,
        ``wall_orthogonality_degrees``, ...; stage seconds) and ``fit`` (as :meth:`fit`
        returns it).
        """
        given = [airfoil is not None, points is not None, stored_wall is not None]
        if sum(given) != 1:
            raise ValueError("give exactly one of airfoil, points and stored_wall")
        request = service_pb2.GenerateGridRequest(grid_id=_grid_id(name),
                                                  display_name=display_name,
                                                  allow_folds=bool(allow_folds))
        if airfoil is not None:
            request.airfoil_file = _airfoil_text(airfoil)
        elif points is not None:
            xy = np.ascontiguousarray(points, dtype=np.float64)
            if xy.ndim != 2 or xy.shape[1] != 2:
                raise ValueError(f"points has shape {xy.shape}; give an (n, 2) array")
            request.points.xy.extend(xy.reshape(-1).tolist())
        else:
            wall = (stored_wall,) if isinstance(stored_wall, str) else tuple(stored_wall)
            if not 1 <= len(wall) <= 3:
                raise ValueError(f"stored_wall = {stored_wall!r}; give name, (name, block) or "
                                 "(name, block, revision)")
            request.stored_wall.name = grid_name(wall[0])
            if len(wall) > 1:
                request.stored_wall.block = _non_negative_int(wall[1], "stored_wall block")
            if len(wall) > 2:
                request.stored_wall.revision = _non_negative_int(wall[2], "stored_wall revision")
        if method is not None:
            if method not in _LAYER_METHODS:
                raise ValueError(f"method = {method!r}; give one of {sorted(_LAYER_METHODS)}")
            request.method = _LAYER_METHODS[method]
        for field, value in (("wall_points", wall_points), ("layers", layers)):
            if value is not None:
                setattr(request, field, _integer(value, field))
        for field, value in (("first_height", first_height), ("distance", distance),
                             ("fit_tolerance", fit_tolerance)):
            if value is not None:  # NaN and non-positive values: the server names them
                setattr(request, field, float(value))
        if orthogonalize is not None:
            request.orthogonalize = bool(orthogonalize)
        if any(v is not None for v in (control_counts, tolerance, boundary_tolerances, fairing)):
            request.spec.CopyFrom(_fit_spec(control_counts, tolerance, order, max_controls,
                                            boundary_tolerances, fairing))
            if not request.spec.HasField("resolution"):
                request.spec.boundary_tolerances.SetInParent()
        return self._unary(self.stub.GenerateGrid, request)

    def wall_curvature(self, name: str, revision: int = 0, level: int = 2,
                       blocks: Blocks = None) -> list[WallCurvatureLine]:
        """Curvature along every wall grid line of revision ``revision`` (0: latest), sampled at
        refinement level ``level`` (2**level - 1 samples between grid points)."""
        request = service_pb2.GetWallCurvatureRequest(
            name=grid_name(name), revision=revision, refinement_level=level,
            blocks=_block_list(blocks))
        response = self._unary(self.stub.GetWallCurvature, request)
        dim = response.spatial_dim
        return [WallCurvatureLine(
            block=line.block, direction=line.direction,
            start=(line.start.i, line.start.j, line.start.k),
            arc_length=np.asarray(line.arc_length, dtype=np.float64),
            points=np.asarray(line.points, dtype=np.float64).reshape(-1, dim),
            curvature=np.asarray(line.curvature, dtype=np.float64)) for line in response.lines]

    def get(self, name: str, revision: int = 0, full: bool = False,
            blocks: Iterable[int] = (), step: Optional[int] = None) -> grid_pb2.Grid:
        """The grid with revision ``revision`` (0: latest). ``full`` adds knots, control points
        and point distributions (of ``blocks`` only, when given). ``step``: instead of a
        revision, the latest revision stamped with this solver time step (see
        :meth:`deform`); NOT_FOUND if there is none."""
        request = service_pb2.GetGridRequest(
            name=grid_name(name), revision=revision, blocks=list(blocks),
            view=service_pb2.GRID_VIEW_FULL if full else service_pb2.GRID_VIEW_BASIC)
        _set_step(request, revision, step)
        return self._unary(self.stub.GetGrid, request)

    def list(self) -> list[grid_pb2.Grid]:
        """Every grid (BASIC view), ordered by name, following the pages."""
        grids: list[grid_pb2.Grid] = []
        request = service_pb2.ListGridsRequest(page_size=LIST_PAGE_SIZE)
        while True:
            response = self._unary(self.stub.ListGrids, request)
            grids.extend(response.grids)
            if not response.next_page_token:
                return grids
            request.page_token = response.next_page_token

    def delete(self, name: str) -> None:
        self._unary(self.stub.DeleteGrid, service_pb2.DeleteGridRequest(name=grid_name(name)))

    # Deformation (fluid-structure coupling)

    def deform(self, name: str, rotate_degrees: Optional[float] = None,
               about: Optional[Sequence[float]] = None,
               axis: Optional[Sequence[float]] = None,
               translate: Optional[Sequence[float]] = None,
               boundary: Union[None, str, FaceRangeLike,
                               Iterable[Union[str, FaceRangeLike]]] = None,
               reference_revision: int = 0, base_revision: int = 0, time: float = 0.0,
               step: int = 0, check_level: int = 0,
               control_displacements: Optional[Mapping[int, tuple[npt.ArrayLike,
                                                                  npt.ArrayLike]]] = None,
               boundary_points: Optional[Iterable[BoundaryPoints]] = None,
               propagation: str = "blend", decay_radius: float = 0.0,
               rigid_radius: float = 0.0,
               smoothing_iterations: int = 0) -> service_pb2.DeformGridResponse:
        """Moves part of a revision's boundary, lets the grid follow, checks it for folded cells
        and stores it as a new revision (DeformGrid); returns the DeformGridResponse proto:
        ``revision`` and ``report`` (DeformReport: ``min_jacobian_ratio``,
        ``max_orthogonality_change_degrees``, ``moved_controls``, ``decay_radius``,
        ``seconds``, ...).

        The motion is one of
          - a rigid motion: ``rotate_degrees`` about the axis ``axis`` (3 values; default z,
            the only axis of a 2-D grid, positive turning counter-clockwise) through ``about``
            (2 or 3 values; default the origin), then ``translate`` (2 or 3 values);
          - ``control_displacements``: ``{block: (controls, displacements)}``, control indices
            (i fastest) of moved controls and their displacements shaped ``(N, s)``; moved
            controls not listed stay;
          - ``boundary_points``: :class:`BoundaryPoints`, new positions (or displacements) of
            the points of boundary ranges at a refinement level, fitted with the stored basis.

        ``boundary`` says what moves: ``"wall"`` (the default), ``"outer"``, ``"interface"``, a
        list of those, or face ranges (one or a list): ``(block, face, begin, end)`` tuples or
        dicts with those keys, ``face`` one of ``"imin"``, ..., ``"kmax"``, ``begin``/``end``
        ``(i, j[, k])`` grid indices inclusive at both ends. Kinds and ranges do not mix.

        ``reference_revision`` is the revision whose geometry is moved (0: the latest): giving
        the fit's revision every step makes the motions absolute (no drift).
        ``base_revision`` is the latest revision the caller has seen: if the grid has a newer
        one the call fails with ABORTED (0: no check). ``time`` and ``step`` stamp the new
        revision (see ``get``/``evaluate(step=...)``). ``check_level`` (0 to 4) is the
        refinement level of the fold check. ``propagation``: ``"blend"`` (free controls by
        their distance to the moved boundary) or ``"transfinite"`` (block interiors by Coons
        interpolation); ``decay_radius`` (0: the distance to the nearest fixed boundary),
        ``rigid_radius`` and ``smoothing_iterations`` shape it.

        A deformation that folds cells raises :class:`SplinegridError` with code
        ``FAILED_PRECONDITION`` and the server's message (how many cells, where); nothing is
        stored. Wrong arguments raise ``ValueError`` before any call.
        """
        request = service_pb2.DeformGridRequest(name=grid_name(name))
        request.reference_revision = _non_negative_int(reference_revision, "reference_revision")
        request.base_revision = _non_negative_int(base_revision, "base_revision")
        request.time = _finite(time, "time")
        request.step = _integer(step, "step")
        request.check_level = _integer(check_level, "check_level")
        if not 0 <= request.check_level <= MAX_CHECK_LEVEL:
            raise ValueError(f"check_level = {check_level}; must be in [0, {MAX_CHECK_LEVEL}]")
        if propagation not in _PROPAGATIONS:
            raise ValueError(f"propagation = {propagation!r}; give 'blend' or 'transfinite'")
        request.propagation = _PROPAGATIONS[propagation]
        request.decay_radius = _non_negative(decay_radius, "decay_radius")
        request.rigid_radius = _non_negative(rigid_radius, "rigid_radius")
        if request.decay_radius > 0.0 and request.rigid_radius > request.decay_radius:
            raise ValueError(f"rigid_radius = {rigid_radius} exceeds decay_radius = "
                             f"{decay_radius}")
        request.smoothing_iterations = _non_negative_int(smoothing_iterations,
                                                         "smoothing_iterations")
        request.boundary.CopyFrom(_boundary_selection(boundary))

        rigid = rotate_degrees is not None or translate is not None
        motions = [label for label, given in (("rotate_degrees/translate", rigid),
                                            ("control_displacements",
                                             control_displacements is not None),
                                            ("boundary_points", boundary_points is not None))
                   if given]
        if len(motions) != 1:
            raise ValueError("give one motion: rotate_degrees (and/or translate), "
                             "control_displacements or boundary_points"
                             + (f"; got {', '.join(motions)}" if motions else ""))
        if not rigid and (about is not None or axis is not None):
            raise ValueError("about and axis belong to a rotation (rotate_degrees)")
        if rigid:
            motion = request.rigid
            motion.angle_degrees = _finite(0.0 if rotate_degrees is None else rotate_degrees,
                                           "rotate_degrees")
            if about is not None:
                motion.center.extend(_vector(about, "about", (2, 3)))
            if axis is not None:
                values = _vector(axis, "axis", (3,))
                if not any(values):
                    raise ValueError("axis = (0, 0, 0); the rotation axis must not be zero")
                motion.axis.extend(values)
            if translate is not None:
                motion.translation.extend(_vector(translate, "translate", (2, 3)))
        elif control_displacements is not None:
            request.controls.SetInParent()
            if not isinstance(control_displacements, Mapping):
                raise ValueError("control_displacements: give {block: (controls, "
                                 "displacements)}")
            for block, pair in control_displacements.items():
                what = f"control_displacements[{block}]"
                try:
                    controls, values = pair
                except (TypeError, ValueError):
                    raise ValueError(f"{what}: give (controls, displacements)") from None
                index = np.asarray(controls).reshape(-1)
                if index.size and not np.issubdtype(index.dtype, np.integer):
                    raise ValueError(f"{what}: control indices must be integers")
                moved = np.asarray(values, dtype=np.float64)
                if moved.ndim != 2 or moved.shape[0] != index.size or moved.shape[1] not in (2, 3):
                    raise ValueError(f"{what}: displacements have shape {moved.shape}; expected "
                                     f"({index.size}, s) with s = 2 or 3")
                if not np.all(np.isfinite(moved)):
                    raise ValueError(f"{what}: displacements must be finite")
                if np.any(index < 0):
                    raise ValueError(f"{what}: control indices must not be negative")
                request.controls.blocks.add(block=_non_negative_int(block, what + " block"),
                                            controls=index.tolist(),
                                            values=moved.reshape(-1).tolist())
        else:
            request.boundary_points.SetInParent()
            for q, item in enumerate(boundary_points):
                what = f"boundary_points[{q}]"
                if not isinstance(item, BoundaryPoints):
                    item = BoundaryPoints(*item) if isinstance(item, tuple) else \
                        BoundaryPoints(**item)
                points = np.asarray(item.coordinates, dtype=np.float64)
                if points.ndim != 2 or points.shape[1] not in (2, 3):
                    raise ValueError(f"{what}: coordinates have shape {points.shape}; expected "
                                     "(N, s) with s = 2 or 3")
                if not np.all(np.isfinite(points)):
                    raise ValueError(f"{what}: coordinates must be finite")
                request.boundary_points.ranges.add(
                    range=_face_range(item.range, what + ".range"),
                    refinement_level=_non_negative_int(item.level, what + ".level"),
                    coordinates=points.reshape(-1).tolist(),
                    displacements=bool(item.displacements))
            if not request.boundary_points.ranges:
                raise ValueError("boundary_points is empty")
        return self._unary(self.stub.DeformGrid, request)

    def watch(self, name: str, after_revision: int = 0) -> RevisionWatch:
        """The grid's revisions as they are stored (WatchGrid): a generator of
        ``RevisionInfo`` (see :class:`RevisionWatch`).

        The revisions after ``after_revision`` that are stored already come first (0: all of
        them, -1: none), then each new one (a fit, a fairing, a deformation) as it is stored.
        The call has no deadline: it lasts until the grid is deleted, the server stops, or the
        watch is closed or cancelled::

            with client.watch("naca") as revisions:
                for info in revisions:
                    print(info.revision, info.step)
        """
        after = _integer(after_revision, "after_revision")
        if after < -1:
            raise ValueError(f"after_revision = {after_revision}; must be >= -1")
        request = service_pb2.WatchGridRequest(name=grid_name(name), after_revision=after)
        metadata = self._metadata(_routing_grid(request))
        return RevisionWatch(lambda: self.stub.WatchGrid(request, metadata=metadata),
                             request.name, self.retry, self._pause_before_retry)

    # Evaluation

    def evaluate(self, name: str, level: Optional[int] = None,
                 counts: Optional[Triple] = None, blocks: Blocks = None,
                 index_box: Optional[tuple[Triple, Triple]] = None,
                 derivatives: bool = False, dtype: npt.DTypeLike = np.float64,
                 revision: int = 0, step: Optional[int] = None) -> EvaluatedGrid:
        """Evaluates blocks of a revision (0: latest) on a grid of parameters.

        Resolution: ``level`` l puts 2^l - 1 new points in every original interval (0, the
        default, gives the original points), or ``counts`` ``(ni, nj[, nk])`` points per
        direction (a missing entry: 1; a count of 1 takes the first index of the block or box),
        both following the original clustering. ``blocks``: an
        index or indices (None: all, in order). ``index_box``: ``(begin, end)``, each
        ``(i, j[, k])`` in original grid indices, inclusive at both ends (missing: 0).
        ``dtype`` float32 transfers single precision (half the bytes). ``step``: instead of
        ``revision``, the latest revision stamped with this solver time step (the result's
        ``revision`` says which one).

        Returns an :class:`EvaluatedGrid`, a list of :class:`EvaluatedBlock` whose arrays are
        shaped ``(nk, nj, ni, s)`` with ``dtype``.
        """
        out_dtype = np.dtype(dtype)
        if out_dtype not in (np.float64, np.float32):
            raise ValueError(f"dtype = {out_dtype}; use float64 or float32")
        if level is not None and counts is not None:
            raise ValueError("give level or counts, not both")
        block_list = _block_list(blocks)
        if len(set(block_list)) != len(block_list):
            # The chunks name blocks by index, so a repeated block could not be told apart.
            raise ValueError(f"blocks = {block_list} repeats a block")
        request = service_pb2.EvaluateGridRequest(
            name=grid_name(name), revision=revision, blocks=block_list,
            derivatives=derivatives,
            precision=(service_pb2.PRECISION_FLOAT if out_dtype == np.float32
                       else service_pb2.PRECISION_DOUBLE))
        _set_step(request, revision, step)
        if counts is not None:
            request.counts.CopyFrom(_extents(counts, "counts", fill=1))
        else:
            request.refinement_level = 0 if level is None else level
        if index_box is not None:
            begin, end = index_box
            request.index_box.begin.CopyFrom(_extents(begin, "index_box begin", fill=0))
            request.index_box.end.CopyFrom(_extents(end, "index_box end", fill=0))
        def attempt(a: _Attempt) -> EvaluatedGrid:
            call = self._evaluate_grid(request, timeout=a.timeout, metadata=a.metadata)
            try:
                return _assemble(a.marking(call), out_dtype)
            except SplinegridError:
                call.cancel()
                raise

        return self._call(attempt, _routing_grid(request))

    def evaluate_points(self, name: str, params: npt.ArrayLike,
                        blocks: Union[int, npt.ArrayLike] = 0, derivatives: bool = False,
                        revision: int = 0, step: Optional[int] = None) -> EvaluatedPoints:
        """Evaluates N parameter points ``params`` (shape ``(N, 3)``: u, v, w in [0, 1]; use
        w = 0 for a 2-D block) of block ``blocks`` (one index for all, or one per point).

        Returns :class:`EvaluatedPoints` with arrays shaped ``(N, s)``. Requests and responses
        must stay under gRPC's 4 MiB message limit, so large N is sent in several calls (each
        with its own deadline), all pinned to the revision the first one evaluated. ``step``:
        instead of ``revision``, the latest revision stamped with this solver time step.
        """
        uvw = np.ascontiguousarray(params, dtype=_wire.DOUBLE)
        if uvw.ndim == 1 and uvw.size == 3:
            uvw = uvw.reshape(1, 3)
        if uvw.ndim != 2 or uvw.shape[1] != 3:
            raise ValueError(f"params has shape {uvw.shape}; expected (N, 3)")
        block_array = np.asarray(blocks, dtype=np.int64).reshape(-1)
        if block_array.size not in (1, len(uvw)):
            raise ValueError(f"{block_array.size} blocks for {len(uvw)} points; give one, "
                             "or one per point")
        # Bytes per point: 24 of parameters + up to 5 of block index in the request; up to
        # 3 coordinates x (1 or 4 fields) x 9 in the response (the server's own estimate).
        if step is not None and revision != 0:
            raise ValueError(f"give revision ({revision}) or step ({step}), not both")
        per_point = max(29, 3 * (4 if derivatives else 1) * 9)
        batch = max(1, POINTS_BATCH_BYTES // per_point)
        parts: list[EvaluatedPoints] = []
        for at in range(0, max(len(uvw), 1), batch):
            head = service_pb2.EvaluatePointsRequest(
                name=grid_name(name), revision=revision, derivatives=derivatives,
                blocks=(block_array if block_array.size == 1
                        else block_array[at:at + batch]).tolist())
            if step is not None and not parts:  # later batches: the first's revision
                head.step = int(step)
            request = head.SerializeToString() + _wire.packed_doubles(  # + parameters
                4, uvw[at:at + batch])
            parts.append(self._unary(self._evaluate_points, request, _routing_grid(head)))
            revision = parts[0].revision
        if len(parts) == 1:
            return parts[0]
        joined = {f: np.concatenate([getattr(part, f) for part in parts])
                  for f in (("points", "du", "dv", "dw") if derivatives else ("points",))}
        return EvaluatedPoints(revision, **joined)

    # Archives

    def export_grid(self, name: str, path: Union[str, "os.PathLike[str]"]) -> ArchiveSummary:
        """Writes the grid with its source points and every revision it keeps (ExportGrid) to
        ``path`` as a record file of ``ArchiveRecord`` payloads (header, source chunks,
        revisions; the framing of :mod:`splinegrid.records`, the C++ client's and
        ``splinegrid export``'s). The records go to a temporary file beside ``path``, fsynced
        and renamed onto it once the stream is complete (its counts match the header): on any
        error nothing is left behind and an existing file stays as it was. An inconsistent
        stream raises :class:`SplinegridError` ``DATA_LOSS``."""
        request = service_pb2.ExportGridRequest(name=grid_name(name))
        path = os.fspath(path)
        temp = f"{path}.partial-{os.getpid()}"
        try:
            with records.RecordWriter(temp) as writer:
                def attempt(a: _Attempt) -> _ArchiveShape:
                    shape = _ArchiveShape(lambda what: _data_loss(
                        f"the export of {request.name}: {what}"))
                    call = self._export_grid(request, timeout=a.timeout, metadata=a.metadata)
                    try:
                        for payload in a.marking(call):
                            shape.add(payload)
                            writer.append(payload)
                    except BaseException:
                        call.cancel()
                        raise
                    shape.complete()
                    return shape

                shape = self._call(attempt, _routing_grid(request))
            os.replace(temp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.remove(temp)
            raise
        _sync_directory(os.path.dirname(path))
        return shape.summary(os.path.getsize(path))

    def import_archive(self, path: Union[str, "os.PathLike[str]"],
                       name: Optional[str] = None) -> grid_pb2.Grid:
        """Creates a grid from a record file written by :meth:`export_grid` (or the C++ client,
        or ``splinegrid export``): under ``name`` ("foo" or "grids/foo"), or the archive's own
        id when None, with every revision under its original number (ImportArchive). Returns
        the grid (BASIC view).

        A file that is not a record file, or is damaged or truncated (a torn record, a CRC
        mismatch, fewer records than its header announces, a first record that is not a
        header), raises :class:`splinegrid.records.RecordFileError` (a ``ValueError``) naming
        the file, the record and its byte offset; found while sending, the call is cancelled
        first, so nothing is stored.
        """
        path = os.fspath(path)
        new_id = _grid_id(name or "")

        def fault(what: str) -> records.RecordFileError:
            return records.RecordFileError(f"'{path}': {what}", path)

        # The header first: a file that is not an archive is refused before any call, and the
        # archive's id routes the call when no new one is given.
        with records.RecordReader(path) as reader:
            first = next(reader, None)
        shape = _ArchiveShape(fault)
        if first is None:
            shape.complete()
        shape.add(first)

        def attempt(a: _Attempt) -> grid_pb2.Grid:
            started = threading.Event()
            failure: list[Exception] = []
            box: dict[str, Any] = {}

            def requests() -> Iterator[bytes]:
                started.wait()
                try:
                    shape = _ArchiveShape(fault)
                    with records.RecordReader(path) as reader:
                        for payload in reader:
                            shape.add(payload)
                            # ImportArchiveRequest: grid_id (1, first message only), record (2).
                            message = _wire.length_delimited(2, payload)
                            if reader.record == 1 and new_id:
                                message = _wire.length_delimited(1, new_id.encode()) + message
                            yield message
                    shape.complete()
                except (records.RecordFileError, OSError) as error:
                    failure.append(error)
                    box["call"].cancel()  # before the stream ends: nothing is stored

            box["call"] = self._import_archive.future(requests(), timeout=a.timeout,
                                                      metadata=a.metadata)
            started.set()
            try:
                return box["call"].result()
            except (grpc.RpcError, grpc.FutureCancelledError):
                if failure:
                    raise failure[0] from None
                raise

        return self._call(attempt, new_id or shape.header.id)

    # Health

    def health(self, service: str = SERVICE) -> str:
        """The grpc.health.v1 status of ``service`` ("" = the whole server): "SERVING",
        "NOT_SERVING", ... A service the server does not know raises NOT_FOUND."""
        with _translated_errors():  # not retried: a probe answers for now
            return self._health_check(service, timeout=self.timeout)


# Helpers


class _Attempt:
    """One try of a call: its ``timeout`` (what is left of the call's deadline), its
    ``metadata``, and whether a response has arrived (``responded``; see ``marking``)."""

    __slots__ = ("timeout", "metadata", "responded")

    def __init__(self, timeout: float, metadata: Optional[tuple]) -> None:
        self.timeout = timeout
        self.metadata = metadata
        self.responded = False

    def marking(self, messages: Iterable[_T]) -> Iterator[_T]:
        """``messages`` passed through, setting ``responded`` at the first."""
        for message in messages:
            self.responded = True
            yield message


def _code(error: grpc.RpcError) -> grpc.StatusCode:
    return error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN


def _routing_grid(request: Union[bytes, Message]) -> str:
    """The grid a request is about: the id of its ``name``, else its ``grid_id`` (a new
    grid's), else none."""
    if isinstance(request, Message):
        fields = request.DESCRIPTOR.fields_by_name
        if "name" in fields:
            return _grid_id(request.name)
        if "grid_id" in fields:
            return request.grid_id
    return ""


def _read_pem(path: Optional[str], name: str) -> Optional[bytes]:
    """The bytes of the PEM file ``path`` (argument ``name``), or None."""
    if path is None:
        return None
    try:
        with open(path, "rb") as file:
            return file.read()
    except OSError as error:
        raise ValueError(f"{name}: cannot read {path!r}: {error.strerror}") from error


def _routing_metadata(grid: str) -> Optional[tuple]:
    """The routing header naming ``grid`` (none for no grid, or an id that is not printable
    ASCII, which the server refuses anyway)."""
    grid = _grid_id(grid)
    # Only what can be a grid id: a long or binary name goes without the header, so that the
    # server (not the metadata size limit) answers it with INVALID_ARGUMENT naming the field.
    if not grid or len(grid) > 128 or not (grid.isascii() and grid.isprintable()):
        return None
    return ((GRID_ROUTING_HEADER, grid),)


class _ArchiveShape:
    """Checks the shape of an archive as its records (serialized ``ArchiveRecord`` payloads)
    pass: a header first and only there, then as many source chunks and revisions as the
    header announces. ``fault`` makes the exception to raise from a description."""

    def __init__(self, fault: Callable[[str], Exception]) -> None:
        self._fault = fault
        self.header = archive_pb2.ArchiveHeader()
        self.records = self.source_chunks = self.revisions = 0

    def add(self, payload: bytes) -> None:
        self.records += 1
        try:
            kinds = [number for number, _, _ in _wire.fields(payload)]
        except ValueError:
            kinds = None
        if kinds is None or not kinds:
            raise self._fault(f"record {self.records - 1} is not an archive record")
        kind = kinds[-1]  # the oneof's last field wins
        if self.records == 1:
            if kind != 1:
                raise self._fault("the first record is not an archive header (is this an "
                                  "archive?)")
            self.header = archive_pb2.ArchiveRecord.FromString(payload).header
        elif kind == 1:
            raise self._fault(f"record {self.records - 1} is a second header")
        elif kind == 2:
            self.source_chunks += 1
        elif kind == 3:
            self.revisions += 1

    def complete(self) -> None:
        """After the last record: the counts match the header (revisions only when it counts
        them, as an export's does)."""
        if self.records == 0:
            raise self._fault("no records (an archive starts with its header)")
        h = self.header
        if (self.source_chunks != h.num_source_chunks
                or (h.num_revisions > 0 and self.revisions != h.num_revisions)):
            raise self._fault(f"truncated or incomplete: the header announces "
                              f"{h.num_source_chunks} source chunks and {h.num_revisions} "
                              f"revisions, there are {self.source_chunks} and {self.revisions}")

    def summary(self, size: int) -> ArchiveSummary:
        return ArchiveSummary(self.header, self.source_chunks, self.revisions, size)


def _export_record_bytes(data: bytes) -> bytes:
    """An ExportGridResponse's ``record`` (field 1) as raw ArchiveRecord bytes."""
    record = b""
    for number, wire_type, value in _wire.fields(data):
        if number == 1 and wire_type == _wire.LENGTH_DELIMITED:
            record += bytes(value)  # repeated occurrences of a message field merge
    return record


def _sync_directory(directory: str) -> None:
    """Makes a rename into ``directory`` durable (best effort)."""
    with contextlib.suppress(OSError):
        fd = os.open(directory or ".", os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


@contextlib.contextmanager
def _translated_errors() -> Iterator[None]:
    """grpc.RpcError -> SplinegridError (chained)."""
    try:
        yield
    except SplinegridError:
        raise
    except grpc.RpcError as error:
        raise SplinegridError.from_rpc_error(error) from error


def _data_loss(message: str) -> SplinegridError:
    return SplinegridError("DATA_LOSS", message)


def _serialize(message: Union[bytes, Message]) -> bytes:
    """Requests that are already encoded pass through; messages are serialized."""
    return message if isinstance(message, bytes) else message.SerializeToString()


def _read_bytes(path_or_bytes: PathOrBytes) -> memoryview:
    if isinstance(path_or_bytes, (bytes, bytearray, memoryview)):
        return memoryview(path_or_bytes).cast("B")
    with open(path_or_bytes, "rb") as file:
        return memoryview(file.read())


def _grid_id(grid_id: str) -> str:
    """The id part of "foo" or "grids/foo"."""
    return grid_id[len("grids/"):] if grid_id.startswith("grids/") else grid_id


def _extents(values: Triple, what: str, fill: int) -> grid_pb2.Extents:
    values = [int(v) for v in values]
    if not 1 <= len(values) <= 3:
        raise ValueError(f"{what} = {values}; give 1 to 3 integers (i, j, k)")
    i, j, k = values + [fill] * (3 - len(values))
    return grid_pb2.Extents(i=i, j=j, k=k)


def _fit_spec(control_counts: Optional[Triple], tolerance: Optional[float], order: int,
              max_controls: int, boundary_tolerances: Optional[dict[str, float]],
              fairing: Union[None, str, float]) -> grid_pb2.FitSpec:
    """The FitSpec of :meth:`Client.fit`'s arguments."""
    given = [control_counts is not None, tolerance is not None,
             boundary_tolerances is not None]
    if sum(given) > 1:
        raise ValueError("give one of control_counts, tolerance and boundary_tolerances")
    spec = grid_pb2.FitSpec(order=order, max_controls_per_direction=max_controls)
    if tolerance is not None:
        spec.tolerance = tolerance
    elif boundary_tolerances is not None:
        unknown = set(boundary_tolerances) - {"wall", "interface", "outer", "interior", "edge"}
        if unknown:
            raise ValueError(f"boundary_tolerances: unknown kinds {sorted(unknown)}")
        spec.boundary_tolerances.SetInParent()
        for kind, value in boundary_tolerances.items():
            setattr(spec.boundary_tolerances, kind, float(value))
    elif control_counts is not None:
        spec.control_counts.CopyFrom(_extents(control_counts, "control_counts", fill=0))
    if fairing is not None:
        spec.fairing.CopyFrom(_fairing(fairing))
    return spec


_FACES = {"imin": grid_pb2.BLOCK_FACE_I_MIN, "imax": grid_pb2.BLOCK_FACE_I_MAX,
          "jmin": grid_pb2.BLOCK_FACE_J_MIN, "jmax": grid_pb2.BLOCK_FACE_J_MAX,
          "kmin": grid_pb2.BLOCK_FACE_K_MIN, "kmax": grid_pb2.BLOCK_FACE_K_MAX}
_KINDS = {"wall": grid_pb2.BOUNDARY_KIND_WALL, "interface": grid_pb2.BOUNDARY_KIND_INTERFACE,
          "outer": grid_pb2.BOUNDARY_KIND_OUTER}
_FACE_HELP = ("give BLOCK:FACE=KIND or {(block, face): kind}, FACE imin, imax, jmin, jmax, kmin "
              "or kmax, KIND wall, interface or outer")


def _face_kinds(face_kinds: Union[str, dict, list]) -> list:
    """FaceKind messages of :meth:`Client.fit`'s ``face_kinds``; ValueError names a bad entry."""
    if isinstance(face_kinds, str):
        face_kinds = [t for t in face_kinds.split(",") if t.strip()]
    if isinstance(face_kinds, dict):
        entries = [(key, key, kind) for key, kind in face_kinds.items()]
    else:
        entries = []
        for token in face_kinds:
            text = str(token).strip()
            block_face, sep, kind = text.partition("=")
            block, sep2, face = block_face.partition(":")
            if not sep or not sep2:
                raise ValueError(f"face_kinds: {text!r}: {_FACE_HELP}")
            entries.append((text, (block, face), kind))
    out, seen = [], {}
    for what, key, kind in entries:
        try:
            block, face = key
            block = int(block)
        except (TypeError, ValueError):
            raise ValueError(f"face_kinds: {what!r}: the block is not a number; "
                             f"{_FACE_HELP}") from None
        face_name, kind_name = str(face).strip().lower(), str(kind).strip().lower()
        if block < 0:
            raise ValueError(f"face_kinds: {what!r}: block {block} < 0; {_FACE_HELP}")
        if face_name not in _FACES:
            raise ValueError(f"face_kinds: {what!r}: unknown face {face!r}; {_FACE_HELP}")
        if kind_name not in _KINDS:
            why = ("there is no symmetry kind (fit a symmetry plane as outer)"
                   if kind_name == "symmetry" else f"unknown kind {kind!r}")
            raise ValueError(f"face_kinds: {what!r}: {why}; {_FACE_HELP}")
        if (block, face_name) in seen:
            if seen[(block, face_name)] != kind_name:
                raise ValueError(f"face_kinds: {what!r}: the face is given another kind before")
            continue
        seen[(block, face_name)] = kind_name
        out.append(grid_pb2.FaceKind(block=block, face=_FACES[face_name], kind=_KINDS[kind_name]))
    return out


def _airfoil_text(airfoil: Union[str, bytes, "os.PathLike[str]"]) -> str:
    """An airfoil file's text from its path, or the text itself (a str with a line break)."""
    if isinstance(airfoil, (bytes, bytearray)):
        return bytes(airfoil).decode()
    if isinstance(airfoil, str) and "\n" in airfoil:
        return airfoil
    with open(airfoil, encoding="utf-8", errors="replace") as file:
        return file.read()


def _fairing(fairing: Union[str, float]) -> grid_pb2.Fairing:
    if fairing == "tol":
        return grid_pb2.Fairing(mode=grid_pb2.FAIRING_MODE_TO_TOLERANCE)
    if isinstance(fairing, str) or not float(fairing) > 0.0:
        raise ValueError(f"fairing = {fairing!r}: give 'tol' or a positive weight")
    return grid_pb2.Fairing(mode=grid_pb2.FAIRING_MODE_WEIGHT, weight=float(fairing))


def _set_step(request: Message, revision: int, step: Optional[int]) -> None:
    """Sets the optional ``step`` of a Get/Evaluate request (not together with a revision)."""
    if step is None:
        return
    if revision != 0:
        raise ValueError(f"give revision ({revision}) or step ({step}), not both")
    request.step = _integer(step, "step")


def _integer(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{what} = {value!r}; must be an integer")
    return int(value)


def _non_negative_int(value: Any, what: str) -> int:
    number = _integer(value, what)
    if number < 0:
        raise ValueError(f"{what} = {value}; must not be negative")
    return number


def _finite(value: Any, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what} = {value!r}; must be a number") from None
    if not math.isfinite(number):
        raise ValueError(f"{what} = {value}; must be finite")
    return number


def _non_negative(value: Any, what: str) -> float:
    number = _finite(value, what)
    if number < 0.0:
        raise ValueError(f"{what} = {value}; must not be negative")
    return number


def _vector(values: Sequence[float], what: str, sizes: tuple[int, ...]) -> list[float]:
    try:
        numbers = [_finite(v, what) for v in values]
    except TypeError:
        raise ValueError(f"{what} = {values!r}; give {' or '.join(map(str, sizes))} numbers") \
            from None
    if len(numbers) not in sizes:
        raise ValueError(f"{what} = {list(values)}; give {' or '.join(map(str, sizes))} "
                         "numbers")
    return numbers


def _face_range(spec: FaceRangeLike, what: str) -> grid_pb2.FaceRange:
    """A FaceRange from a proto, a (block, face, begin, end) tuple or a dict."""
    if isinstance(spec, grid_pb2.FaceRange):
        return spec
    if isinstance(spec, Mapping):
        unknown = set(spec) - {"block", "face", "begin", "end"}
        if unknown or not {"block", "face", "begin", "end"} <= set(spec):
            raise ValueError(f"{what} = {dict(spec)}; give the keys block, face, begin, end")
        block, face, begin, end = spec["block"], spec["face"], spec["begin"], spec["end"]
    elif isinstance(spec, (tuple, list)) and len(spec) == 4:
        block, face, begin, end = spec
    else:
        raise ValueError(f"{what} = {spec!r}; give (block, face, begin, end)")
    if isinstance(face, str):
        key = face.lower().replace("_", "").replace("-", "")
        if key not in _FACES:
            raise ValueError(f"{what}: face = {face!r}; give one of {', '.join(_FACES)}")
        face = _FACES[key]
    elif face not in _FACES.values():
        raise ValueError(f"{what}: face = {face!r}; give one of {', '.join(_FACES)}")
    begin_e = _extents(begin, f"{what} begin", fill=0)
    end_e = _extents(end, f"{what} end", fill=0)
    for axis in "ijk":
        lo, hi = getattr(begin_e, axis), getattr(end_e, axis)
        if lo < 0 or hi < lo:
            raise ValueError(f"{what}: {axis} range [{lo}, {hi}] is not 0 <= begin <= end")
    return grid_pb2.FaceRange(block=_non_negative_int(block, f"{what} block"), face=face,
                              begin=begin_e, end=end_e)


def _boundary_selection(boundary: Any) -> service_pb2.BoundarySelection:
    """``boundary`` of :meth:`Client.deform` as a BoundarySelection."""
    selection = service_pb2.BoundarySelection()
    if boundary is None:
        return selection
    if isinstance(boundary, service_pb2.BoundarySelection):
        return boundary
    single = (isinstance(boundary, (str, grid_pb2.FaceRange, Mapping))
              or (isinstance(boundary, tuple) and len(boundary) == 4
                  and isinstance(boundary[0], (int, np.integer))))
    for q, item in enumerate([boundary] if single else list(boundary)):
        if isinstance(item, str):
            if item.lower() not in _KINDS:
                raise ValueError(f"boundary[{q}] = {item!r}; give wall, outer, interface or a "
                                 "face range")
            selection.kinds.append(_KINDS[item.lower()])
        else:
            selection.ranges.append(_face_range(item, f"boundary[{q}]"))
    if selection.kinds and selection.ranges:
        raise ValueError("boundary: give boundary kinds or face ranges, not both")
    return selection


def _block_list(blocks: Blocks) -> list[int]:
    if blocks is None:
        return []
    if isinstance(blocks, (int, np.integer)):
        return [int(blocks)]
    return [int(b) for b in blocks]


def _as_block(block: npt.ArrayLike, index: int) -> np.ndarray:
    """An upload block as a C-ordered little-endian float64 array (nk, nj, ni, s)."""
    array = np.asarray(block, dtype=np.float64)
    if not 2 <= array.ndim <= 4 or array.shape[-1] not in (2, 3):
        raise ValueError(f"blocks[{index}] has shape {array.shape}; expected (nk, nj, ni, s), "
                         "(nj, ni, s) or (ni, s) with s = 2 or 3")
    array = array.reshape((1,) * (4 - array.ndim) + array.shape)
    return np.ascontiguousarray(array, dtype=_wire.DOUBLE)


class _Chunk(NamedTuple):
    block: int
    field: int
    offset: int
    values: np.ndarray


def _decode_evaluate_response(data: bytes) -> Union[service_pb2.EvaluationHeader, _Chunk]:
    """An EvaluateGridResponse: the header as a proto, a chunk with its values as an array."""
    part: Union[service_pb2.EvaluationHeader, _Chunk, None] = None
    for number, wire_type, value in _wire.fields(data):
        if number == 1 and wire_type == _wire.LENGTH_DELIMITED:
            part = service_pb2.EvaluationHeader.FromString(value.tobytes())
        elif number == 2 and wire_type == _wire.LENGTH_DELIMITED:
            part = _decode_chunk(value)
    if part is None:
        raise ValueError("an EvaluateGridResponse with neither header nor chunk")
    return part


def _decode_chunk(data: memoryview) -> _Chunk:
    """An EvaluationChunk (fields: 1 block, 2 field, 3 offset, 4 values, 5 float_values)."""
    ints = {1: 0, 2: 0, 3: 0}
    floats = _wire.FloatFields()
    for number, wire_type, value in _wire.fields(data):
        if number in ints and wire_type == _wire.VARINT:
            ints[number] = _wire.signed(value)
        elif number == 4:
            floats.add(4, wire_type, value, _wire.DOUBLE)
        elif number == 5:
            floats.add(5, wire_type, value, _wire.FLOAT)
    values = floats.get(4, _wire.DOUBLE)
    if values.size == 0:
        values = floats.get(5, _wire.FLOAT)
    return _Chunk(ints[1], ints[2], ints[3], values)


def _assemble(messages: Iterable[Union[service_pb2.EvaluationHeader, _Chunk]],
              dtype: np.dtype) -> EvaluatedGrid:
    """Reassembles an EvaluateGrid stream into preallocated arrays."""
    result: Optional[EvaluatedGrid] = None
    targets: dict[tuple[int, int], np.ndarray] = {}  # (block, field) -> flat view
    missing = 0  # values announced but not received yet
    for part in messages:
        if isinstance(part, service_pb2.EvaluationHeader):
            if result is not None:
                raise _data_loss("a second header")
            s = part.spatial_dim
            result = EvaluatedGrid(part.revision, s)
            fields = list(_FIELD_NAMES.items())[:4 if part.derivatives else 1]
            for announced in part.blocks:
                if (announced.block, service_pb2.FIELD_POINTS) in targets:
                    raise _data_loss(f"block {announced.block} announced twice")
                e = announced.extents
                arrays = {attribute: np.empty((e.k, e.j, e.i, s), dtype=dtype)
                          for _, attribute in fields}
                for field, attribute in fields:
                    targets[announced.block, field] = arrays[attribute].reshape(-1)
                    missing += arrays[attribute].size
                result.append(EvaluatedBlock(announced.block, **arrays))
            continue
        if result is None:
            raise _data_loss("a chunk before the header")
        target = targets.get((part.block, part.field))
        end = part.offset + part.values.size
        if target is None or part.offset < 0 or end > target.size:
            raise _data_loss(f"a chunk (block {part.block}, field {part.field}, values "
                             f"[{part.offset}, {end})) that does not fit what the header "
                             "announced")
        target[part.offset:end] = part.values
        missing -= part.values.size
    if result is None:
        raise _data_loss("the stream ended without a header")
    if missing != 0:
        raise _data_loss(f"{missing} announced values did not arrive")
    return result


def _decode_points_response(data: bytes) -> EvaluatedPoints:
    """An EvaluatePointsResponse (1 revision, 2 spatial_dim, 3 points, 4-6 du, dv, dw)."""
    ints = {1: 0, 2: 0}
    floats = _wire.FloatFields()
    for number, wire_type, value in _wire.fields(data):
        if number in ints and wire_type == _wire.VARINT:
            ints[number] = _wire.signed(value)
        elif 3 <= number <= 6:
            floats.add(number, wire_type, value, _wire.DOUBLE)
    s = ints[2] or 1
    points, du, dv, dw = (floats.get(n, _wire.DOUBLE).reshape(-1, s) for n in range(3, 7))
    if du.size == 0:
        return EvaluatedPoints(ints[1], points)
    return EvaluatedPoints(ints[1], points, du, dv, dw)


# grpc.health.v1: Debian's python3-grpcio does not ship grpc_health, and the two messages are
# one field each, so they are encoded by hand: HealthCheckRequest {string service = 1;},
# HealthCheckResponse {ServingStatus status = 1;} (an enum, i.e. a varint).

def _encode_health_request(service: str) -> bytes:
    return _wire.length_delimited(1, service.encode()) if service else b""


def _decode_health_response(data: bytes) -> str:
    status = 0
    for number, wire_type, value in _wire.fields(data):
        if number == 1 and wire_type == _wire.VARINT:
            status = int(value)
    return _HEALTH_STATUS[status] if status < len(_HEALTH_STATUS) else str(status)
