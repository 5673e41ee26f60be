"""Enough of a Plot3D reader to answer one question before an upload: is the file a two-plane
grid (a 2-D grid stored as two planes, CFL3D style), whose planar view should be stored?

The server reads the file itself (``core/io/plot3d.h``); this module only mirrors the layout
detection of that reader for the layouts that can hold a two-plane grid, so that
:meth:`Client.import_plot3d` decides ``planar_view`` locally and uploads once:

- formatted text: numbers separated by blanks or commas, Fortran ``n*value`` repeats and
  ``D`` exponents; the hypotheses {block-count line, none} x {3-D} x {no iblank, iblank} in
  the reader's order, the number of values matching the header exactly;
- Fortran unformatted records (4-byte markers before and after each record, either byte
  order; a 4-byte first record is the block count; single or double precision, with or
  without iblank, told by the first block record's length);
- C-stream binary (no record markers): either byte order, with or without the block count,
  single or double, with or without iblank, the file size matching the header exactly.

Files are read in the "whole" layout (all x, all y, all z of a block, i fastest). A file this
module cannot read (the "planes" layout, a damaged file) is not a two-plane grid here: it is
uploaded as read and the server answers for it. The two-plane test is
``core/io/planar_view.h``'s: extent 2 along some index direction, the two planes equal except
for one coordinate that is constant on each plane and differs between them, all within
``1e-8`` times the block's bounding-box diagonal. Cost: O(file size) when some block has an
extent of 2 (every value is read), else only the header is looked at.
"""

from __future__ import annotations

import re
from typing import Optional, Sequence, Union

import numpy as np

from splinegrid._wire import Array

__all__ = ["is_two_plane_block", "is_two_plane_grid", "read_3d_blocks", "two_plane_file"]

RELATIVE_TOLERANCE = 1e-8  # PlanarViewOptions::relative_tolerance
HEADER_PROBE_BYTES = 1 << 16  # text: the header of any plausible file lies in this prefix

Dims = list[tuple[int, int, int]]  # (ni, nj, nk) per block


def two_plane_file(data: Union[bytes, memoryview]) -> bool:
    """Whether the Plot3D file ``data`` is a 3-D grid whose every block is a two-plane block
    (the server's ``IsTwoPlaneGrid``). False for anything else, including files not read here
    (see the module docstring)."""
    blocks = read_3d_blocks(data, only_if_extent_2=True)
    return blocks is not None and is_two_plane_grid(blocks)


def read_3d_blocks(data: Union[bytes, memoryview],
                   only_if_extent_2: bool = False) -> Optional[list[Array]]:
    """The blocks of 3-D Plot3D file ``data`` as float64 arrays ``(nk, nj, ni, 3)``, or None
    when the file is not a 3-D grid in a layout read here. With ``only_if_extent_2`` also None,
    without reading the coordinates, when some block has no extent 2 (it cannot be a
    two-plane grid)."""
    if not data:
        return None
    binary = any(not (32 <= c < 127 or c in b" \t\r\n\f\v") for c in bytes(data[:4]))
    if binary:
        return _read_records(data, only_if_extent_2) or _read_stream(data, only_if_extent_2)
    return _read_text(data if isinstance(data, bytes) else bytes(data), only_if_extent_2)


def is_two_plane_grid(blocks: Sequence[Array]) -> bool:
    """Whether there are blocks and every one is a two-plane block."""
    return bool(blocks) and all(is_two_plane_block(b) for b in blocks)


def is_two_plane_block(block: Array) -> bool:
    """Whether ``block`` (``(nk, nj, ni, 3)``) is a two-plane block along some direction."""
    if block.ndim != 4 or block.shape[3] != 3 or block.size == 0:
        return False
    flat = block.reshape(-1, 3)
    tol = RELATIVE_TOLERANCE * float(np.sqrt(np.sum((flat.max(0) - flat.min(0)) ** 2)))
    for axis in (2, 1, 0):  # directions i, j, k: the first that works wins
        if block.shape[axis] != 2:
            continue
        planes = (np.take(block, 0, axis=axis), np.take(block, 1, axis=axis))
        first = planes[1].reshape(-1, 3)[0] - planes[0].reshape(-1, 3)[0]
        differ = [s for s in range(3) if not abs(first[s]) <= tol]
        if len(differ) != 1:
            continue
        normal = differ[0]
        in_plane = [s for s in range(3) if s != normal]
        if not np.all(np.abs(planes[1][..., in_plane] - planes[0][..., in_plane]) <= tol):
            continue
        if all(np.all(np.abs(p[..., normal] - p.reshape(-1, 3)[0, normal]) <= tol)
               for p in planes):
            return True
    return False


def _plausible(dims: Dims) -> bool:
    return all(min(d) >= 1 for d in dims)


def _has_extent_2(dims: Dims) -> bool:
    return all(2 in d for d in dims)


def _blocks(values: Array, dims: Dims, iblank: bool) -> list[Array]:
    """Splits the coordinate values (and skips iblank values) into (nk, nj, ni, 3) blocks."""
    blocks, at = [], 0
    for ni, nj, nk in dims:
        n = ni * nj * nk
        xyz = values[at:at + 3 * n].reshape(3, nk, nj, ni)
        blocks.append(np.ascontiguousarray(np.moveaxis(xyz, 0, -1), dtype=np.float64))
        at += 3 * n + (n if iblank else 0)
    return blocks


# Formatted text.

_REPEAT = re.compile(rb"(\d+)\*([^\s,]+)")


