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
    A call that breaks off (UNAVAILABLE: a replica died, a balancer had no upstream, the server
    is restarting; INTERNAL "RST_STREAM": a balancer whose upstream died mid-stream reset it)
    is made again after a growing, jittered wait (:class:`RetryPolicy`): every call from its
    start (``evaluate`` and ``export_grid`` drop what had arrived, uploads are sent again
    whole), and ``watch`` resumed after the last revision received (:class:`RevisionWatch`).
    ``health`` is not retried. An attempt whose answer was lost may still have been
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

Bulk data (uploads, evaluation chunks, EvaluatePoints, control points) is moved between wire
bytes and NumPy arrays without a step per value, see ``_wire``.

Modules
    ``client`` (this one: the :class:`Client`, its connection and the call machinery),
    ``errors``, ``retry``, ``results`` (NumPy-backed results), ``watch``, ``filekind`` (what a
    file is, decided before any upload), ``records`` (``.sgrid`` framing); private: the
    families of calls the Client is made of, each building its requests from the arguments
    (checked before any call) and reading the responses: ``_upload_calls`` (ImportGrid),
    ``_archive`` (ExportGrid, ImportArchive), ``_grid_calls`` (get, list, delete, watch),
    ``_fit_calls`` (fit, fair), ``_generate_calls``, ``_deform_calls``, ``_evaluation_calls``
    (evaluate, evaluate_points, wall_curvature), on what ``_calls`` declares of the Client;
    ``_args`` (argument checks and conversions), ``_transport`` (attempts, metadata, routing),
    ``_evaluation`` and ``_splines`` (bulk decoding), ``_wire``, ``_stubs`` (generation of
    ``splinegrid.v1``).
