"""Just enough of the protobuf wire format to move bulk numbers without per-value work.

The generated classes hold packed ``repeated double`` fields as containers that NumPy cannot
view, so converting them costs a step per value. The bulk messages of the service (point
uploads, evaluation chunks, EvaluatePoints) are therefore encoded and decoded here, straight
between wire bytes and NumPy arrays (``np.frombuffer`` / ``ndarray.tobytes``). Everything else
goes through the generated classes.

Wire format reminder: a message is a sequence of ``tag = field << 3 | wire_type`` varints, each
followed by a varint (type 0), 8 bytes (type 1), a varint length and that many bytes (type 2,
also used for packed repeated scalars) or 4 bytes (type 5). Concatenated encodings of a message
merge: repeated fields append. The helpers below rely on that.
"""

from __future__ import annotations

from typing import Any, Iterator, Union

import numpy as np
import numpy.typing as npt

Buffer = Union[bytes, memoryview]
Array = npt.NDArray[Any]  # a NumPy array of any dtype (float64/float32 for bulk numbers)
Dtype = np.dtype[Any]

VARINT, FIXED64, LENGTH_DELIMITED, FIXED32 = 0, 1, 2, 5

DOUBLE: Dtype = np.dtype("<f8")
FLOAT: Dtype = np.dtype("<f4")


def encode_varint(value: int) -> bytes:
    """The varint encoding of a non-negative integer (negative int32/int64 as 10 bytes)."""
    value &= (1 << 64) - 1
    out = bytearray()
    while value >= 0x80:
        out.append((value & 0x7F) | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def decode_varint(buf: Buffer, pos: int) -> tuple[int, int]:
    """The unsigned varint at ``buf[pos:]`` and the position after it."""
    result = shift = 0
    while True:
        if pos >= len(buf) or shift > 63:
            raise ValueError("truncated or overlong varint")
        byte = buf[pos]
        pos += 1
        result |= (byte & 0x7F) << shift
        if byte < 0x80:
            return result, pos
        shift += 7


def signed(value: int) -> int:
    """A decoded varint as the signed int32/int64 it encodes."""
    return value - (1 << 64) if value >= 1 << 63 else value


def length_delimited(field: int, payload: bytes) -> bytes:
    """Field ``field`` holding ``payload`` (bytes, string, message or packed values)."""
    return encode_varint(field << 3 | LENGTH_DELIMITED) + encode_varint(len(payload)) + payload


def packed_doubles(field: int, values: npt.ArrayLike) -> bytes:
    """A packed ``repeated double`` field holding ``values`` (any shape, read in C order)."""
    return length_delimited(field, np.ascontiguousarray(values, dtype="<f8").tobytes())


def fields(buf: Buffer) -> Iterator[tuple[int, int, Union[int, memoryview]]]:
    """(field number, wire type, value) of each field of one encoded message, in order.

    The value is an int for varints and a memoryview (no copy) for all other wire types.
    """
    view = memoryview(buf)
    pos = 0
    while pos < len(view):
        tag, pos = decode_varint(view, pos)
        field, wire_type = tag >> 3, tag & 7
        if wire_type == VARINT:
            value, pos = decode_varint(view, pos)
            yield field, wire_type, value
            continue
        if wire_type == LENGTH_DELIMITED:
            size, pos = decode_varint(view, pos)
        elif wire_type in (FIXED64, FIXED32):
            size = 8 if wire_type == FIXED64 else 4
        else:
            raise ValueError(f"unsupported wire type {wire_type} (field {field})")
        if pos + size > len(view):
            raise ValueError(f"field {field} runs past the end of the message")
        yield field, wire_type, view[pos:pos + size]
        pos += size


class FloatFields:
    """Collects repeated float/double fields of one message as NumPy arrays (no per-value work).

    ``add`` takes a field as yielded by :func:`fields`, packed (the usual proto3 encoding) or
    not (one value per field, which parsers must also accept).
    """

    def __init__(self) -> None:
        self._pieces: dict[int, list[Array]] = {}

    def add(self, field: int, wire_type: int, value: memoryview, dtype: Dtype) -> None:
        unpacked = FIXED64 if dtype.itemsize == 8 else FIXED32
        if wire_type not in (LENGTH_DELIMITED, unpacked):
            raise ValueError(f"field {field}: wire type {wire_type} is not {dtype} data")
        if len(value) % dtype.itemsize:
            raise ValueError(f"field {field}: {len(value)} bytes is not a whole number of values")
        self._pieces.setdefault(field, []).append(np.frombuffer(value, dtype=dtype))

    def get(self, field: int, dtype: Dtype) -> Array:
        """The values of ``field`` in ``dtype``'s byte order (empty if it was absent)."""
        pieces = self._pieces.get(field)
        if not pieces:
            return np.empty(0, dtype=dtype)
        return pieces[0] if len(pieces) == 1 else np.concatenate(pieces)

