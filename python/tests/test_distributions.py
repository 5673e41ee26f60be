"""Distributions on demand: ``Client.evaluate(distributions=...)`` builds the request, refuses
bad arguments before any call, and against the real server gives a new wall spacing on the
fitted RAE 2822 C-grid while keeping the wall and the far field, and names the field the server
refuses."""

import numpy as np
import pytest

from splinegrid import Client, Distribution, SplinegridError
from splinegrid._evaluation_calls import _evaluate_request
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

from conftest import DATA


def request_with(distributions):
    request, _ = _evaluate_request("g", 1, None, None, None, False, np.float64, 0, None,
                                   distributions)
    return request


class TestRequest:
    def test_kinds_reach_the_request(self):
        request = request_with({"i": "uniform_arc_length", "j": Distribution.geometric(1e-5, True),
                                "k": Distribution("uniform_parameter")})
        d = request.distributions
        assert d.i.kind == service_pb2.Distribution.KIND_UNIFORM_ARC_LENGTH
        assert d.j.kind == service_pb2.Distribution.KIND_GEOMETRIC
        assert (d.j.first_spacing, d.j.from_end) == (1e-5, True)
        assert d.k.kind == service_pb2.Distribution.KIND_UNIFORM_PARAMETER
        assert not request_with(None).HasField("distributions")

    @pytest.mark.parametrize("distributions, message", [
        ({"x": "original"}, "distributions key 'x'"),
        ({"i": "tanh"}, "Distribution kind = 'tanh'"),
        ({"j": 3}, r"distributions\['j'\] = 3"),
    ])
    def test_wrong_arguments_are_named(self, distributions, message):
        with pytest.raises(ValueError, match=message):
            request_with(distributions)

    @pytest.mark.parametrize("kwargs, message", [
        (dict(kind="geometric"), "first_spacing = 0.0"),
        (dict(kind="geometric", first_spacing=float("nan")), "first_spacing = nan"),
        (dict(kind="uniform_arc_length", first_spacing=1.0), "only for 'geometric'"),
        (dict(kind="original", from_end=True), "only for 'geometric'"),
    ])
    def test_wrong_distributions_are_named(self, kwargs, message):
        with pytest.raises(ValueError, match=message):
            Distribution(**kwargs)


def test_real_server_new_wall_spacing(server):
    """RAE 2822 257x97 (walls at j = 0): a first spacing of 1e-6 chords at level 1. The wall
    row and the outer row are the original distribution's; the first interval off the wall is
    1e-6 on every line: its arc length exactly (the kernel tests check that); the straight
    distance measured here is shorter where the fitted line bends inside its first original
    interval (up to 0.4% near the leading edge: below the fit's tolerance the spline is not
    held to the data's shape); every cell keeps its orientation."""
    with Client(server, timeout=120) as client:
        client.import_file(DATA / "grids" / "rae2822_257x97.fmt", grid_id="rae")
        client.fit("rae", boundary_tolerances={})
        before = client.evaluate("rae", level=1)[0].points[0]           # (nj, ni, 2)
        after = client.evaluate("rae", level=1,
                                distributions={"j": Distribution.geometric(1e-6)})[0].points[0]
        assert after.shape == before.shape
        np.testing.assert_allclose(after[0], before[0], rtol=0, atol=1e-13)
        np.testing.assert_allclose(after[-1], before[-1], rtol=1e-13, atol=1e-12)
        first = np.linalg.norm(after[1] - after[0], axis=-1)
        np.testing.assert_allclose(first, 1e-6, rtol=1e-2)
        assert np.all(first <= 1e-6 * (1 + 1e-9))  # a chord never exceeds its arc

        def signed_areas(x):
            a, b, c, d = x[:-1, :-1], x[:-1, 1:], x[1:, 1:], x[1:, :-1]
            cross = lambda p, q: p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]
            return cross(a, b) + cross(b, c) + cross(c, d) + cross(d, a)

        orientation = np.sign(signed_areas(before))
        assert np.all(orientation == orientation.flat[0])
        assert np.all(np.sign(signed_areas(after)) == orientation.flat[0])

        with pytest.raises(SplinegridError, match=r"distributions.j.first_spacing = 1000 is not "
                                                  r"below the length"):
            client.evaluate("rae", level=0, distributions={"j": Distribution.geometric(1000)})
        with pytest.raises(SplinegridError, match="both measured"):
            client.evaluate("rae", level=0, distributions={"i": "uniform_arc_length",
                                                           "j": Distribution.geometric(1e-6)})


def test_an_evaluation_over_max_evaluation_bytes_is_refused_when_its_header_arrives(server):
    # As the C++ client's ClientOptions::max_evaluation_bytes: refused before anything is
    # allocated, naming the sizes; within the cap, or without one, it is assembled.
    with Client(server) as client:
        client.import_file(DATA / "grids" / "n0012_113-33.p2dfmt", grid_id="small")
        client.fit("small", boundary_tolerances={})
    one_level = 225 * 65 * 2 * 8  # level 1 of the 113 x 33 grid, 2 doubles a point
    with Client(server, max_evaluation_bytes=one_level - 1) as client:
        with pytest.raises(SplinegridError, match=r"RESOURCE_EXHAUSTED.*holds 14625 points"):
            client.evaluate("small", level=1)
        assert client.evaluate("small", level=1, dtype=np.float32)[0].points.shape == (1, 65, 225, 2)
    with Client(server, max_evaluation_bytes=one_level) as client:
        assert client.evaluate("small", level=1)[0].points.shape == (1, 65, 225, 2)
    with pytest.raises(ValueError, match="max_evaluation_bytes = 0"):
        Client(server, max_evaluation_bytes=0)
