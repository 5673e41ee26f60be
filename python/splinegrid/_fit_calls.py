"""Fits of a grid's source points (FitGrid) and refits with fairing (FairGrid): the requests
built from the Client's arguments (checked before any call), and the two calls."""

from __future__ import annotations

from typing import Optional, Union

from splinegrid._args import FaceKindsLike, Triple, _face_kinds, _fairing, _fit_spec, grid_name
from splinegrid._calls import _Calls
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2


def _fit_request(name: str, control_counts: Optional[Triple], tolerance: Optional[float],
                 order: int, max_controls: int,
                 boundary_tolerances: Optional[dict[str, float]],
                 fairing: Union[None, str, float], allow_folds: bool,
                 ref_length: Optional[float],
                 face_kinds: Optional[FaceKindsLike]) -> service_pb2.FitGridRequest:
    """The FitGridRequest of :meth:`Client.fit`'s arguments; ValueError for a combination the
    fit does not take. ``ref_length`` and ``face_kinds`` belong to the tolerances by kind:
    either implies ``boundary_tolerances={}`` (all defaults) when none is given."""
    if ref_length is not None:
        if tolerance is not None or control_counts is not None:
            raise ValueError("ref_length applies to the tolerances by kind; tolerance and "
                             "control_counts are absolute")
        if not float(ref_length) > 0.0:
            raise ValueError(f"ref_length = {ref_length}; give a positive length")
        if boundary_tolerances is None:
            boundary_tolerances = {}
    if face_kinds is not None:
        if tolerance is not None or control_counts is not None:
            raise ValueError("face_kinds apply to the tolerances by kind; tolerance and "
                             "control_counts do not use kinds")
        if boundary_tolerances is None:
            boundary_tolerances = {}
    spec = _fit_spec(control_counts, tolerance, order, max_controls, boundary_tolerances,
                     fairing)
    if face_kinds is not None:
        spec.face_kinds.extend(_face_kinds(face_kinds))
    spec.allow_folds = bool(allow_folds)
    if ref_length is not None:
        spec.reference_length = float(ref_length)
    return service_pb2.FitGridRequest(name=grid_name(name), spec=spec)


def _fair_request(name: str, revision: int, fairing: Union[None, str, float],
                  allow_folds: bool) -> service_pb2.FairGridRequest:
    """The FairGridRequest of :meth:`Client.fair`'s arguments (no ``fairing``: the server's
    default); ValueError for a fairing that is neither "tol" nor a positive weight."""
    request = service_pb2.FairGridRequest(name=grid_name(name), revision=revision,
                                          allow_folds=bool(allow_folds))
    if fairing is not None:
        request.fairing.CopyFrom(_fairing(fairing))
    return request


class _FitCalls(_Calls):
    """The Client's fits (FitGrid, FairGrid)."""

    def fit(self, name: str, control_counts: Optional[Triple] = None,
            tolerance: Optional[float] = None, order: int = 4,
            max_controls: int = 0,
            boundary_tolerances: Optional[dict[str, float]] = None,
            fairing: Union[None, str, float] = None,
            allow_folds: bool = False,
            ref_length: Optional[float] = None,
            face_kinds: Optional[FaceKindsLike] = None) -> service_pb2.FitGridResponse:
        """Fits the grid's source points; the result is stored as a new revision.

        Give one of ``control_counts`` ``(a, b)`` or ``(a, b, c)`` (control points per
        direction i, j, k for every block; 0 or a missing entry: as many as points), a
        ``tolerance`` (largest deviation of every point, in the grid's length unit) or
        ``boundary_tolerances``, a dict with any of ``wall``, ``interface``, ``outer``,
        ``interior``, ``edge`` and ``first_layer`` (missing: the paper's 0.15e-3, 2e-3, 8e-3, no
        interior tolerance, edge 0.5, first layer off; ``{}`` takes all defaults). ``edge`` and
        ``first_layer`` are relative (``first_layer=0.05``: every first-layer height at the
        walls, what a solver's y+ follows, within 5%; the report's
        ``deviation_by_kind.first_layer`` gives the change either way); the other values given
        are lengths in the grid's unit; the defaults are fractions of the grid's reference
        length: ``ref_length`` (implies ``boundary_tolerances={}`` when none is given; refused
        with ``tolerance`` or ``control_counts``, which are absolute), else detected by the server as the largest
        extent of a wall (an airfoil's chord; the bounding-box diagonal without walls), so a
        grid in chords, millimetres or inches is fitted alike. The report states it
        (``reference_length``, ``reference_length_description``) and the tolerances held
        (``tolerances``). With tolerances, knots are added until
        they are met or ``max_controls`` per direction (0 = no cap) is reached, and the fit is
        watertight across blocks. Neither: interpolate.

        ``fairing``: ``"tol"`` (the largest fairing weight within the tolerances) or a weight.

        ``face_kinds``: explicit boundary kinds of block faces, overriding the server's
        classification: a dict ``{(block, face): kind}``, a list of ``"BLOCK:FACE=KIND"``
        strings, or one such string with commas (as the CLI's ``--face``); FACE is ``imin``,
        ``imax``, ``jmin``, ``jmax``, ``kmin`` or ``kmax``, KIND ``wall``, ``interface`` or
        ``outer`` (there is no symmetry kind). Implies ``boundary_tolerances={}`` when none
        is given; refused with ``tolerance`` or ``control_counts``. A bad entry raises
        ValueError naming it.

        A fit whose cells fold at refinement levels 0-2 (after the server's repair, tolerance
        fits only) raises a FAILED_PRECONDITION error naming the cells and stores nothing,
        unless ``allow_folds`` is true: then the revision is stored and its ``report`` says
        ``quality_met = False`` with ``folded_cells``.

        Returns the FitGridResponse proto: ``revision``, ``num_points``,
        ``num_control_points``, ``compression_ratio``, ``max_deviation``, ``seconds``,
        ``blocks`` (one BlockFitSummary per block: deviation overall and per boundary kind,
        cell quality, tolerance outcome) and ``report`` (FitReport: tolerances met, cell
        validity at refinement levels 0-2, connectivity and gaps, fairing weight, wall
        curvature before and after fairing).
        """
        request = _fit_request(name, control_counts, tolerance, order, max_controls,
                               boundary_tolerances, fairing, allow_folds, ref_length,
                               face_kinds)
        return self._unary(self.stub.FitGrid, request, service_pb2.FitGridResponse)

    def fair(self, name: str, revision: int = 0,
             fairing: Union[None, str, float] = None,
             allow_folds: bool = False) -> service_pb2.FitGridResponse:
        """Refits revision ``revision`` (0: latest) with fairing and stores a new revision.
        A faired fit that folds cells is refused (FAILED_PRECONDITION) unless ``allow_folds``.

        ``fairing``: ``"tol"``, a weight, or None (the server's default: to tolerance for a
        revision fitted to tolerances). Returns the FitGridResponse of the new revision; its
        report compares the wall curvature with and without fairing.
        """
        request = _fair_request(name, revision, fairing, allow_folds)
        return self._unary(self.stub.FairGrid, request, service_pb2.FitGridResponse)
