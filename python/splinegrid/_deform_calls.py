"""Deformation of a stored grid (DeformGrid, fluid-structure coupling): the request built from
the Client's arguments (one motion, what moves, how the grid follows; all checked before any
call, errors naming the argument), and the call."""

from __future__ import annotations

from typing import Iterable, Optional, Sequence, Union

from splinegrid._args import _finite, _integer, _non_negative, _non_negative_int, grid_name
from splinegrid._calls import _Calls
from splinegrid._motion_args import (MAX_CHECK_LEVEL, _PROPAGATIONS, ControlDisplacements,
                                     _boundary_points_motion, _boundary_selection,
                                     _control_motion, _rigid_motion)
from splinegrid.results import BoundaryPoints, FaceRangeLike
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

Boundary = Union[None, str, FaceRangeLike, Iterable[Union[str, FaceRangeLike]]]


def _deform_request(name: str, rotate_degrees: Optional[float],
                    about: Optional[Sequence[float]], axis: Optional[Sequence[float]],
                    translate: Optional[Sequence[float]], boundary: Boundary,
                    reference_revision: int, base_revision: int, time: float, step: int,
                    check_level: int, control_displacements: Optional[ControlDisplacements],
                    boundary_points: Optional[Iterable[BoundaryPoints]], propagation: str,
                    decay_radius: float, rigid_radius: float,
                    smoothing_iterations: int,
                    max_boundary_error: float = 0.0) -> service_pb2.DeformGridRequest:
    """The DeformGridRequest of :meth:`Client.deform`'s arguments; ValueError naming the
    argument (and its value) that is wrong, or the motions when not exactly one is given."""
    request = service_pb2.DeformGridRequest(name=grid_name(name))
    request.reference_revision = _non_negative_int(reference_revision, "reference_revision")
    request.base_revision = _non_negative_int(base_revision, "base_revision")
    request.time = _finite(time, "time")
    request.step = _integer(step, "step")
    request.check_level = _integer(check_level, "check_level")
    if not 0 <= request.check_level <= MAX_CHECK_LEVEL:
        raise ValueError(f"check_level = {check_level}; must be in [0, {MAX_CHECK_LEVEL}]")
    if propagation not in _PROPAGATIONS:
        raise ValueError(f"propagation = {propagation!r}; give 'blend' or 'transfinite'")
    request.propagation = _PROPAGATIONS[propagation]
    request.max_boundary_error = _non_negative(max_boundary_error, "max_boundary_error")
    request.decay_radius = _non_negative(decay_radius, "decay_radius")
    request.rigid_radius = _non_negative(rigid_radius, "rigid_radius")
    if request.decay_radius > 0.0 and request.rigid_radius > request.decay_radius:
        raise ValueError(f"rigid_radius = {rigid_radius} exceeds decay_radius = "
                         f"{decay_radius}")
    request.smoothing_iterations = _non_negative_int(smoothing_iterations,
                                                     "smoothing_iterations")
    request.boundary.CopyFrom(_boundary_selection(boundary))

    rigid = rotate_degrees is not None or translate is not None
    motions = [label for label, given in (("rotate_degrees/translate", rigid),
                                        ("control_displacements",
                                         control_displacements is not None),
                                        ("boundary_points", boundary_points is not None))
               if given]
    if len(motions) != 1:
        raise ValueError("give one motion: rotate_degrees (and/or translate), "
                         "control_displacements or boundary_points"
                         + (f"; got {', '.join(motions)}" if motions else ""))
    if not rigid and (about is not None or axis is not None):
        raise ValueError("about and axis belong to a rotation (rotate_degrees)")
    if rigid:
        _rigid_motion(request.rigid, rotate_degrees, about, axis, translate)
    elif control_displacements is not None:
        _control_motion(request.controls, control_displacements)
    else:
        _boundary_points_motion(request.boundary_points, boundary_points or ())
    return request


