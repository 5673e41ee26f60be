"""What a grid file is, decided from its first bytes before anything is uploaded, so that
:meth:`Client.import_file` sends a file once, to the one call that takes it.

- ``ARCHIVE``: a ``.sgrid`` record file (its magic line ``splinegrid-records``, see
  :mod:`splinegrid.records`) -> ImportArchive.
- ``CGNS``: an HDF5 file (signature ``\\x89HDF\\r\\n\\x1a\\n``, at offset 0 or a power of two
  from 512 on, as HDF5 places it after a user block) or an ADF file (``@(#)ADF Database``).
- ``PLOT3D``: anything else. Plot3D has no signature, so it is the remaining kind; the server
  reads it and answers INVALID_ARGUMENT for a file that is not a Plot3D grid.

The contents decide, not the extension: a renamed archive is still an archive.
"""

from __future__ import annotations

import enum
import os
from typing import Union

from splinegrid import records

__all__ = ["FileKind", "detect_file_kind", "HDF5_SIGNATURE", "ADF_SIGNATURE"]

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
ADF_SIGNATURE = b"@(#)ADF Database"
_HDF5_OFFSETS = (0, 512, 1024, 2048, 4096, 8192)  # where HDF5 looks for its superblock
PROBE_BYTES = _HDF5_OFFSETS[-1] + len(HDF5_SIGNATURE)


class FileKind(enum.Enum):
    """The kinds of grid files the service imports."""

    PLOT3D = "plot3d"
    ARCHIVE = "archive"
    CGNS = "cgns"


def detect_file_kind(path_or_head: Union[str, "os.PathLike[str]", bytes, memoryview]
                     ) -> FileKind:
    """The kind of the file at a path, or of a file whose bytes (at least its first
    ``PROBE_BYTES``, or all of it) are given. OSError for a path that cannot be read."""
    if isinstance(path_or_head, (bytes, bytearray, memoryview)):
        head = bytes(path_or_head[:PROBE_BYTES])
    else:
        with open(path_or_head, "rb") as file:
            head = file.read(PROBE_BYTES)
    if head.startswith(records.MAGIC):
        return FileKind.ARCHIVE
    if any(head[at:at + len(HDF5_SIGNATURE)] == HDF5_SIGNATURE for at in _HDF5_OFFSETS):
        return FileKind.CGNS
    if ADF_SIGNATURE in head[:64]:
        return FileKind.CGNS
    return FileKind.PLOT3D
