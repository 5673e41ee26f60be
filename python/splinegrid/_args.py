"""The client's arguments as request protos: checks that raise ``ValueError`` naming the
argument and its value before any call is made, and the conversions (names, index triples, fit
specs, face kinds, point blocks). Those of deform's motions and boundaries: ``_motion_args``."""

from __future__ import annotations

import math
import os
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

PathOrBytes = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview]

Triple = Sequence[int]  # (i, j) or (i, j, k)

Blocks = Union[None, int, Iterable[int]]

_FACES = {"imin": grid_pb2.BLOCK_FACE_I_MIN, "imax": grid_pb2.BLOCK_FACE_I_MAX,
          "jmin": grid_pb2.BLOCK_FACE_J_MIN, "jmax": grid_pb2.BLOCK_FACE_J_MAX,
          "kmin": grid_pb2.BLOCK_FACE_K_MIN, "kmax": grid_pb2.BLOCK_FACE_K_MAX}

_KINDS = {"wall": grid_pb2.BOUNDARY_KIND_WALL, "interface": grid_pb2.BOUNDARY_KIND_INTERFACE,
          "outer": grid_pb2.BOUNDARY_KIND_OUTER}

_FACE_HELP = ("give BLOCK:FACE=KIND or {(block, face): kind}, FACE imin, imax, jmin, jmax, kmin "
              "or kmax, KIND wall, interface or outer")

_MARCH_SIDES = {
    "outward": service_pb2.MARCH_SIDE_OUTWARD,
    "along": service_pb2.MARCH_SIDE_ALONG_NORMAL,
    "against": service_pb2.MARCH_SIDE_AGAINST_NORMAL,
}

_LAYER_METHODS = {
    "offsets": service_pb2.LAYER_METHOD_OFFSETS,
    "transfinite": service_pb2.LAYER_METHOD_TRANSFINITE,
    "elliptic": service_pb2.LAYER_METHOD_ELLIPTIC,
}


def grid_name(name_or_id: str) -> str:
    """``"foo"`` or ``"grids/foo"`` -> ``"grids/foo"``."""
    return name_or_id if name_or_id.startswith("grids/") else f"grids/{name_or_id}"


def _grid_id(grid_id: str) -> str:
    """The id part of "foo" or "grids/foo"."""
    return grid_id[len("grids/"):] if grid_id.startswith("grids/") else grid_id


def _read_bytes(path_or_bytes: PathOrBytes) -> memoryview:
    """The bytes given, or a file's; ValueError when there are none (the server would name
    only its header field, total_bytes = 0)."""
    if isinstance(path_or_bytes, (bytes, bytearray, memoryview)):
        data = memoryview(path_or_bytes).cast("B")
        what = "the bytes given are"
    else:
        with open(path_or_bytes, "rb") as file:
            data = memoryview(file.read())
        what = f"{os.fspath(path_or_bytes)} is"
    if len(data) == 0:
        raise ValueError(f"{what} empty: no grid to import")
    return data


def _extents(values: Triple, what: str, fill: int) -> grid_pb2.Extents:
    given = values
    try:
        if isinstance(values, (str, bytes)):
            raise TypeError  # "128" would be (1, 2, 8)
        items = list(values)  # an iterator is read once
        if any(isinstance(v, (str, bytes)) for v in items):
            raise TypeError  # ("3", 4)
        values = [int(v) for v in items]
        if any(v != int(v) for v in items):
            raise ValueError  # 1.5
    except (TypeError, ValueError, OverflowError):  # a bare number, inf, not an integer
        raise ValueError(f"{what} = {given!r}; give 1 to 3 integers (i, j, k)") from None
    if not 1 <= len(values) <= 3:
        raise ValueError(f"{what} = {values}; give 1 to 3 integers (i, j, k)")
    i, j, k = values + [fill] * (3 - len(values))
    return grid_pb2.Extents(i=i, j=j, k=k)


def _fit_spec(control_counts: Optional[Triple], tolerance: Optional[float], order: int,
              max_controls: int, boundary_tolerances: Optional[dict[str, float]],
              fairing: Union[None, str, float]) -> grid_pb2.FitSpec:
    """The FitSpec of :meth:`Client.fit`'s arguments."""
    given = [control_counts is not None, tolerance is not None,
             boundary_tolerances is not None]
    if sum(given) > 1:
        raise ValueError("give one of control_counts, tolerance and boundary_tolerances")
    spec = grid_pb2.FitSpec(order=order, max_controls_per_direction=max_controls)
    if tolerance is not None:
        spec.tolerance = tolerance
    elif boundary_tolerances is not None:
        unknown = set(boundary_tolerances) - {"wall", "interface", "outer", "interior", "edge",
                                              "first_layer"}
        if unknown:
            raise ValueError(f"boundary_tolerances: unknown kinds {sorted(unknown)}")
        spec.boundary_tolerances.SetInParent()
        for kind, value in boundary_tolerances.items():
            setattr(spec.boundary_tolerances, kind, float(value))
    elif control_counts is not None:
        spec.control_counts.CopyFrom(_extents(control_counts, "control_counts", fill=0))
    if fairing is not None:
        spec.fairing.CopyFrom(_fairing(fairing))
    return spec

