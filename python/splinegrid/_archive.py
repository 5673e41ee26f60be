"""Archives (``.sgrid`` files): the Client's ExportGrid and ImportArchive calls and the checks
of an archive's record sequence they make on the way."""

from __future__ import annotations

import contextlib
import os
import threading
from typing import Any, Callable, Iterator, Optional, Union

import grpc

from splinegrid import _wire
from splinegrid import records
from splinegrid._args import _grid_id, grid_name
from splinegrid._calls import _Calls
from splinegrid._transport import _as, _Attempt, _routing_grid
from splinegrid.errors import _data_loss
from splinegrid.results import ArchiveSummary
from splinegrid.v1 import archive_pb2, grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

_GRID_ID_FIELD = 1  # ImportArchiveRequest.grid_id (first message only)
_RECORD_FIELD = 2  # ImportArchiveRequest.record


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
    for number, _, value in _wire.fields(data):
        if number == 1 and isinstance(value, memoryview):
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


def _import_archive_request(payload: bytes, first: bool, new_id: str) -> bytes:
    """The ImportArchiveRequest carrying the record ``payload``; the first one also carries the
    grid's new id when one is given ("": the archive's own)."""
    message = _wire.length_delimited(_RECORD_FIELD, payload)
    if first and new_id:
        message = _wire.length_delimited(_GRID_ID_FIELD, new_id.encode()) + message
    return message


class _ArchiveCalls(_Calls):
    """The Client's archive calls (ExportGrid, ImportArchive): raw ArchiveRecord bytes
    between the stream and the record file."""

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
        def attempt(a: _Attempt) -> _ArchiveShape:
            # Every attempt writes the file from its start (a retried export repeats the
            # stream).
            shape = _ArchiveShape(lambda what: _data_loss(
                f"the export of {request.name}: {what}"))
            with records.RecordWriter(temp) as writer:
                call = self._export_grid(request, timeout=a.timeout, metadata=a.metadata)
                try:
                    for payload in call:
                        shape.add(payload)
                        writer.append(payload)
                except BaseException:
                    call.cancel()
                    raise
                shape.complete()
            return shape

        try:
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
                            yield _import_archive_request(payload, reader.record == 1, new_id)
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
