"""The client's arguments as request protos: checks that raise ``ValueError`` naming the
argument and its value before any call is made, and the conversions (names, index triples, fit
specs, face ranges, boundary selections, point blocks)."""

from __future__ import annotations

import math
import os
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from google.protobuf.message import Message

from splinegrid import _wire
from splinegrid.results import BoundaryPoints, FaceRangeLike
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

PathOrBytes = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview]

Triple = Sequence[int]  # (i, j) or (i, j, k)

Blocks = Union[None, int, Iterable[int]]

MAX_CHECK_LEVEL = 4  # the server's highest fold-check level

_FACES = {"imin": grid_pb2.BLOCK_FACE_I_MIN, "imax": grid_pb2.BLOCK_FACE_I_MAX,
          "jmin": grid_pb2.BLOCK_FACE_J_MIN, "jmax": grid_pb2.BLOCK_FACE_J_MAX,
          "kmin": grid_pb2.BLOCK_FACE_K_MIN, "kmax": grid_pb2.BLOCK_FACE_K_MAX}

_KINDS = {"wall": grid_pb2.BOUNDARY_KIND_WALL, "interface": grid_pb2.BOUNDARY_KIND_INTERFACE,
          "outer": grid_pb2.BOUNDARY_KIND_OUTER}

_FACE_HELP = ("give BLOCK:FACE=KIND or {(block, face): kind}, FACE imin, imax, jmin, jmax, kmin "
              "or kmax, KIND wall, interface or outer")

