"""``get(full=True)``: the revision's splines as NumPy arrays, control points shaped
``(nck, ncj, nci, s)`` with control (a, b, c) at ``[c, b, a]``, knots and point distributions
per direction; decoded from wire bytes, checked against the proto and against the real
server (a clamped spline passes through its corner control points)."""

from concurrent import futures

import grpc
import numpy as np
import pytest

from splinegrid import Client, FullGrid, RetryPolicy, SplinegridError
from splinegrid._splines import decode_full_grid
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

from conftest import DATA


def clamped(n, k):
    """A clamped knot vector of n controls of order k."""
    inner = np.linspace(0, 1, n - k + 2)[1:-1]
    return np.concatenate([np.zeros(k), inner, np.ones(k)])


def full_grid(counts=(5, 4, 3), s=3, blocks=2):
    """A FULL Grid whose control point (a, b, c) of block m holds (a, b, c + 10 m)[:s]."""
    grid = grid_pb2.Grid(name="grids/g", latest_revision=2)
    grid.revision.revision = 2
    for m in range(blocks):
        block = grid.revision.blocks.add(index=m, spatial_dim=s)
        block.fit.max_deviation = 0.5 * m
        for n in counts:
            k = min(4, n) if n > 1 else 1
            block.directions.add(order=k, num_controls=n, knots=clamped(n, k).tolist() if n > 1
                                 else [], parameters=np.linspace(0, 1, 2 * n).tolist(),
                                 breaks=[0, 2 * n - 1])
        values = [(a, b, c + 10 * m)[:s] for c in range(counts[2]) for b in range(counts[1])
                  for a in range(counts[0])]
        block.control_points.extend(np.asarray(values, dtype=float).reshape(-1).tolist())
    return grid


class TestDecode:
    def test_shapes_and_order(self):
        full = decode_full_grid(full_grid().SerializeToString())
        assert isinstance(full, FullGrid) and full.revision == 2 and full.name == "grids/g"
        assert len(full.blocks) == 2
        for m, block in enumerate(full.blocks):
            assert block.index == m and block.spatial_dim == 3
            assert block.control_points.shape == (3, 4, 5, 3)      # (nck, ncj, nci, s)
            assert block.control_counts == (5, 4, 3)
            assert block.orders == (4, 4, 3)
            assert block.control_points.dtype == np.float64
            assert block.control_points.flags.writeable
            c, b, a = 2, 1, 3
            np.testing.assert_array_equal(block.control_points[c, b, a], [a, b, c + 10 * m])
            np.testing.assert_array_equal(block.knots[0], clamped(5, 4))
            assert block.knots[2].size == 3 + 3
            assert block.parameters[1].shape == (8,) and block.breaks[0].tolist() == [0, 9]
            assert block.fit.max_deviation == 0.5 * m

    def test_a_surface(self):
        full = decode_full_grid(full_grid(counts=(6, 5, 1), s=2, blocks=1).SerializeToString())
        (block,) = full.blocks
        assert block.control_points.shape == (1, 5, 6, 2)
        assert block.knots[2].size == 0 and block.orders[2] == 1

    def test_bulk_fields_leave_the_proto(self):
        full = decode_full_grid(full_grid().SerializeToString())
        for block in full.grid.revision.blocks:
            assert len(block.control_points) == 0
            assert all(len(d.knots) == len(d.parameters) == len(d.breaks) == 0
                       for d in block.directions)
            assert [d.num_controls for d in block.directions] == [5, 4, 3]

    def test_a_short_net_is_data_loss(self):
        grid = full_grid()
        del grid.revision.blocks[1].control_points[-3:]
        with pytest.raises(SplinegridError) as error:
            decode_full_grid(grid.SerializeToString())
        assert error.value.code == "DATA_LOSS" and "block 1" in error.value.message

    def test_matches_the_generated_class(self):
        """The wire path gives what the generated class holds, value for value."""
        grid = full_grid(counts=(40, 30, 20))
        grid.revision.blocks[0].control_points[:] = np.random.default_rng(1).normal(
            size=40 * 30 * 20 * 3).tolist()
        full = decode_full_grid(grid.SerializeToString())
        for block, arrays in zip(grid.revision.blocks, full.blocks):
            np.testing.assert_array_equal(arrays.control_points.reshape(-1),
                                          np.array(block.control_points))


class FullGridServer(service_grpc.SplineGridServicer):
    def GetGrid(self, request, context):
        grid = full_grid()
        if request.view != service_pb2.GRID_VIEW_FULL:
            del grid.revision.blocks[:]
        return grid


def test_get_full_through_a_call():
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=2))
    service_grpc.add_SplineGridServicer_to_server(FullGridServer(), server)
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    try:
        with Client(f"127.0.0.1:{port}", timeout=10,
                    retry=RetryPolicy(max_attempts=1)) as client:
            basic = client.get("g")
            assert isinstance(basic, grid_pb2.Grid) and not basic.revision.blocks
            full = client.get("g", full=True)
            assert full.blocks[1].control_points.shape == (3, 4, 5, 3)
    finally:
        server.stop(0)


def test_real_server_corners(server):
    """A clamped B-spline interpolates its corner control points: the evaluated corners of
    the fitted grid are the corners of the control net, in the same array order."""
    with Client(server, timeout=120) as client:
        client.import_file(DATA / "grids" / "n0012_113-33.p2dfmt", grid_id="corners")
        client.fit("corners", control_counts=(24, 12), allow_folds=True)  # folds do not matter
        full = client.get("corners", full=True)
        (block,) = full.blocks
        assert block.control_points.shape == (1, 12, 24, 2)
        assert [len(k) for k in block.knots[:2]] == [24 + 4, 12 + 4]
        assert block.parameters[0].size == 113 and block.parameters[1].size == 33
        points = client.evaluate("corners", level=0)[0].points       # (1, 33, 113, 2)
        for j, i in ((0, 0), (-1, 0), (0, -1), (-1, -1)):
            np.testing.assert_allclose(points[0, j, i], block.control_points[0, j, i],
                                       atol=1e-12)
        client.delete("corners")