"""


from __future__ import annotations

import contextlib
import operator
import os
import threading
import time
from typing import Any, Callable, Optional, TypeVar, Union

import grpc
from google.protobuf.message import Message

from splinegrid._archive import _ArchiveCalls, _export_record_bytes
from splinegrid._deform_calls import _DeformCalls
from splinegrid._evaluation import _decode_evaluate_response, _decode_points_response
from splinegrid._evaluation_calls import _EvaluationCalls
from splinegrid._evaluation_calls import POINTS_BATCH_BYTES as POINTS_BATCH_BYTES
from splinegrid._fit_calls import _FitCalls
from splinegrid._generate_calls import _GenerateCalls
from splinegrid._grid_calls import _GridCalls
from splinegrid._grid_calls import LIST_PAGE_SIZE as LIST_PAGE_SIZE
from splinegrid._transport import (GRID_ROUTING_HEADER, SERVICE, _as, _Attempt,
                                   _decode_health_response, _encode_health_request, _read_pem,
                                   _routing_grid, _routing_metadata, _serialize, Metadata)
from splinegrid._upload_calls import _UploadCalls
from splinegrid._upload_calls import UPLOAD_CHUNK_BYTES as UPLOAD_CHUNK_BYTES
from splinegrid.filekind import FileKind, detect_file_kind
from splinegrid.errors import SplinegridError, _broke_off, _translated_errors
from splinegrid.retry import RetryPolicy
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

# The sizes of the calls (UPLOAD_CHUNK_BYTES, LIST_PAGE_SIZE, POINTS_BATCH_BYTES) live with
# them; the explicit re-exports above keep them importable from here, as before the split.
__all__ = ["Client"]  # the package (splinegrid/__init__.py) exports the rest from their modules

MAX_RECEIVE_BYTES = 8 << 20

_T = TypeVar("_T")


class Client(_UploadCalls, _ArchiveCalls, _GridCalls, _FitCalls, _GenerateCalls, _DeformCalls,
             _EvaluationCalls):
    """A connection to a splinegrid server (a plaintext or TLS channel to ``target``; default:
    the environment variable ``SPLINEGRID_SERVER``, else ``localhost:50051``).

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

    ``max_evaluation_bytes``: the most bytes of arrays one :meth:`evaluate` may assemble in this
    process (None, the default: no limit, as ``ClientOptions::max_evaluation_bytes`` of the C++
    client). A larger evaluation is refused with RESOURCE_EXHAUSTED as soon as its header
    arrives, before anything is allocated, instead of growing the process until the machine
    runs out of memory.
    """

    def __init__(self, target: Optional[str] = None, timeout: float = 120.0,
                 retry: Optional[RetryPolicy] = None, *, token: Optional[str] = None,
                 tls: bool = False, tls_ca: Optional[str] = None,
                 tls_cert: Optional[str] = None, tls_key: Optional[str] = None,
                 tls_server_name: Optional[str] = None,
                 max_evaluation_bytes: Optional[int] = None) -> None:
        if not timeout > 0:
            raise ValueError(f"timeout = {timeout}; must be positive")
        self.max_evaluation_bytes: Optional[int] = None
        if max_evaluation_bytes is not None:
            try:  # an int or NumPy integer; not a float, str or bool
                cap = operator.index(max_evaluation_bytes)
            except TypeError:
                cap = 0
            if isinstance(max_evaluation_bytes, bool) or cap <= 0:
                raise ValueError(f"max_evaluation_bytes = {max_evaluation_bytes!r}; must be a "
                                 "positive int (None: no limit)")
            self.max_evaluation_bytes = cap
        if target is None:
            target = os.environ.get("SPLINEGRID_SERVER") or "localhost:50051"
        if token is None:
            token = os.environ.get("SPLINEGRID_TOKEN", "")
        if token and not (token.isascii() and token.isprintable() and " " not in token):
            # Never repeat the token itself.
            raise ValueError("token: must be printable ASCII without blanks")
        if (tls_cert is None) != (tls_key is None):
            raise ValueError("tls_cert and tls_key: give both (a client certificate) or neither")
        self._auth: Metadata = (("authorization", f"Bearer {token}"),) if token else ()
        self.target = target
        self.timeout = timeout
        self.retry = RetryPolicy() if retry is None else retry
        options: list[tuple[str, Union[int, str]]] = [
            ("grpc.max_receive_message_length", MAX_RECEIVE_BYTES)]
        if self.retry.max_attempts > 1:
            # gRPC's own reconnect backoff starts at 1 s: a restarted server would be reached
            # only after the retries are spent. Reconnect at the retry policy's pace instead.
            options += [("grpc.initial_reconnect_backoff_ms",
                         max(1, int(self.retry.initial_backoff * 1000))),
                        ("grpc.max_reconnect_backoff_ms",
                         max(1, int(self.retry.max_backoff * 1000)))]
        self._tls = (tls or tls_ca is not None or tls_cert is not None
                     or tls_server_name is not None)
        self._client_cert = tls_cert is not None
        if self._tls:
            credentials = grpc.ssl_channel_credentials(
                root_certificates=_read_pem(tls_ca, "tls_ca"),
                private_key=_read_pem(tls_key, "tls_key"),
                certificate_chain=_read_pem(tls_cert, "tls_cert"))
            if tls_server_name:
                options.append(("grpc.ssl_target_name_override", tls_server_name))
            self._channel = grpc.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(target, options=options)
        self.stub = service_grpc.SplineGridStub(self._channel)  # type: ignore[no-untyped-call]
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
        # The FULL view's control points go from the wire bytes to NumPy (see _splines).
        self._get_grid_bytes = self._channel.unary_unary(
            f"/{SERVICE}/GetGrid", request_serializer=_serialize, response_deserializer=None)
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
        """Runs ``attempt`` (one try of a call, given its timeout and metadata, from scratch)
        until it does not break off (``errors._broke_off``) or ``self.retry`` gives up; all
        attempts share the deadline ``self.timeout`` from now. grpc.RpcError ->
        SplinegridError (chained; the message says the attempt when there were retries)."""
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
                if _broke_off(error):
                    wait = next(waits, None)
                if wait is None or time.monotonic() + wait >= deadline:
                    translated = SplinegridError.from_rpc_error(error)
                    if attempts > 1:
                        translated = SplinegridError(
                            translated.code, f"{translated.message} [attempt {attempts}; each "
                            "earlier one ended UNAVAILABLE or was reset, and was made again]")
                    # A TLS server closes a plaintext connection at once, and a server that
                    # asks for client certificates a TLS connection without one.
                    hint = ("if it uses TLS, give its CA: tls_ca=" if not self._tls else
                            "if it asks for client certificates (mTLS), give yours: tls_cert= "
                            "and tls_key=" if not self._client_cert else None)
                    if (hint and translated.code == "UNAVAILABLE"
                            and "Socket closed" in translated.message):
                        translated = SplinegridError(
                            translated.code,
                            f"{translated.message} (the server closed the connection: {hint})")
                    # gRPC's own words when the client's deadline fires first.
                    if (translated.code == "DEADLINE_EXCEEDED"
                            and translated.message == "Deadline Exceeded"):
                        translated = SplinegridError(
                            translated.code, "the call's deadline passed before its answer "
                            f"came (the client's timeout, {self.timeout} s: timeout=)")
                    # A plaintext server answers a TLS handshake with bytes that are no TLS
                    # record (OpenSSL: "wrong version number").
                    if (self._tls and translated.code == "UNAVAILABLE"
                            and "wrong version number" in translated.message):
                        translated = SplinegridError(
                            translated.code,
                            f"{translated.message} (the server answered the TLS handshake in "
                            "plaintext: it does not use TLS; connect without tls_ca=)")
                    raise translated from error
            self._pause_before_retry(wait)

    def _metadata(self, grid: str) -> Optional[Metadata]:
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

    def _unary(self, method: Callable[..., Any], request: Union[bytes, Message],
               response: type[_T], grid: Optional[str] = None) -> _T:
        """One unary call with :meth:`_call`; ``grid`` (default: the request's) routes it.
        ``response`` is the type the method's deserializer returns (checked: the stubs are
        untyped)."""
        if grid is None:
            grid = _routing_grid(request)
        return self._call(lambda a: _as(response, method(request, timeout=a.timeout,
                                                         metadata=a.metadata)), grid)

    # Import by what the file is: the uploads are _upload_calls' and _archive's.

    def import_file(self, path: Union[str, "os.PathLike[str]"], grid_id: str = "",
                    display_name: Optional[str] = None) -> grid_pb2.Grid:
        """Imports the grid file at ``path`` as a new grid by what the file is, decided from
        its contents before anything is sent (:func:`splinegrid.filekind.detect_file_kind`):
        an ``.sgrid`` archive goes to :meth:`import_archive` (``grid_id`` "" keeps the
        archive's id), a CGNS file to :meth:`import_cgns`, anything else to
        :meth:`import_plot3d` (the server stores the planar view of two-plane files). ``display_name`` defaults to the
        file's name (Plot3D, CGNS). Returns the grid (BASIC view)."""
        kind = detect_file_kind(path)
        if kind is FileKind.ARCHIVE:
            return self.import_archive(path, name=grid_id or None)
        name = os.path.basename(os.fspath(path)) if display_name is None else display_name
        if kind is FileKind.CGNS:
            return self.import_cgns(path, grid_id=grid_id, display_name=name)
        return self.import_plot3d(path, grid_id=grid_id, display_name=name)

    # Health

    def health(self, service: str = SERVICE) -> str:
        """The grpc.health.v1 status of ``service`` ("" = the whole server): "SERVING",
        "NOT_SERVING", ... A service the server does not know raises NOT_FOUND."""
        with _translated_errors():  # not retried: a probe answers for now
            return _as(str, self._health_check(service, timeout=self.timeout))