def _tokens(text: bytes) -> list[bytes]:
    text = text.replace(b",", b" ").replace(b"D", b"E").replace(b"d", b"e")
    if b"*" in text:
        text = _REPEAT.sub(lambda m: b" ".join([m.group(2)] * int(m.group(1))), text)
    return text.split()


def _int_token(token: bytes) -> Optional[int]:
    return int(token) if token.isdigit() else None


def _text_hypotheses(head: list[bytes]) -> list[tuple[int, Dims]]:
    """(number of header values, dims) of the 3-D header hypotheses in the reader's order:
    with a block-count line first, then without (a single block)."""
    out: list[tuple[int, Dims]] = []
    count = _int_token(head[0]) if head else None
    if count is not None and count >= 1 and len(head) >= 1 + 3 * count:
        ints = [_int_token(t) for t in head[1:1 + 3 * count]]
        if all(v is not None for v in ints):
            values = [v for v in ints if v is not None]
            dims = [(values[3 * b], values[3 * b + 1], values[3 * b + 2]) for b in range(count)]
            if _plausible(dims):
                out.append((1 + 3 * count, dims))
    ints3 = [_int_token(t) for t in head[:3]]
    if len(ints3) == 3 and all(v is not None for v in ints3):
        ni, nj, nk = (v or 0 for v in ints3)
        if _plausible([(ni, nj, nk)]):
            out.append((3, [(ni, nj, nk)]))
    return out


def _read_text(data: bytes, only_if_extent_2: bool) -> Optional[list[Array]]:
    candidates = _text_hypotheses(_tokens(data[:HEADER_PROBE_BYTES]))
    if only_if_extent_2:
        candidates = [c for c in candidates if _has_extent_2(c[1])]
    if not candidates:
        return None
    tokens = _tokens(data)
    for header, dims in candidates:
        points = sum(ni * nj * nk for ni, nj, nk in dims)
        for iblank in (False, True):
            if len(tokens) - header != points * (4 if iblank else 3):
                continue
            try:
                values = np.array(tokens[header:], dtype=np.float64)
            except ValueError:
                return None
            return _blocks(values, dims, iblank)
    return None


# Binary: Fortran records and C streams.

def _read_records(data: Union[bytes, memoryview], only_if_extent_2: bool) -> Optional[list[Array]]:
    for order in "<>":
        records = _split_records(data, order)
        if records is None or len(records) < 2:
            continue
        first = 0
        count = 1
        if len(records[0]) == 4:
            count = int(np.frombuffer(records[0], dtype=f"{order}i4")[0])
            first = 1
        if count < 1 or len(records[first]) != 12 * count or len(records) != first + 1 + count:
            continue
        raw = np.frombuffer(records[first], dtype=f"{order}i4").reshape(count, 3)
        dims = [(int(a), int(b), int(c)) for a, b, c in raw]
        if not _plausible(dims) or (only_if_extent_2 and not _has_extent_2(dims)):
            return None
        blocks = []
        for (ni, nj, nk), record in zip(dims, records[first + 1:]):
            n = ni * nj * nk
            layout = _real_layout(len(record), n)
            if layout is None:
                return None
            real, iblank = layout
            values = np.frombuffer(record, dtype=f"{order}f{real}", count=3 * n)
            blocks += _blocks(values, [(ni, nj, nk)], False)
        return blocks
    return None


def _split_records(data: Union[bytes, memoryview], order: str) -> Optional[list[bytes]]:
    """The payloads of Fortran sequential records, or None if the markers do not add up."""
    records, at = [], 0
    marker = np.dtype(f"{order}i4")
    while at < len(data):
        if at + 4 > len(data):
            return None
        size = int(np.frombuffer(data, dtype=marker, count=1, offset=at)[0])
        end = at + 4 + size
        if size < 0 or end + 4 > len(data):
            return None
        if int(np.frombuffer(data, dtype=marker, count=1, offset=end)[0]) != size:
            return None
        records.append(data[at + 4:end])
        at = end + 4
    return records


def _real_layout(size: int, points: int) -> Optional[tuple[int, bool]]:
    """(bytes per real, iblank) of a block of ``points`` points stored in ``size`` bytes."""
    for real in (8, 4):
        for iblank in (False, True):
            if size == points * (3 * real + (4 if iblank else 0)):
                return real, iblank
    return None


def _read_stream(data: Union[bytes, memoryview], only_if_extent_2: bool) -> Optional[list[Array]]:
    for order in "<>":
        for with_count in (True, False):
            ints = np.frombuffer(data[:min(len(data), HEADER_PROBE_BYTES) // 4 * 4],
                                 dtype=f"{order}i4")
            count = int(ints[0]) if with_count and ints.size else 1
            header = (1 if with_count else 0) + 3 * count
            if count < 1 or ints.size < header:
                continue
            dims = [tuple(int(v) for v in ints[h:h + 3])
                    for h in range((1 if with_count else 0), header, 3)]
            typed: Dims = [(d[0], d[1], d[2]) for d in dims]
            if not _plausible(typed):
                continue
            points = sum(ni * nj * nk for ni, nj, nk in typed)
            layout = _real_layout(len(data) - 4 * header, points)
            if layout is None:
                continue
            if only_if_extent_2 and not _has_extent_2(typed):
                return None
            real, iblank = layout
            blocks, at = [], 4 * header
            for ni, nj, nk in typed:
                n = ni * nj * nk
                values = np.frombuffer(data, dtype=f"{order}f{real}", count=3 * n, offset=at)
                blocks += _blocks(values, [(ni, nj, nk)], False)
                at += 3 * n * real + (4 * n if iblank else 0)
            return blocks
    return None