class _DeformCalls(_Calls):
    """The Client's deformation (DeformGrid)."""

    def deform(self, name: str, rotate_degrees: Optional[float] = None,
               about: Optional[Sequence[float]] = None,
               axis: Optional[Sequence[float]] = None,
               translate: Optional[Sequence[float]] = None,
               boundary: Union[None, str, FaceRangeLike,
                               Iterable[Union[str, FaceRangeLike]]] = None,
               reference_revision: int = 0, base_revision: int = 0, time: float = 0.0,
               step: int = 0, check_level: int = 0,
               control_displacements: Optional[ControlDisplacements] = None,
               boundary_points: Optional[Iterable[BoundaryPoints]] = None,
               propagation: str = "blend", decay_radius: float = 0.0,
               rigid_radius: float = 0.0,
               smoothing_iterations: int = 0,
               max_boundary_error: float = 0.0) -> service_pb2.DeformGridResponse:
        """Moves part of a revision's boundary, lets the grid follow, checks it for folded cells
        and stores it as a new revision (DeformGrid); returns the DeformGridResponse proto:
        ``revision`` and ``report`` (DeformReport: ``min_jacobian_ratio``,
        ``max_orthogonality_change_degrees``, ``moved_controls``, ``decay_radius``,
        ``boundary_error``, ``seconds``, ...).

        The motion is one of
          - a rigid motion: ``rotate_degrees`` about the axis ``axis`` (3 values; default z,
            the only axis of a 2-D grid, positive turning counter-clockwise) through ``about``
            (2 or 3 values; default the origin), then ``translate`` (2 or 3 values);
          - ``control_displacements``: ``{block: (controls, displacements)}``, control indices
            (i fastest) of moved controls and their displacements shaped ``(N, s)``; moved
            controls not listed stay;
          - ``boundary_points``: :class:`BoundaryPoints`, new positions (or displacements) of
            the points of boundary ranges at a refinement level, fitted with the stored basis
            by least squares. A boundary that misses them by more than
            ``max_boundary_error`` (0: twice the fit's tolerance of the moved boundary's kind) is refused with
            ``FAILED_PRECONDITION`` naming the point; ``report.boundary_error`` is the miss.

        ``boundary`` says what moves: ``"wall"`` (the default), ``"outer"``, ``"interface"``, a
        list of those, or face ranges (one or a list): ``(block, face, begin, end)`` tuples or
        dicts with those keys, ``face`` one of ``"imin"``, ..., ``"kmax"``, ``begin``/``end``
        ``(i, j[, k])`` grid indices inclusive at both ends. Kinds and ranges do not mix.

        ``reference_revision`` is the revision whose geometry is moved (0: the latest): giving
        the fit's revision every step makes the motions absolute (no drift).
        ``base_revision`` is the latest revision the caller has seen: if the grid has a newer
        one the call fails with ABORTED (0: no check). ``time`` and ``step`` stamp the new
        revision (see ``get``/``evaluate(step=...)``). ``check_level`` (0 to 4) is the
        refinement level of the fold check: set it to the level you evaluate at (level 0 does
        not see the folds of finer levels). ``propagation``: ``"blend"`` (free controls by
        their distance to the moved boundary) or ``"transfinite"`` (block interiors by Coons
        interpolation); ``decay_radius`` (0: the distance to the nearest fixed boundary),
        ``rigid_radius`` and ``smoothing_iterations`` shape it.

        A deformation that folds cells raises :class:`SplinegridError` with code
        ``FAILED_PRECONDITION`` and the server's message (how many cells, where); nothing is
        stored. Wrong arguments raise ``ValueError`` before any call.
        """
        request = _deform_request(name, rotate_degrees, about, axis, translate, boundary,
                                  reference_revision, base_revision, time, step, check_level,
                                  control_displacements, boundary_points, propagation,
                                  decay_radius, rigid_radius, smoothing_iterations,
                                  max_boundary_error)
        return self._unary(self.stub.DeformGrid, request, service_pb2.DeformGridResponse)
