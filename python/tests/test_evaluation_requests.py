"""Evaluation requests and responses without a server (EvaluateGrid requests, EvaluatePoints
arguments, batches and joined results, wall curvature lines), and evaluate_points in several
batches against an in-process fake server: every point once, in order, all batches pinned to
the revision of the first."""

import numpy as np
import pytest

from splinegrid import EvaluatedPoints
from splinegrid import _evaluation_calls
from splinegrid._evaluation_calls import (POINTS_BATCH_BYTES, _evaluate_request,
                                          _joined_points, _points_arguments, _points_request,
                                          _wall_curvature_lines)
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

from conftest import fake_client


def evaluate(name="naca", level=None, counts=None, blocks=None, index_box=None,
             derivatives=False, dtype=np.float64, revision=0, step=None):
    """_evaluate_request with Client.evaluate's defaults."""
    return _evaluate_request(name, level, counts, blocks, index_box, derivatives, dtype,
                             revision, step)


class TestEvaluateRequest:
    def test_defaults_are_the_original_points_in_double(self):
        request, dtype = evaluate()
        assert dtype == np.float64
        assert (request.name, request.refinement_level, list(request.blocks)) == (
            "grids/naca", 0, [])
        assert request.precision == service_pb2.PRECISION_DOUBLE
        assert request.WhichOneof("resolution") == "refinement_level"

    def test_counts_box_blocks_and_float(self):
        request, dtype = evaluate(counts=(33, 9), blocks=np.int64(2),
                                  index_box=((1, 2), (10, 20, 0)), derivatives=True,
                                  dtype="float32", step=8)
        assert dtype == np.float32 and request.precision == service_pb2.PRECISION_FLOAT
        assert (request.counts.i, request.counts.j, request.counts.k) == (33, 9, 1)
        assert list(request.blocks) == [2] and request.derivatives and request.step == 8
        box = request.index_box
        assert (box.begin.i, box.begin.j, box.begin.k, box.end.i, box.end.j) == (1, 2, 0, 10, 20)

    @pytest.mark.parametrize("kwargs, message", [
        (dict(dtype=np.int32), "dtype = int32; use float64 or float32"),
        (dict(level=1, counts=(3, 3)), "give level or counts, not both"),
        (dict(blocks=[0, 1, 0]), r"blocks = \[0, 1, 0\] repeats a block"),
        (dict(revision=3, step=1), r"give revision \(3\) or step \(1\), not both"),
        (dict(counts=()), r"counts = \[\]; give 1 to 3 integers"),
        (dict(index_box=((0, 0, 0, 0), (1, 1))), r"index_box begin = \[0, 0, 0, 0\]"),
    ])
    def test_wrong_arguments_are_named(self, kwargs, message):
        with pytest.raises(ValueError, match=message):
            evaluate(**kwargs)


