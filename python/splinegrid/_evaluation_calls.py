"""Evaluation of stored splines: EvaluateGrid (blocks on a grid of parameters, streamed),
EvaluatePoints (parameter points, in batches under gRPC's message limit) and GetWallCurvature.
The requests are built and checked here before any call; the bulk responses are decoded by
``_evaluation``."""

from __future__ import annotations

from typing import Optional, Union

import numpy as np
import numpy.typing as npt

from splinegrid import _wire
from splinegrid._args import Blocks, Triple, _block_list, _extents, _set_step, grid_name
from splinegrid._calls import _Calls
from splinegrid._evaluation import _assemble
from splinegrid._transport import _Attempt, _routing_grid
from splinegrid.distributions import Distributions, _set_distributions
from splinegrid.errors import SplinegridError
from splinegrid.results import EvaluatedGrid, EvaluatedPoints, WallCurvatureLine
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

POINTS_BATCH_BYTES = 3 << 20  # EvaluatePoints request or response size per call
_PARAMETERS_FIELD = 4  # EvaluatePointsRequest.parameters (packed doubles)


def _evaluate_request(name: str, level: Optional[int], counts: Optional[Triple],
                      blocks: Blocks, index_box: Optional[tuple[Triple, Triple]],
                      derivatives: bool, dtype: npt.DTypeLike, revision: int,
                      step: Optional[int], distributions: Distributions = None
                      ) -> tuple[service_pb2.EvaluateGridRequest, _wire.Dtype]:
    """The EvaluateGridRequest of :meth:`Client.evaluate`'s arguments and the dtype of the
    result; ValueError naming the argument that is wrong."""
    out_dtype = np.dtype(dtype)
    if out_dtype not in (np.float64, np.float32):
        raise ValueError(f"dtype = {out_dtype}; use float64 or float32")
    if level is not None and counts is not None:
        raise ValueError("give level or counts, not both")
    block_list = _block_list(blocks)
    if len(set(block_list)) != len(block_list):
        # The chunks name blocks by index, so a repeated block could not be told apart.
        raise ValueError(f"blocks = {block_list} repeats a block")
    request = service_pb2.EvaluateGridRequest(
        name=grid_name(name), revision=revision, blocks=block_list,
        derivatives=derivatives,
        precision=(service_pb2.PRECISION_FLOAT if out_dtype == np.float32
                   else service_pb2.PRECISION_DOUBLE))
    _set_step(request, revision, step)
    if counts is not None:
        request.counts.CopyFrom(_extents(counts, "counts", fill=1))
    else:
        request.refinement_level = 0 if level is None else level
    if index_box is not None:
        begin, end = index_box
        request.index_box.begin.CopyFrom(_extents(begin, "index_box begin", fill=0))
        request.index_box.end.CopyFrom(_extents(end, "index_box end", fill=0))
    _set_distributions(request, distributions)
    return request, out_dtype