_PROPAGATIONS = {
    "blend": service_pb2.PROPAGATION_BLEND,
    "transfinite": service_pb2.PROPAGATION_TRANSFINITE,
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
    if isinstance(path_or_bytes, (bytes, bytearray, memoryview)):
        return memoryview(path_or_bytes).cast("B")
    with open(path_or_bytes, "rb") as file:
        return memoryview(file.read())


def _extents(values: Triple, what: str, fill: int) -> grid_pb2.Extents:
    values = [int(v) for v in values]
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
        unknown = set(boundary_tolerances) - {"wall", "interface", "outer", "interior", "edge"}
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


def _vector(values: Sequence[float], what: str, sizes: tuple[int, ...]) -> list[float]:
    try:
        numbers = [_finite(v, what) for v in values]
    except TypeError:
        raise ValueError(f"{what} = {values!r}; give {' or '.join(map(str, sizes))} numbers") \
            from None
    if len(numbers) not in sizes:
        raise ValueError(f"{what} = {list(values)}; give {' or '.join(map(str, sizes))} "
                         "numbers")
    return numbers


def _face_range(spec: FaceRangeLike, what: str) -> grid_pb2.FaceRange:
    """A FaceRange from a proto, a (block, face, begin, end) tuple or a dict."""
    if isinstance(spec, grid_pb2.FaceRange):
        return spec
    if isinstance(spec, Mapping):
        unknown = set(spec) - {"block", "face", "begin", "end"}
        if unknown or not {"block", "face", "begin", "end"} <= set(spec):
            raise ValueError(f"{what} = {dict(spec)}; give the keys block, face, begin, end")
        block, face, begin, end = spec["block"], spec["face"], spec["begin"], spec["end"]
    elif isinstance(spec, (tuple, list)) and len(spec) == 4:
        block, face, begin, end = spec
    else:
        raise ValueError(f"{what} = {spec!r}; give (block, face, begin, end)")
    if isinstance(face, str):
        key = face.lower().replace("_", "").replace("-", "")
        if key not in _FACES:
            raise ValueError(f"{what}: face = {face!r}; give one of {', '.join(_FACES)}")
        face = _FACES[key]
    elif face not in _FACES.values():
        raise ValueError(f"{what}: face = {face!r}; give one of {', '.join(_FACES)}")
    begin_e = _extents(begin, f"{what} begin", fill=0)
    end_e = _extents(end, f"{what} end", fill=0)
    for axis in "ijk":
        lo, hi = getattr(begin_e, axis), getattr(end_e, axis)
        if lo < 0 or hi < lo:
            raise ValueError(f"{what}: {axis} range [{lo}, {hi}] is not 0 <= begin <= end")
    return grid_pb2.FaceRange(block=_non_negative_int(block, f"{what} block"), face=face,
                              begin=begin_e, end=end_e)


def _boundary_selection(boundary: Any) -> service_pb2.BoundarySelection:
    """``boundary`` of :meth:`Client.deform` as a BoundarySelection."""
    selection = service_pb2.BoundarySelection()
    if boundary is None:
        return selection
    if isinstance(boundary, service_pb2.BoundarySelection):
        return boundary
    single = (isinstance(boundary, (str, grid_pb2.FaceRange, Mapping))
              or (isinstance(boundary, tuple) and len(boundary) == 4
                  and isinstance(boundary[0], (int, np.integer))))
    for q, item in enumerate([boundary] if single else list(boundary)):
        if isinstance(item, str):
            if item.lower() not in _KINDS:
                raise ValueError(f"boundary[{q}] = {item!r}; give wall, outer, interface or a "
                                 "face range")
            selection.kinds.append(_KINDS[item.lower()])
        else:
            selection.ranges.append(_face_range(item, f"boundary[{q}]"))
    if selection.kinds and selection.ranges:
        raise ValueError("boundary: give boundary kinds or face ranges, not both")
    return selection


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


# The motions of Client.deform (one of them is set in the DeformGridRequest's oneof).

def _rigid_motion(motion: service_pb2.RigidMotion, rotate_degrees: Optional[float],
                  about: Optional[Sequence[float]], axis: Optional[Sequence[float]],
                  translate: Optional[Sequence[float]]) -> None:
    """Fills ``motion``: a rotation about ``axis`` through ``about``, then ``translate``."""
    motion.angle_degrees = _finite(0.0 if rotate_degrees is None else rotate_degrees,
                                   "rotate_degrees")
    if about is not None:
        motion.center.extend(_vector(about, "about", (2, 3)))
    if axis is not None:
        values = _vector(axis, "axis", (3,))
        if not any(values):
            raise ValueError("axis = (0, 0, 0); the rotation axis must not be zero")
        motion.axis.extend(values)
    if translate is not None:
        motion.translation.extend(_vector(translate, "translate", (2, 3)))

ControlDisplacements = Mapping[int, tuple[npt.ArrayLike, npt.ArrayLike]]


def _control_motion(motion: service_pb2.ControlMotion,
                    control_displacements: ControlDisplacements) -> None:
    """Fills ``motion`` from ``{block: (controls, displacements)}``."""
    motion.SetInParent()
    if not isinstance(control_displacements, Mapping):
        raise ValueError("control_displacements: give {block: (controls, displacements)}")
    for block, pair in control_displacements.items():
        what = f"control_displacements[{block}]"
        try:
            controls, values = pair
        except (TypeError, ValueError):
            raise ValueError(f"{what}: give (controls, displacements)") from None
        index = np.asarray(controls).reshape(-1)
        if index.size and not np.issubdtype(index.dtype, np.integer):
            raise ValueError(f"{what}: control indices must be integers")
        moved = np.asarray(values, dtype=np.float64)
        if moved.ndim != 2 or moved.shape[0] != index.size or moved.shape[1] not in (2, 3):
            raise ValueError(f"{what}: displacements have shape {moved.shape}; expected "
                             f"({index.size}, s) with s = 2 or 3")
        if not np.all(np.isfinite(moved)):
            raise ValueError(f"{what}: displacements must be finite")
        if np.any(index < 0):
            raise ValueError(f"{what}: control indices must not be negative")
        motion.blocks.add(block=_non_negative_int(block, what + " block"),
                          controls=index.tolist(), values=moved.reshape(-1).tolist())


def _boundary_points_motion(motion: service_pb2.BoundaryPointsMotion,
                            boundary_points: Iterable[Any]) -> None:
    """Fills ``motion`` from BoundaryPoints (or tuples / dicts of their fields)."""
    motion.SetInParent()
    for q, given in enumerate(boundary_points):
        what = f"boundary_points[{q}]"
        item = given if isinstance(given, BoundaryPoints) else (
            BoundaryPoints(*given) if isinstance(given, tuple) else BoundaryPoints(**given))
        points = np.asarray(item.coordinates, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] not in (2, 3):
            raise ValueError(f"{what}: coordinates have shape {points.shape}; expected "
                             "(N, s) with s = 2 or 3")
        if not np.all(np.isfinite(points)):
            raise ValueError(f"{what}: coordinates must be finite")
        motion.ranges.add(
            range=_face_range(item.range, what + ".range"),
            refinement_level=_non_negative_int(item.level, what + ".level"),
            coordinates=points.reshape(-1).tolist(),
            displacements=bool(item.displacements))
    if not motion.ranges:
        raise ValueError("boundary_points is empty")
