"""Uploads of new grids (ImportGrid): a Plot3D or CGNS file's bytes after an ImportHeader, or
point blocks as PointChunk messages. The requests are built here without a call (the pieces are
encoded without copying into messages, see ``_wire``); every upload is sent whole, once, and
again whole when it is retried."""

from __future__ import annotations

from typing import Iterator, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid._args import PathOrBytes, _as_block, _grid_id, _read_bytes
from splinegrid._calls import _Calls
from splinegrid._transport import _as
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

UPLOAD_CHUNK_BYTES = 1 << 20  # Plot3D bytes or point coordinates per upload message
_PLOT3D_CHUNK_FIELD = 2  # ImportGridRequest.plot3d_chunk
_CGNS_CHUNK_FIELD = 4  # ImportGridRequest.cgns_chunk
_POINTS_FIELD = 3  # ImportGridRequest.points (a PointChunk)
_COORDINATES_FIELD = 2  # PointChunk.coordinates (packed doubles)


def _plot3d_header(size: int, grid_id: str, display_name: str,
                   planar_view: Optional[bool]) -> service_pb2.ImportHeader:
    """The ImportHeader of a Plot3D file of ``size`` bytes (see Client.import_plot3d)."""
    source = service_pb2.Plot3dSource(total_bytes=size, planar_view=planar_view is True,
                                      planar_view_if_two_planes=planar_view is None)
    return service_pb2.ImportHeader(grid_id=_grid_id(grid_id), display_name=display_name,
                                    plot3d=source)


def _cgns_header(size: int, grid_id: str, display_name: str) -> service_pb2.ImportHeader:
    """The ImportHeader of a CGNS file of ``size`` bytes."""
    return service_pb2.ImportHeader(grid_id=_grid_id(grid_id), display_name=display_name,
                                    cgns=service_pb2.CgnsSource(total_bytes=size))


def _file_requests(header: service_pb2.ImportHeader, chunk_field: int,
                   data: memoryview) -> Iterator[Union[bytes, Message]]:
    """ImportGridRequests of a file: ``header``, then the file's bytes in pieces of
    UPLOAD_CHUNK_BYTES as field ``chunk_field`` (plot3d_chunk = 2, cgns_chunk = 4)."""
    yield service_pb2.ImportGridRequest(header=header)
    for at in range(0, len(data), UPLOAD_CHUNK_BYTES):
        yield _wire.length_delimited(chunk_field, data[at:at + UPLOAD_CHUNK_BYTES].tobytes())


def _points_header(blocks: Sequence[npt.ArrayLike], grid_id: str, display_name: str
                   ) -> tuple[service_pb2.ImportHeader, list[_wire.Array]]:
    """The ImportHeader of point blocks and the blocks as 4-D float64 arrays; ValueError for
    no block, a block of a wrong shape (named by its index) or mixed coordinate counts."""
    if isinstance(blocks, np.ndarray):
        # Iterating one array would split it along its first axis into blocks of one line each.
        raise ValueError(f"blocks is one array of shape {blocks.shape}; give a list of blocks "
                         "(e.g. [points] for one block)")
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
    return header, arrays


def _points_requests(header: service_pb2.ImportHeader,
                     arrays: list[_wire.Array]) -> Iterator[Union[bytes, Message]]:
    """ImportGridRequests of point blocks: ``header``, then each block's coordinates as
    PointChunk messages of at most UPLOAD_CHUNK_BYTES of values."""
    values_per_chunk = UPLOAD_CHUNK_BYTES // 8
    yield service_pb2.ImportGridRequest(header=header)
    for b, array in enumerate(arrays):
        flat = array.reshape(-1)
        prefix = service_pb2.PointChunk(block=b).SerializeToString()
        for at in range(0, flat.size, values_per_chunk):
            chunk = prefix + _wire.packed_doubles(_COORDINATES_FIELD,
                                                  flat[at:at + values_per_chunk])
            yield _wire.length_delimited(_POINTS_FIELD, chunk)


class _UploadCalls(_Calls):
    """The Client's uploads (ImportGrid)."""

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
        header = _plot3d_header(len(data), grid_id, display_name, planar_view)
        return self._upload_file(header, _PLOT3D_CHUNK_FIELD, data)

    def import_cgns(self, path_or_bytes: PathOrBytes, grid_id: str = "",
                    display_name: str = "") -> grid_pb2.Grid:
        """Uploads a CGNS file (HDF5 or ADF; a path, or its bytes) as a new grid; returns it
        (BASIC view). The server decodes it in a separate process: structured zones become
        blocks, boundary conditions (families resolved) the default boundary kinds of fits
        (``grid.source.boundaries``; its ``notes`` say what the import mapped with a choice or
        left out). A file it cannot read raises INVALID_ARGUMENT (``cgns: ...``)."""
        data = _read_bytes(path_or_bytes)
        return self._upload_file(_cgns_header(len(data), grid_id, display_name),
                                 _CGNS_CHUNK_FIELD, data)

    def _upload_file(self, header: service_pb2.ImportHeader, chunk_field: int,
                     data: memoryview) -> grid_pb2.Grid:
        """ImportGrid of a file (:func:`_file_requests`). Retried whole under the retry
        policy; the routing header is the header's grid_id."""
        return self._call(lambda a: _as(grid_pb2.Grid, self._import_grid(
            _file_requests(header, chunk_field, data), timeout=a.timeout,
            metadata=a.metadata)), header.grid_id)

    def import_points(self, blocks: Sequence[npt.ArrayLike], grid_id: str = "",
                      display_name: str = "") -> grid_pb2.Grid:
        """Uploads point blocks as a new grid; returns it (BASIC view).

        Each block is an array shaped ``(nk, nj, ni, s)``, ``(nj, ni, s)`` or ``(ni, s)`` (C
        order: i fastest; see the module docstring), with the same s (2 or 3) for all blocks.
        The coordinates go as PointChunk messages of at most 1 MiB of values each.
        """
        header, arrays = _points_header(blocks, grid_id, display_name)
        return self._call(lambda a: _as(grid_pb2.Grid, self._import_grid(
            _points_requests(header, arrays), timeout=a.timeout, metadata=a.metadata)),
            header.grid_id)
