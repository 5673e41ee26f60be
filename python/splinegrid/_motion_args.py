"""The arguments of :meth:`Client.deform` as request protos: what moves (boundary kinds or face
ranges) and the motion (rigid, control displacements, boundary points), with checks that raise
``ValueError`` naming the argument and its value before any call is made."""

from __future__ import annotations

from typing import Any, Iterable, Mapping, Optional, Sequence

import numpy as np
import numpy.typing as npt

from splinegrid._args import _FACES, _KINDS, _extents, _finite, _non_negative_int
from splinegrid.results import BoundaryPoints, FaceRangeLike
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

MAX_CHECK_LEVEL = 4  # the server's highest fold-check level

_PROPAGATIONS = {
    "blend": service_pb2.PROPAGATION_BLEND,
    "transfinite": service_pb2.PROPAGATION_TRANSFINITE,
}

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
