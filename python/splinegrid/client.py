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

Bulk data (uploads, evaluation chunks, EvaluatePoints, control points) is moved between wire
bytes and NumPy arrays without a step per value, see ``_wire``.

Modules
    ``client`` (this one: the calls), ``errors``, ``retry``, ``results`` (NumPy-backed
    results), ``watch``, ``filekind`` (what a file is, decided before any upload), ``plot3d``
    (Plot3D headers and the two-plane check), ``records`` (``.sgrid`` framing); private:
    ``_args`` (argument checks and conversions), ``_transport`` (attempts, metadata, routing),
    ``_evaluation`` and ``_splines`` (bulk decoding), ``_archive``, ``_wire``, ``_stubs``
    (generation of ``splinegrid.v1``).
"""


from __future__ import annotations

import contextlib
import os
import threading
import time
from typing import (Any, Callable, Iterable, Iterator, Literal, Optional, Sequence,
                    TypeVar, Union, overload)

import grpc
import numpy as np
import numpy.typing as npt
from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid import records
from splinegrid._archive import _ArchiveShape, _export_record_bytes, _sync_directory
from splinegrid._args import (MAX_CHECK_LEVEL, _LAYER_METHODS, _PROPAGATIONS, Blocks,
                              ControlDisplacements, FaceKindsLike, PathOrBytes, Triple,
                              _airfoil_text, _as_block, _block_list, _boundary_points_motion,
                              _boundary_selection, _control_motion, _extents, _face_kinds,
                              _fairing, _finite, _fit_spec, _grid_id, _integer, _non_negative,
                              _non_negative_int, _read_bytes, _rigid_motion, _set_step,
                              grid_name)
from splinegrid._evaluation import (_assemble, _decode_evaluate_response,
                                    _decode_points_response)
from splinegrid._splines import decode_full_grid
from splinegrid._transport import (GRID_ROUTING_HEADER, SERVICE, _as, _Attempt,
                                   _decode_health_response, _encode_health_request, _read_pem,
                                   _routing_grid, _routing_metadata, _serialize, Metadata)
from splinegrid.filekind import FileKind, detect_file_kind
from splinegrid.errors import SplinegridError, _code, _data_loss, _translated_errors
from splinegrid.results import (ArchiveSummary, BoundaryPoints, EvaluatedBlock, EvaluatedGrid,
                                EvaluatedPoints, FaceRangeLike, FullGrid, SplineArrays,
                                WallCurvatureLine)
from splinegrid.retry import RetryPolicy
from splinegrid.watch import RevisionWatch
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

__all__ = ["Client"]  # the package (splinegrid/__init__.py) exports the rest from their modules


UPLOAD_CHUNK_BYTES = 1 << 20  # Plot3D bytes or point coordinates per upload message

MAX_RECEIVE_BYTES = 8 << 20

LIST_PAGE_SIZE = 500

POINTS_BATCH_BYTES = 3 << 20  # EvaluatePoints request or response size per call
_PLOT3D_CHUNK_FIELD = 2  # ImportGridRequest.plot3d_chunk
_CGNS_CHUNK_FIELD = 4  # ImportGridRequest.cgns_chunk

_T = TypeVar("_T")


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

    # Import: every upload of a file goes through _upload_file, once.

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

    def import_plot3d(self, path_or_bytes: PathOrBytes, grid_id: str = "",
                      display_name: str = "",
                      planar_view: Optional[bool] = None) -> grid_pb2.Grid:
        """Uploads a Plot3D file (a path, or its bytes) as a new grid; returns it (BASIC view).

        The file goes in 1 MiB pieces after an ImportHeader, once. ``grid_id`` is the new
        name's last segment ("" lets the server pick). ``planar_view=True`` stores the 2-D view
        of a grid held as two planes (CFL3D style) and fails for any other grid; ``False``
        stores the file as read. ``None`` (the default) lets the server decide from the file it
        parsed: the planar view exactly when every block is a two-plane block
        (``planar_view_if_two_planes``; ``grid.source.format`` then ends in ", planar view").
        """
        data = _read_bytes(path_or_bytes)
        source = service_pb2.Plot3dSource(total_bytes=len(data),
                                          planar_view=planar_view is True,
                                          planar_view_if_two_planes=planar_view is None)
        header = service_pb2.ImportHeader(grid_id=_grid_id(grid_id), display_name=display_name,
                                          plot3d=source)
        return self._upload_file(header, _PLOT3D_CHUNK_FIELD, data)

    def import_cgns(self, path_or_bytes: PathOrBytes, grid_id: str = "",
                    display_name: str = "") -> grid_pb2.Grid:
        """Uploads a CGNS file (HDF5 or ADF; a path, or its bytes) as a new grid; returns it
        (BASIC view). The server decodes it in a separate process: structured zones become
        blocks, boundary conditions (families resolved) the default boundary kinds of fits
        (``grid.source.boundaries``; its ``notes`` say what the import mapped with a choice or
        left out). A file it cannot read raises INVALID_ARGUMENT (``cgns: ...``)."""
        data = _read_bytes(path_or_bytes)
        source = service_pb2.CgnsSource(total_bytes=len(data))
        header = service_pb2.ImportHeader(grid_id=_grid_id(grid_id), display_name=display_name,
                                          cgns=source)
        return self._upload_file(header, _CGNS_CHUNK_FIELD, data)

    def _upload_file(self, header: service_pb2.ImportHeader, chunk_field: int,
                     data: memoryview) -> grid_pb2.Grid:
        """ImportGrid of a file: ``header`` (its ``source`` says the format and size), then
        the file's bytes in pieces of UPLOAD_CHUNK_BYTES as ImportGridRequest field
        ``chunk_field`` (plot3d_chunk = 2, cgns_chunk = 4), encoded without copying into
        messages. Retried
        whole under the retry policy; the routing header is the header's grid_id."""

        def requests() -> Iterator[Union[bytes, Message]]:
            yield service_pb2.ImportGridRequest(header=header)
            for at in range(0, len(data), UPLOAD_CHUNK_BYTES):
                yield _wire.length_delimited(chunk_field,
                                             data[at:at + UPLOAD_CHUNK_BYTES].tobytes())

        return self._call(lambda a: _as(grid_pb2.Grid, self._import_grid(
            requests(), timeout=a.timeout, metadata=a.metadata)), header.grid_id)

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

        return self._call(lambda a: _as(grid_pb2.Grid, self._import_grid(
            requests(), timeout=a.timeout, metadata=a.metadata)), header.grid_id)

    # Fit and the grid resource

    def fit(self, name: str, control_counts: Optional[Triple] = None,
            tolerance: Optional[float] = None, order: int = 4,
            max_controls: int = 0,
            boundary_tolerances: Optional[dict[str, float]] = None,
            fairing: Union[None, str, float] = None,
            allow_folds: bool = False,
            ref_length: Optional[float] = None,
            face_kinds: Optional[FaceKindsLike] = None) -> service_pb2.FitGridResponse:
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
        return self._unary(self.stub.FitGrid, request, service_pb2.FitGridResponse)

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
        return self._unary(self.stub.FairGrid, request, service_pb2.FitGridResponse)

    def generate(self, name: str = "", airfoil: Union[None, str, bytes,
                                                      "os.PathLike[str]"] = None,
                 points: Optional[npt.ArrayLike] = None,
                 stored_wall: Union[None, str, tuple[Any, ...]] = None,
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
            wall: tuple[Any, ...] = ((stored_wall,) if isinstance(stored_wall, str)
                                     else tuple(stored_wall or ()))
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
        for field, number in (("first_height", first_height), ("distance", distance),
                              ("fit_tolerance", fit_tolerance)):
            if number is not None:  # NaN and non-positive values: the server names them
                setattr(request, field, float(number))
        if orthogonalize is not None:
            request.orthogonalize = bool(orthogonalize)
        if any(v is not None for v in (control_counts, tolerance, boundary_tolerances, fairing)):
            request.spec.CopyFrom(_fit_spec(control_counts, tolerance, order, max_controls,
                                            boundary_tolerances, fairing))
            if not request.spec.HasField("resolution"):
                request.spec.boundary_tolerances.SetInParent()
        return self._unary(self.stub.GenerateGrid, request,
                           service_pb2.GenerateGridResponse)

    def wall_curvature(self, name: str, revision: int = 0, level: int = 2,
                       blocks: Blocks = None) -> list[WallCurvatureLine]:
        """Curvature along every wall grid line of revision ``revision`` (0: latest), sampled at
        refinement level ``level`` (2**level - 1 samples between grid points)."""
        request = service_pb2.GetWallCurvatureRequest(
            name=grid_name(name), revision=revision, refinement_level=level,
            blocks=_block_list(blocks))
        response = self._unary(self.stub.GetWallCurvature, request,
                               service_pb2.GetWallCurvatureResponse)
        dim = response.spatial_dim
        return [WallCurvatureLine(
            block=line.block, direction=line.direction,
            start=(line.start.i, line.start.j, line.start.k),
            arc_length=np.asarray(line.arc_length, dtype=np.float64),
            points=np.asarray(line.points, dtype=np.float64).reshape(-1, dim),
            curvature=np.asarray(line.curvature, dtype=np.float64)) for line in response.lines]

    @overload
    def get(self, name: str, revision: int = 0, full: Literal[False] = False,
            blocks: Iterable[int] = (), step: Optional[int] = None) -> grid_pb2.Grid: ...

    @overload
    def get(self, name: str, revision: int = 0, *, full: Literal[True],
            blocks: Iterable[int] = (), step: Optional[int] = None) -> FullGrid: ...

    def get(self, name: str, revision: int = 0, full: bool = False,
            blocks: Iterable[int] = (), step: Optional[int] = None
            ) -> Union[grid_pb2.Grid, FullGrid]:
        """The grid with revision ``revision`` (0: latest): the ``Grid`` proto (BASIC view).

        ``full=True`` returns a :class:`FullGrid` instead: the FULL view's proto and the
        revision's splines as NumPy arrays (:class:`SplineArrays`: control points
        ``(nck, ncj, nci, s)``, knot vectors, point distributions), of ``blocks`` only when
        given, decoded without a step per value. ``step``: instead of a revision, the latest
        revision stamped with this solver time step (see :meth:`deform`); NOT_FOUND if there
        is none."""
        request = service_pb2.GetGridRequest(
            name=grid_name(name), revision=revision, blocks=list(blocks),
            view=service_pb2.GRID_VIEW_FULL if full else service_pb2.GRID_VIEW_BASIC)
        _set_step(request, revision, step)
        if not full:
            return self._unary(self.stub.GetGrid, request, grid_pb2.Grid)
        data = self._unary(self._get_grid_bytes, request, bytes)
        return decode_full_grid(data)

    def list(self) -> list[grid_pb2.Grid]:
        """Every grid (BASIC view), ordered by name, following the pages."""
        grids: list[grid_pb2.Grid] = []
        request = service_pb2.ListGridsRequest(page_size=LIST_PAGE_SIZE)
        while True:
            response = self._unary(self.stub.ListGrids, request,
                                   service_pb2.ListGridsResponse)
            grids.extend(response.grids)
            if not response.next_page_token:
                return grids
            request.page_token = response.next_page_token

    def delete(self, name: str) -> None:
        self._unary(self.stub.DeleteGrid, service_pb2.DeleteGridRequest(name=grid_name(name)),
                    object)

    # Deformation (fluid-structure coupling)

    def deform(self, name: str, rotate_degrees: Optional[float] = None,
               about: Optional[Sequence[float]] = None,
               axis: Optional[Sequence[float]] = None,
               translate: Optional[Sequence[float]] = None,
               boundary: Union[None, str, FaceRangeLike,
                               Iterable[Union[str, FaceRangeLike]]] = None,
               reference_revision: int = 0, base_revision: int = 0, time: float = 0.0,
               step: int = 0, check_level: int = 0,
               control_displacements: Optional[ControlDisplacements] = None,
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
            _rigid_motion(request.rigid, rotate_degrees, about, axis, translate)
        elif control_displacements is not None:
            _control_motion(request.controls, control_displacements)
        else:
            _boundary_points_motion(request.boundary_points, boundary_points or ())
        return self._unary(self.stub.DeformGrid, request, service_pb2.DeformGridResponse)

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
            parts.append(self._unary(self._evaluate_points, request, EvaluatedPoints,
                                     _routing_grid(head)))
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
        file = os.fspath(path)
        new_id = _grid_id(name or "")

        def fault(what: str) -> records.RecordFileError:
            return records.RecordFileError(f"'{file}': {what}", file)

        # The header first: a file that is not an archive is refused before any call, and the
        # archive's id routes the call when no new one is given.
        with records.RecordReader(file) as reader:
            first = next(reader, None)
        shape = _ArchiveShape(fault)
        if first is None:
            shape.complete()  # raises: no records
        else:
            shape.add(first)

        def attempt(a: _Attempt) -> grid_pb2.Grid:
            started = threading.Event()
            failure: list[Exception] = []
            box: dict[str, Any] = {}

            def requests() -> Iterator[bytes]:
                started.wait()
                try:
                    shape = _ArchiveShape(fault)
                    with records.RecordReader(file) as reader:
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
                return _as(grid_pb2.Grid, box["call"].result())
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
            return _as(str, self._health_check(service, timeout=self.timeout))