class TestPoints:
    def test_arguments_and_batch_sizes(self):
        uvw, blocks, batch = _points_arguments([0.5, 0.25, 0.0], 3, False, 0, None)
        assert uvw.shape == (1, 3) and uvw.dtype == np.float64
        assert list(blocks) == [3]
        assert batch == POINTS_BATCH_BYTES // 29        # 24 + 5 bytes a point in the request
        assert _points_arguments(np.zeros((2, 3)), [0, 1], True, 0, None)[2] == (
            POINTS_BATCH_BYTES // 108)                  # 3 coordinates x 4 fields x 9 back

    @pytest.mark.parametrize("params, blocks, revision, step, message", [
        (np.zeros((4, 2)), 0, 0, None, r"params has shape \(4, 2\); expected \(N, 3\)"),
        (np.zeros((4, 3)), [0, 1], 0, None, "2 blocks for 4 points; give one, or one per"),
        (np.zeros((4, 3)), 0, 2, 5, r"give revision \(2\) or step \(5\), not both"),
    ])
    def test_wrong_arguments_are_named(self, params, blocks, revision, step, message):
        with pytest.raises(ValueError, match=message):
            _points_arguments(params, blocks, False, revision, step)

    def test_a_batch_is_a_slice_of_points_and_blocks(self):
        uvw = np.arange(15.0).reshape(5, 3)
        blocks = np.array([0, 1, 2, 3, 4])
        head, data = _points_request("naca", uvw, blocks, 2, 2, True, 0, 9)
        request = service_pb2.EvaluatePointsRequest.FromString(data)
        assert (request.name, list(request.blocks), request.step) == ("grids/naca", [2, 3], 9)
        assert list(request.parameters) == list(range(6, 12)) and request.derivatives
        assert head.name == "grids/naca" and len(head.parameters) == 0  # routing only
        one_block, _ = _points_request("naca", uvw, np.array([7]), 2, 2, False, 4, None)
        assert list(one_block.blocks) == [7] and one_block.revision == 4
        assert not one_block.HasField("step")

    def test_joined_batches(self):
        parts = [EvaluatedPoints(5, np.zeros((2, 2)), np.ones((2, 2)), np.ones((2, 2)),
                                 np.ones((2, 2))),
                 EvaluatedPoints(5, np.ones((1, 2)), np.zeros((1, 2)), np.zeros((1, 2)),
                                 np.zeros((1, 2)))]
        joined = _joined_points(parts, True)
        assert joined.revision == 5
        assert joined.points.tolist() == [[0, 0], [0, 0], [1, 1]]
        assert joined.du.tolist() == [[1, 1], [1, 1], [0, 0]]
        assert _joined_points(parts[:1], False) is parts[0]
        assert _joined_points(parts, False).du is None


def test_wall_curvature_lines_are_shaped_by_the_spatial_dimension():
    response = service_pb2.GetWallCurvatureResponse(spatial_dim=3, lines=[
        service_pb2.WallCurvatureLine(block=1, direction=0, start=grid_pb2.Extents(i=0, j=0,
                                                                                   k=4),
                                      arc_length=[0.0, 0.5], points=[0, 0, 0, 0.5, 0, 0],
                                      curvature=[0.0, -2.0])])
    (line,) = _wall_curvature_lines(response)
    assert (line.block, line.direction, line.start) == (1, 0, (0, 0, 4))
    assert line.points.shape == (2, 3) and line.points[1].tolist() == [0.5, 0.0, 0.0]
    assert line.arc_length.tolist() == [0.0, 0.5] and line.curvature.tolist() == [0.0, -2.0]
    assert _wall_curvature_lines(service_pb2.GetWallCurvatureResponse()) == []


class PointsServer(service_grpc.SplineGridServicer):
    """Answers EvaluatePoints with (u, v + block) per point at revision 5 and keeps the
    requests."""

    def __init__(self):
        self.requests = []

    def EvaluatePoints(self, request, context):
        self.requests.append(request)
        uvw = np.asarray(request.parameters).reshape(-1, 3)
        blocks = np.broadcast_to(np.asarray(request.blocks), len(uvw))
        points = np.stack([uvw[:, 0], uvw[:, 1] + blocks], axis=1)
        return service_pb2.EvaluatePointsResponse(revision=5, spatial_dim=2,
                                                   points=points.reshape(-1).tolist())


def test_evaluate_points_in_batches_pinned_to_the_first_revision(monkeypatch):
    monkeypatch.setattr(_evaluation_calls, "POINTS_BATCH_BYTES", 29 * 4)  # 4 points a call
    fake = PointsServer()
    with fake_client(fake) as client:
        uvw = np.stack([np.linspace(0, 1, 10), np.linspace(0, 0.1, 10), np.zeros(10)], 1)
        result = client.evaluate_points("naca", uvw, blocks=np.arange(10), step=3)
    assert [len(r.blocks) for r in fake.requests] == [4, 4, 2]
    assert [(r.revision, r.HasField("step")) for r in fake.requests] == [
        (0, True), (5, False), (5, False)]
    assert fake.requests[0].step == 3
    assert result.revision == 5 and result.points.shape == (10, 2)
    assert np.allclose(result.points[:, 0], uvw[:, 0])
    assert np.allclose(result.points[:, 1], uvw[:, 1] + np.arange(10))
