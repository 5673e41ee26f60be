"""GetGrid's FULL view decoded with its bulk numbers as NumPy arrays.

The generated ``Grid`` class parses the response (in C++, fast), but its packed ``repeated
double control_points`` is a container NumPy converts value by value (about 80 ns per value:
250 ms for a million control points, ``python/benchmarks/decode_benchmark.py``). The control
points are therefore taken from the wire bytes with ``np.frombuffer`` (path: Grid.revision = 7
-> Revision.blocks = 5 -> SplineBlock.control_points = 4) and the now redundant fields are
cleared from the proto. Knots,
parameters and breaks are small (a few hundred values per direction) and are converted from
the proto.
"""

from __future__ import annotations

import numpy as np

from splinegrid import _wire
from splinegrid.errors import _data_loss
from splinegrid.results import FullGrid, SplineArrays
from splinegrid.v1 import grid_pb2

_GRID_REVISION, _REVISION_BLOCKS, _BLOCK_CONTROL_POINTS = 7, 5, 4


def decode_full_grid(data: bytes) -> FullGrid:
    """A GetGrid response (``Grid``, FULL view) as a :class:`FullGrid`; SplinegridError
    DATA_LOSS when a block's control points do not match its control counts."""
    grid = grid_pb2.Grid.FromString(data)
    nets = _control_point_values(data)
    if len(nets) != len(grid.revision.blocks):
        raise _data_loss(f"{len(nets)} control nets for {len(grid.revision.blocks)} blocks")
    blocks = []
    for block, values in zip(grid.revision.blocks, nets):
        blocks.append(_spline_arrays(block, values))
        block.ClearField("control_points")
        for direction in block.directions:
            for field in ("knots", "parameters", "breaks"):
                direction.ClearField(field)
    return FullGrid(grid, blocks)


def _control_point_values(data: bytes) -> list[_wire.Array]:
    """The control point values of every block of the response's revision, in block order."""
    pieces: list[memoryview] = []
    for number, _, value in _wire.fields(data):
        if number == _GRID_REVISION and isinstance(value, memoryview):
            pieces.append(value)  # a repeated message field merges: blocks append
    nets: list[_wire.Array] = []
    for piece in pieces:
        for number, _, value in _wire.fields(piece):
            if number == _REVISION_BLOCKS and isinstance(value, memoryview):
                values = _wire.FloatFields()
                for inner, wire_type, field in _wire.fields(value):
                    if inner == _BLOCK_CONTROL_POINTS and isinstance(field, memoryview):
                        values.add(inner, wire_type, field, _wire.DOUBLE)
                nets.append(values.get(_BLOCK_CONTROL_POINTS, _wire.DOUBLE))
    return nets


def _spline_arrays(block: grid_pb2.SplineBlock, values: _wire.Array) -> SplineArrays:
    s = block.spatial_dim
    directions = list(block.directions)
    if len(directions) != 3 or s not in (2, 3):
        raise _data_loss(f"block {block.index}: {len(directions)} directions, spatial_dim {s}; "
                         "expected 3 directions and 2 or 3 coordinates")
    nci, ncj, nck = (max(1, d.num_controls) for d in directions)
    if values.size != nci * ncj * nck * s:
        raise _data_loss(f"block {block.index}: {values.size} control point values for "
                         f"{nci} x {ncj} x {nck} controls of {s} coordinates")
    # A copy in native order: writable, and independent of the response's buffer.
    net = values.astype(np.float64).reshape(nck, ncj, nci, s)
    i, j, k = directions
    return SplineArrays(
        index=block.index, spatial_dim=s, orders=(i.order, j.order, k.order),
        control_points=net,
        knots=(np.array(i.knots, dtype=np.float64), np.array(j.knots, dtype=np.float64),
               np.array(k.knots, dtype=np.float64)),
        parameters=(np.array(i.parameters, dtype=np.float64),
                    np.array(j.parameters, dtype=np.float64),
                    np.array(k.parameters, dtype=np.float64)),
        breaks=(np.array(i.breaks, dtype=np.int32), np.array(j.breaks, dtype=np.int32),
                np.array(k.breaks, dtype=np.int32)),
        fit=block.fit)
