"""What the client's calls return beyond the generated protos: NumPy-backed results and the
argument records of :meth:`Client.deform`. Arrays follow the package's convention
(``(nk, nj, ni, s)``, C order, i fastest; see :mod:`splinegrid.client`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Mapping, NamedTuple, Optional, Union

import numpy.typing as npt

from splinegrid._wire import Array
from splinegrid.v1 import grid_pb2


# A face range: a grid_pb2.FaceRange, a (block, face, begin, end) tuple or a dict with those
# keys; face "imin" ... "kmax" (or the BlockFace value), begin/end (i, j[, k]) inclusive.
FaceRangeLike = Union[grid_pb2.FaceRange, tuple[Any, ...], Mapping[str, Any]]


class ArchiveSummary(NamedTuple):
    """What :meth:`Client.export_grid` wrote: the archive's header (an ``ArchiveHeader``
    proto), its source chunk and revision records, and the file's size in bytes."""
    header: Any
    source_chunks: int
    revisions: int
    bytes: int


@dataclass


class EvaluatedBlock:
    """One evaluated block: ``points`` and, when asked for, ``du``/``dv``/``dw``.

    All arrays are shaped ``(nk, nj, ni, s)`` (C order, i fastest); the derivatives are
    dX/du, dX/dv, dX/dw with respect to the block's spline parameters.
    """

    block: int
    points: Array
    du: Optional[Array] = None
    dv: Optional[Array] = None
    dw: Optional[Array] = None


class EvaluatedGrid(list[EvaluatedBlock]):
    """The blocks of one evaluation in the order asked for: a list with two more attributes,
    the ``revision`` that was evaluated and ``spatial_dim`` (s)."""

    def __init__(self, revision: int, spatial_dim: int,
                 blocks: Iterable[EvaluatedBlock] = ()) -> None:
        super().__init__(blocks)
        self.revision = revision
        self.spatial_dim = spatial_dim


@dataclass


class EvaluatedPoints:
    """The result of :meth:`Client.evaluate_points`: arrays shaped ``(N, s)``."""

    revision: int
    points: Array
    du: Optional[Array] = None
    dv: Optional[Array] = None
    dw: Optional[Array] = None


class BoundaryPoints(NamedTuple):
    """New positions (or, with ``displacements=True``, displacements) of the points of one face
    range at refinement level ``level``, for :meth:`Client.deform`: ``coordinates`` is shaped
    ``(N, s)`` with the range's points at that level in point order (i fastest)."""
    range: FaceRangeLike
    coordinates: npt.ArrayLike
    level: int = 0
    displacements: bool = False


class WallCurvatureLine(NamedTuple):
    """Curvature samples along one wall grid line (points start + t e_direction of a block)."""
    block: int
    direction: int           # 0 i, 1 j, 2 k
    start: tuple[int, int, int]
    arc_length: Array   # (n,)
    points: Array       # (n, spatial_dim)
    curvature: Array    # (n,), signed in 2-D (positive turning left)


@dataclass
class SplineArrays:
    """One B-spline block of a revision as NumPy arrays (:meth:`Client.get` with
    ``full=True``).

    ``control_points`` is shaped ``(nck, ncj, nci, s)`` in C order, like evaluated points:
    ``control_points[c, b, a]`` is control point ``(a, b, c)``, i fastest (the service's
    "coordinates interleaved, i fastest"); ``s`` is ``spatial_dim`` (2 or 3) and an unused
    direction has one control point (a surface: ``nck = 1``). Per direction i, j, k:
    ``orders`` (k, degree k - 1; 1 for an unused direction), ``knots`` (clamped, n + k values),
    ``parameters`` (the data parameter of every original grid index) and ``breaks`` (grid
    indices where that map is interpolated in separate pieces). ``fit`` is the block's
    ``BlockFitSummary`` proto.
    """

    index: int
    spatial_dim: int
    orders: tuple[int, int, int]
    control_points: Array
    knots: tuple[Array, Array, Array]
    parameters: tuple[Array, Array, Array]
    breaks: tuple[Array, Array, Array]
    fit: grid_pb2.BlockFitSummary

    @property
    def control_counts(self) -> tuple[int, int, int]:
        """Control points per direction ``(nci, ncj, nck)``."""
        nck, ncj, nci = self.control_points.shape[:3]
        return nci, ncj, nck


@dataclass
class FullGrid:
    """:meth:`Client.get` with ``full=True``: the ``Grid`` proto (FULL view) and the splines
    of its revision as NumPy arrays, one :class:`SplineArrays` per block asked for.

    The bulk numbers live only in ``blocks``: in ``grid.revision.blocks`` the fields
    ``control_points`` and, per direction, ``knots``, ``parameters`` and ``breaks`` are
    cleared; everything else (orders, control counts, fit summaries, the source grid's
    connectivity, the revision's report) is there as the server sent it.
    """

    grid: grid_pb2.Grid
    blocks: list[SplineArrays]

    @property
    def name(self) -> str:
        return self.grid.name

    @property
    def revision(self) -> int:
        """The revision these splines are of."""
        return self.grid.revision.revision