FaceKindsLike = Union[str, Mapping[Any, Any], Sequence[Any]]  # see Client.fit's face_kinds


def _face_kinds(face_kinds: FaceKindsLike) -> list[grid_pb2.FaceKind]:
    """FaceKind messages of :meth:`Client.fit`'s ``face_kinds``; ValueError names a bad entry."""
    if isinstance(face_kinds, str):
        face_kinds = [t for t in face_kinds.split(",") if t.strip()]
    entries: list[tuple[Any, Any, Any]] = []  # (what to name in errors, (block, face), kind)
    if isinstance(face_kinds, Mapping):
        entries = [(key, key, kind) for key, kind in face_kinds.items()]
    else:
        for token in face_kinds:
            text = str(token).strip()
            block_face, sep, kind = text.partition("=")
            block_text, sep2, face_text = block_face.partition(":")
            if not sep or not sep2:
                raise ValueError(f"face_kinds: {text!r}: {_FACE_HELP}")
            entries.append((text, (block_text, face_text), kind))
    out: list[grid_pb2.FaceKind] = []
    seen: dict[tuple[int, str], str] = {}
    for what, key, kind in entries:
        try:
            given_block, face = key
            block = int(given_block)
        except (TypeError, ValueError):
            raise ValueError(f"face_kinds: {what!r}: the block is not a number; "
                             f"{_FACE_HELP}") from None
        face_name, kind_name = str(face).strip().lower(), str(kind).strip().lower()
        if block < 0:
            raise ValueError(f"face_kinds: {what!r}: block {block} < 0; {_FACE_HELP}")
        if face_name not in _FACES:
            raise ValueError(f"face_kinds: {what!r}: unknown face {face!r}; {_FACE_HELP}")
        if kind_name not in _KINDS:
            why = ("there is no symmetry kind (fit a symmetry plane as outer)"
                   if kind_name == "symmetry" else f"unknown kind {kind!r}")
            raise ValueError(f"face_kinds: {what!r}: {why}; {_FACE_HELP}")
        if (block, face_name) in seen:
            if seen[(block, face_name)] != kind_name:
                raise ValueError(f"face_kinds: {what!r}: the face is given another kind before")
            continue
        seen[(block, face_name)] = kind_name
        out.append(grid_pb2.FaceKind(block=block, face=_FACES[face_name], kind=_KINDS[kind_name]))
    return out


def _airfoil_text(airfoil: Union[str, bytes, "os.PathLike[str]"]) -> str:
    """An airfoil file's text from its path, or the text itself (a str with a line break)."""
    if isinstance(airfoil, (bytes, bytearray)):
        return bytes(airfoil).decode()
    if isinstance(airfoil, str) and "\n" in airfoil:
        return airfoil
    with open(airfoil, encoding="utf-8", errors="replace") as file:
        return file.read()


def _fairing(fairing: Union[str, float]) -> grid_pb2.Fairing:
    if fairing == "tol":
        return grid_pb2.Fairing(mode=grid_pb2.FAIRING_MODE_TO_TOLERANCE)
    if isinstance(fairing, str) or not float(fairing) > 0.0:
        raise ValueError(f"fairing = {fairing!r}: give 'tol' or a positive weight")
    return grid_pb2.Fairing(mode=grid_pb2.FAIRING_MODE_WEIGHT, weight=float(fairing))


def _set_step(request: Message, revision: int, step: Optional[int]) -> None:
    """Sets the optional ``step`` of a Get/Evaluate request (not together with a revision)."""
    if step is None:
        return
    if revision != 0:
        raise ValueError(f"give revision ({revision}) or step ({step}), not both")
    request.step = _integer(step, "step")


def _integer(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{what} = {value!r}; must be an integer")
    return int(value)


def _non_negative_int(value: Any, what: str) -> int:
    number = _integer(value, what)
    if number < 0:
        raise ValueError(f"{what} = {value}; must not be negative")
    return number


def _finite(value: Any, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what} = {value!r}; must be a number") from None
    if not math.isfinite(number):
        raise ValueError(f"{what} = {value}; must be finite")
    return number


def _non_negative(value: Any, what: str) -> float:
    number = _finite(value, what)
    if number < 0.0:
        raise ValueError(f"{what} = {value}; must not be negative")
    return number


def _block_list(blocks: Blocks) -> list[int]:
    if blocks is None:
        return []
    if isinstance(blocks, (int, np.integer)):
        return [int(blocks)]
    return [int(b) for b in blocks]


def _as_block(block: npt.ArrayLike, index: int) -> _wire.Array:
    """An upload block as a C-ordered little-endian float64 array (nk, nj, ni, s)."""
    array = np.asarray(block, dtype=np.float64)
    if not 2 <= array.ndim <= 4 or array.shape[-1] not in (2, 3):
        raise ValueError(f"blocks[{index}] has shape {array.shape}; expected (nk, nj, ni, s), "
                         "(nj, ni, s) or (ni, s) with s = 2 or 3")
    array = array.reshape((1,) * (4 - array.ndim) + array.shape)
    return np.ascontiguousarray(array, dtype=_wire.DOUBLE)
