"""Framed record files, as core/io/record_file.h writes and reads them (.sgrid archives).

Layout: the magic line ``MAGIC`` once, then per record a little-endian uint32 payload length,
a little-endian uint32 CRC-32 of the payload (zlib's polynomial: ``zlib.crc32``) and the
payload. A file cut at a record boundary reads as a clean shorter file; anywhere else it is
reported as truncated. The framing is proto-agnostic: an .sgrid archive holds one serialized
``splinegrid.v1.ArchiveRecord`` per record (a header, source chunks, revisions), and the count
of those is the archive's business (``Client.import_archive`` checks it).

    with RecordWriter("grid.sgrid") as writer:
        writer.append(b"payload")
    for payload in read_records("grid.sgrid"):
        ...
"""

from __future__ import annotations

import os
import struct
import zlib
from typing import BinaryIO, Iterator, Optional, Union

__all__ = ["MAGIC", "MAX_RECORD_BYTES", "RecordFileError", "RecordReader", "RecordWriter",
           "frame_record", "read_records"]

MAGIC = b"splinegrid-records\n"
MAX_RECORD_BYTES = 64 << 20  # the C++ reader's default limit
_FRAME = struct.Struct("<II")  # length, CRC-32
_READ_CHUNK = 1 << 20

PathLike = Union[str, "os.PathLike[str]"]


class RecordFileError(ValueError):
    """A file that is not a record file, or a damaged or truncated one. ``path``, ``record``
    (0-based index of the failed record, None for the magic line) and ``offset`` (its byte
    offset) say where."""

    def __init__(self, message: str, path: str, record: Optional[int] = None,
                 offset: Optional[int] = None) -> None:
        super().__init__(message)
        self.path = path
        self.record = record
        self.offset = offset


def frame_record(payload: bytes) -> bytes:
    """The 8-byte frame header (length, CRC-32) followed by ``payload``."""
    if len(payload) > 0xFFFFFFFF:
        raise ValueError(f"a record of {len(payload)} bytes exceeds the 4 GiB record limit")
    return _FRAME.pack(len(payload), zlib.crc32(payload)) + bytes(payload)


class RecordWriter:
    """Writes a record file from the start (creates or truncates ``path``). Buffered; nothing is
    durable before ``close(sync=True)``. A context manager: leaving the block normally closes
    with sync, leaving it by an exception closes without."""

    def __init__(self, path: PathLike) -> None:
        self.path = os.fspath(path)
        self._file: Optional[BinaryIO] = open(self.path, "wb")
        self._file.write(MAGIC)

    def append(self, payload: Union[bytes, bytearray, memoryview]) -> None:
        """Appends one framed record."""
        if self._file is None:
            raise ValueError(f"record file '{self.path}' is closed")
        payload = bytes(payload)
        self._file.write(_FRAME.pack(len(payload), zlib.crc32(payload)))
        self._file.write(payload)

    def close(self, sync: bool = True) -> None:
        """Flushes and, with ``sync``, fsyncs the file so its bytes survive a crash; closes."""
        if self._file is None:
            return
        file, self._file = self._file, None
        try:
            file.flush()
            if sync:
                os.fsync(file.fileno())
        finally:
            file.close()

    def __enter__(self) -> RecordWriter:
        return self

    def __exit__(self, exc_type: object, *rest: object) -> None:
        self.close(sync=exc_type is None)


class RecordReader:
    """Reads a record file front to back: an iterator of payloads (bytes). Opening checks the
    magic line; a record announcing more than ``max_record_bytes`` is refused before it is
    read. Faults raise :class:`RecordFileError` naming the path, the record and its offset.
    ``offset`` is the byte offset of the next record (just past the last complete one)."""

    def __init__(self, path: PathLike, max_record_bytes: int = MAX_RECORD_BYTES) -> None:
        self.path = os.fspath(path)
        self.max_record_bytes = max_record_bytes
        self._file: BinaryIO = open(self.path, "rb")
        start = self._file.read(len(MAGIC))
        if start != MAGIC:
            self._file.close()
            raise RecordFileError(
                f"'{self.path}' is not a record file (it does not start with the line "
                f"\"{MAGIC.decode().strip()}\")", self.path)
        self.offset = len(MAGIC)
        self.record = 0

    def _fault(self, what: str) -> RecordFileError:
        return RecordFileError(f"record file '{self.path}': record {self.record} at byte offset "
                               f"{self.offset}: {what}", self.path, self.record, self.offset)

    def __iter__(self) -> RecordReader:
        return self

    def __next__(self) -> bytes:
        header = self._file.read(_FRAME.size)
        if not header:
            raise StopIteration  # clean end: the file ends right after a record
        if len(header) < _FRAME.size:
            raise self._fault(f"truncated record: the file ends {len(header)} bytes into the "
                              "8-byte frame header")
        length, crc = _FRAME.unpack(header)
        if length > self.max_record_bytes:
            raise self._fault(f"announced length {length} bytes exceeds the limit of "
                              f"{self.max_record_bytes} bytes")
        pieces = []
        have = 0
        while have < length:  # memory follows the bytes present, not the announced length
            piece = self._file.read(min(length - have, _READ_CHUNK))
            if not piece:
                raise self._fault(f"truncated record: {have} of {length} payload bytes present")
            pieces.append(piece)
            have += len(piece)
        payload = b"".join(pieces)
        actual = zlib.crc32(payload)
        if actual != crc:
            raise self._fault(f"CRC mismatch: stored 0x{crc:08x}, payload has 0x{actual:08x}")
        self.offset += _FRAME.size + length
        self.record += 1
        return payload

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> RecordReader:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def read_records(path: PathLike, max_record_bytes: int = MAX_RECORD_BYTES) -> Iterator[bytes]:
    """The payloads of the record file at ``path`` in order (see :class:`RecordReader`)."""
    with RecordReader(path, max_record_bytes) as reader:
        yield from reader
