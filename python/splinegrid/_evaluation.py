"""Decoding of the bulk evaluation responses straight from wire bytes into NumPy arrays (see
``_wire``): EvaluateGrid's stream (a header, then chunks of one block's field) reassembled into
preallocated arrays, and EvaluatePoints' response."""

from __future__ import annotations

from typing import Iterable, NamedTuple, Optional, Union

import numpy as np

from splinegrid import _wire
from splinegrid.errors import SplinegridError, _data_loss
from splinegrid.results import EvaluatedBlock, EvaluatedGrid, EvaluatedPoints
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2


_FIELD_NAMES = {
    service_pb2.FIELD_POINTS: "points",
    service_pb2.FIELD_DU: "du",
    service_pb2.FIELD_DV: "dv",
    service_pb2.FIELD_DW: "dw",
}


class _Chunk(NamedTuple):
    block: int
    field: int
    offset: int
    values: _wire.Array


def _decode_evaluate_response(data: bytes) -> Union[service_pb2.EvaluationHeader, _Chunk]:
    """An EvaluateGridResponse: the header as a proto, a chunk with its values as an array."""
    part: Union[service_pb2.EvaluationHeader, _Chunk, None] = None
    for number, wire_type, value in _wire.fields(data):
        if isinstance(value, int):  # no varint fields at this level
            continue
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
        if isinstance(value, int):
            if number in ints:
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
              dtype: _wire.Dtype, max_bytes: Optional[int] = None) -> EvaluatedGrid:
    """Reassembles an EvaluateGrid stream into preallocated arrays. With ``max_bytes``, an
    evaluation whose arrays would take more is refused (RESOURCE_EXHAUSTED) when its header
    arrives, before anything is allocated."""
    result: Optional[EvaluatedGrid] = None
    targets: dict[tuple[int, int], _wire.Array] = {}  # (block, field) -> flat view
    missing = 0  # values announced but not received yet
    for part in messages:
        if isinstance(part, service_pb2.EvaluationHeader):
            if result is not None:
                raise _data_loss("a second header")
            s = part.spatial_dim
            fields = list(_FIELD_NAMES.items())[:4 if part.derivatives else 1]
            if max_bytes is not None:
                _check_size(part, len(fields), np.dtype(dtype).itemsize, max_bytes)
            result = EvaluatedGrid(part.revision, s)
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


def _check_size(header: service_pb2.EvaluationHeader, fields: int, itemsize: int,
                max_bytes: int) -> None:
    """RESOURCE_EXHAUSTED unless the arrays the header announces fit in ``max_bytes``."""
    values = sum(max(b.extents.i, 1) * max(b.extents.j, 1) * max(b.extents.k, 1)
                 for b in header.blocks) * max(header.spatial_dim, 1) * fields
    if values * itemsize <= max_bytes:
        return
    gib = float(1 << 30)
    raise SplinegridError(
        "RESOURCE_EXHAUSTED",
        f"the evaluation holds {header.total_points} points ({values * itemsize / gib:.2f} GiB "
        f"of values) but this client may hold {max_bytes / gib:.2f} GiB "
        "(Client(max_evaluation_bytes=...)): ask for fewer points (counts, index_box, a lower "
        "level, or blocks)")


def _decode_points_response(data: bytes) -> EvaluatedPoints:
    """An EvaluatePointsResponse (1 revision, 2 spatial_dim, 3 points, 4-6 du, dv, dw)."""
    ints = {1: 0, 2: 0}
    floats = _wire.FloatFields()
    for number, wire_type, value in _wire.fields(data):
        if isinstance(value, int):
            if number in ints:
                ints[number] = _wire.signed(value)
        elif 3 <= number <= 6:
            floats.add(number, wire_type, value, _wire.DOUBLE)
    s = ints[2] or 1
    points, du, dv, dw = (floats.get(n, _wire.DOUBLE).reshape(-1, s) for n in range(3, 7))
    if du.size == 0:
        return EvaluatedPoints(ints[1], points)
    return EvaluatedPoints(ints[1], points, du, dv, dw)