def _points_arguments(params: npt.ArrayLike, blocks: Union[int, npt.ArrayLike],
                      derivatives: bool, revision: int, step: Optional[int]
                      ) -> tuple[_wire.Array, _wire.Array, int]:
    """:meth:`Client.evaluate_points`'s parameters as an ``(N, 3)`` float64 array, its blocks
    (one, or one per point) and the points per call; ValueError naming what is wrong."""
    uvw = np.ascontiguousarray(params, dtype=_wire.DOUBLE)
    if uvw.ndim == 1 and uvw.size == 3:
        uvw = uvw.reshape(1, 3)
    if uvw.ndim != 2 or uvw.shape[1] != 3:
        raise ValueError(f"params has shape {uvw.shape}; expected (N, 3)")
    block_array = np.asarray(blocks, dtype=np.int64).reshape(-1)
    if block_array.size not in (1, len(uvw)):
        raise ValueError(f"{block_array.size} blocks for {len(uvw)} points; give one, "
                         "or one per point")
    if step is not None and revision != 0:
        raise ValueError(f"give revision ({revision}) or step ({step}), not both")
    # Bytes per point: 24 of parameters + up to 5 of block index in the request; up to
    # 3 coordinates x (1 or 4 fields) x 9 in the response (the server's own estimate).
    per_point = max(29, 3 * (4 if derivatives else 1) * 9)
    return uvw, block_array, max(1, POINTS_BATCH_BYTES // per_point)


def _points_request(name: str, uvw: _wire.Array, block_array: _wire.Array, at: int, batch: int,
                    derivatives: bool, revision: int, step: Optional[int]
                    ) -> tuple[service_pb2.EvaluatePointsRequest, bytes]:
    """The EvaluatePointsRequest of the points ``at`` to ``at + batch``: its head (every field
    but the parameters, for routing) and the request's bytes (the head + the parameters)."""
    head = service_pb2.EvaluatePointsRequest(
        name=grid_name(name), revision=revision, derivatives=derivatives,
        blocks=(block_array if block_array.size == 1
                else block_array[at:at + batch]).tolist())
    if step is not None:
        head.step = int(step)
    return head, head.SerializeToString() + _wire.packed_doubles(_PARAMETERS_FIELD,
                                                                 uvw[at:at + batch])


def _joined_points(parts: list[EvaluatedPoints], derivatives: bool) -> EvaluatedPoints:
    """The batches' results as one (the revision of the first)."""
    if len(parts) == 1:
        return parts[0]
    joined = {f: np.concatenate([getattr(part, f) for part in parts])
              for f in (("points", "du", "dv", "dw") if derivatives else ("points",))}
    return EvaluatedPoints(parts[0].revision, **joined)


def _wall_curvature_lines(response: service_pb2.GetWallCurvatureResponse
                          ) -> list[WallCurvatureLine]:
    """GetWallCurvatureResponse -> one WallCurvatureLine per line, points ``(n, s)``."""
    dim = response.spatial_dim
    return [WallCurvatureLine(
        block=line.block, direction=line.direction,
        start=(line.start.i, line.start.j, line.start.k),
        arc_length=np.asarray(line.arc_length, dtype=np.float64),
        points=np.asarray(line.points, dtype=np.float64).reshape(-1, dim),
        curvature=np.asarray(line.curvature, dtype=np.float64)) for line in response.lines]


class _EvaluationCalls(_Calls):
    """The Client's evaluation calls."""

    def evaluate(self, name: str, level: Optional[int] = None,
                 counts: Optional[Triple] = None, blocks: Blocks = None,
                 index_box: Optional[tuple[Triple, Triple]] = None,
                 derivatives: bool = False, dtype: npt.DTypeLike = np.float64,
                 revision: int = 0, step: Optional[int] = None,
                 distributions: Distributions = None) -> EvaluatedGrid:
        """Evaluates blocks of a revision (0: latest) on a grid of parameters.

        Resolution: ``level`` l puts 2^l - 1 new points in every original interval (0, the
        default, gives the original points), or ``counts`` ``(ni, nj[, nk])`` points per
        direction (a missing entry: 1; a count of 1 takes the first index of the block or box),
        both following the original clustering. ``blocks``: an
        index or indices (None: all, in order). ``index_box``: ``(begin, end)``, each
        ``(i, j[, k])`` in original grid indices, inclusive at both ends (missing: 0).
        ``dtype`` float32 transfers single precision (half the bytes). ``step``: instead of
        ``revision``, the latest revision stamped with this solver time step (the result's
        ``revision`` says which one). ``distributions``: another point distribution per
        direction, ``{"j": Distribution.geometric(2e-6)}`` for a new wall spacing, or
        ``{"i": "uniform_arc_length"}`` (see :class:`Distribution`; the ends stay those of the
        block or ``index_box``; with float32 a first spacing under about 1e-7 of the
        coordinates is lost in transfer).

        Returns an :class:`EvaluatedGrid`, a list of :class:`EvaluatedBlock` whose arrays are
        shaped ``(nk, nj, ni, s)`` with ``dtype``.
        """
        request, out_dtype = _evaluate_request(name, level, counts, blocks, index_box,
                                               derivatives, dtype, revision, step,
                                               distributions)

        def attempt(a: _Attempt) -> EvaluatedGrid:
            call = self._evaluate_grid(request, timeout=a.timeout, metadata=a.metadata)
            try:
                return _assemble(call, out_dtype, self.max_evaluation_bytes)
            except SplinegridError:
                call.cancel()
                raise

        return self._call(attempt, _routing_grid(request))

    def evaluate_points(self, name: str, params: npt.ArrayLike,
                        blocks: Union[int, npt.ArrayLike] = 0, derivatives: bool = False,
                        revision: int = 0, step: Optional[int] = None) -> EvaluatedPoints:
        """Evaluates N parameter points ``params`` (shape ``(N, 3)``: u, v, w in [0, 1]; use
        w = 0 for a 2-D block) of block ``blocks`` (one index for all, or one per point).

        Returns :class:`EvaluatedPoints` with arrays shaped ``(N, s)``. Requests and responses
        must stay under gRPC's 4 MiB message limit, so large N is sent in several calls (each
        with its own deadline), all pinned to the revision the first one evaluated. ``step``:
        instead of ``revision``, the latest revision stamped with this solver time step.
        """
        uvw, block_array, batch = _points_arguments(params, blocks, derivatives, revision,
                                                    step)
        parts: list[EvaluatedPoints] = []
        for at in range(0, max(len(uvw), 1), batch):
            # Later batches: the revision the first one evaluated.
            head, request = _points_request(name, uvw, block_array, at, batch, derivatives,
                                            revision, None if parts else step)
            parts.append(self._unary(self._evaluate_points, request, EvaluatedPoints,
                                     _routing_grid(head)))
            revision = parts[0].revision
        return _joined_points(parts, derivatives)

    def wall_curvature(self, name: str, revision: int = 0, level: int = 2,
                       blocks: Blocks = None) -> list[WallCurvatureLine]:
        """Curvature along every wall grid line of revision ``revision`` (0: latest), sampled at
        refinement level ``level`` (2**level - 1 samples between grid points)."""
        request = service_pb2.GetWallCurvatureRequest(
            name=grid_name(name), revision=revision, refinement_level=level,
            blocks=_block_list(blocks))
        return _wall_curvature_lines(self._unary(self.stub.GetWallCurvature, request,
                                                 service_pb2.GetWallCurvatureResponse))
