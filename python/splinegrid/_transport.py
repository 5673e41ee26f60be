"""What every call shares: one attempt's deadline and metadata, the routing header, request
serialization, credentials files, and the hand-encoded grpc.health.v1 messages."""

from __future__ import annotations

from typing import Optional, TypeVar, Union

from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid._args import _grid_id

_T = TypeVar("_T")
SERVICE = "splinegrid.v1.SplineGrid"
GRID_ROUTING_HEADER = "x-splinegrid-grid"  # the grid a call is about, for a balancer to hash on
Metadata = tuple[tuple[str, str], ...]  # gRPC call metadata: (key, value) pairs
_HEALTH_STATUS = ("UNKNOWN", "SERVING", "NOT_SERVING", "SERVICE_UNKNOWN")


class _Attempt:
    """One try of a call: its ``timeout`` (what is left of the call's deadline) and its
    ``metadata``. An attempt starts from scratch (a stream's partial results are dropped), so
    every call may be repeated when it broke off."""

    __slots__ = ("timeout", "metadata")

    def __init__(self, timeout: float, metadata: Optional[Metadata]) -> None:
        self.timeout = timeout
        self.metadata = metadata


def _routing_grid(request: Union[bytes, Message]) -> str:
    """The grid a request is about: the id of its ``name``, else its ``grid_id`` (a new
    grid's), else none."""
    if isinstance(request, Message):
        fields = request.DESCRIPTOR.fields_by_name
        if "name" in fields:
            return _grid_id(str(request.name))
        if "grid_id" in fields:
            return str(request.grid_id)
    return ""


def _as(kind: type[_T], value: object) -> _T:
    """``value``, checked to be a ``kind``: what a call of the untyped gRPC stubs answered."""
    if not isinstance(value, kind):
        raise TypeError(f"expected a {kind.__name__} from the call, got a "
                        f"{type(value).__name__}")
    return value


def _read_pem(path: Optional[str], name: str) -> Optional[bytes]:
    """The bytes of the PEM file ``path`` (argument ``name``), or None."""
    if path is None:
        return None
    try:
        with open(path, "rb") as file:
            return file.read()
    except OSError as error:
        raise ValueError(f"{name}: cannot read {path!r}: {error.strerror}") from error


def _routing_metadata(grid: str) -> Optional[Metadata]:
    """The routing header naming ``grid`` (none for no grid, or an id that is not printable
    ASCII, which the server refuses anyway)."""
    grid = _grid_id(grid)
    # Only what can be a grid id: a long or binary name goes without the header, so that the
    # server (not the metadata size limit) answers it with INVALID_ARGUMENT naming the field.
    if not grid or len(grid) > 128 or not (grid.isascii() and grid.isprintable()):
        return None
    return ((GRID_ROUTING_HEADER, grid),)


def _serialize(message: Union[bytes, Message]) -> bytes:
    """Requests that are already encoded pass through; messages are serialized."""
    return message if isinstance(message, bytes) else bytes(message.SerializeToString())


def _encode_health_request(service: str) -> bytes:
    return _wire.length_delimited(1, service.encode()) if service else b""


def _decode_health_response(data: bytes) -> str:
    status = 0
    for number, _, value in _wire.fields(data):
        if number == 1 and isinstance(value, int):
            status = value
    return _HEALTH_STATUS[status] if status < len(_HEALTH_STATUS) else str(status)
