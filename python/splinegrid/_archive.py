"""Checks of an archive's record sequence (export and import of ``.sgrid`` files)."""

from __future__ import annotations

import contextlib
import os
from typing import Callable

from splinegrid import _wire
from splinegrid.results import ArchiveSummary
from splinegrid.v1 import archive_pb2


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
