"""Volume grids off a stored surface (``Client.generate_volume``): arguments checked before any
call, and against the real server the shared six-block sphere marched outward: every hexahedron
right-handed at level 1 (corner Jacobians computed here), the outer layer at the requested
distance, and the server naming a planar grid it cannot march off."""

import numpy as np
import pytest

from splinegrid import Client, SplinegridError
from splinegrid._generate_calls import _volume_request
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

from conftest import DATA


def test_the_request_carries_the_march():
    request = _volume_request("vol", "grids/sphere", 2, "", 8, 0.01, 1.0, "against", 40, False,
                              False)
    assert request.stored_surface.name == "grids/sphere"
    assert request.stored_surface.revision == 2
    assert (request.layers, request.first_height, request.distance) == (8, 0.01, 1.0)
    assert request.side == service_pb2.MARCH_SIDE_AGAINST_NORMAL
    assert request.normal_smoothing == 40 and request.HasField("symmetry_planes")
    assert not request.HasField("wall_points")
    with pytest.raises(ValueError, match="side = 'sideways'"):
        _volume_request("vol", "sphere", 0, "", None, None, None, "sideways", None, None, False)
    with pytest.raises(ValueError, match="symmetry_planes = 'no'"):
        _volume_request("vol", "sphere", 0, "", None, None, None, "outward", None, "no", False)
    with pytest.raises(ValueError, match="normal_smoothing = 1000000000000"):
        _volume_request("vol", "sphere", 0, "", None, None, None, "outward", 10**12, None, False)


def corner_jacobians(x):
    """det[x_i, x_j, x_k] at every hexahedron's lower corner of points (nk, nj, ni, 3)."""
    e_i = x[:-1, :-1, 1:] - x[:-1, :-1, :-1]
    e_j = x[:-1, 1:, :-1] - x[:-1, :-1, :-1]
    e_k = x[1:, :-1, :-1] - x[:-1, :-1, :-1]
    return np.einsum("...c,...c->...", e_i, np.cross(e_j, e_k))


def test_real_server_sphere_outward(server):
    with Client(server, timeout=120) as client:
        client.import_file(DATA / "surfaces" / "even_sphere.fmt", grid_id="sphere")
        client.fit("sphere")
        response = client.generate_volume("sphere-volume", "sphere", layers=8, first_height=0.02,
                                          distance=1.0)
        volume = response.report.volume
        assert volume.blocks == 6 and volume.components == 1
        assert len(volume.symmetry_planes) == 0
        assert response.report.parameters.side == service_pb2.MARCH_SIDE_OUTWARD
        blocks = client.evaluate("sphere-volume", level=1)
        assert len(blocks) == 6
        for block in blocks:
            x = block.points                                 # (nk, nj, ni, 3)
            assert x.shape[0] == 2 * 8 + 1
            assert np.all(corner_jacobians(x) > 0)           # right-handed, none folded
            # Between its 5 x 5 points the interpolated sphere is off by up to 2e-3.
            radius = np.linalg.norm(x, axis=-1)
            np.testing.assert_allclose(radius[0], 1.0, atol=5e-3)
            np.testing.assert_allclose(radius[-1], 2.0, atol=0.02)

        client.import_file(DATA / "grids" / "n0012_113-33.p2dfmt", grid_id="planar")
        client.fit("planar", allow_folds=True)  # any planar revision will do
        with pytest.raises(SplinegridError, match="layers are marched off surface blocks"):
            client.generate_volume("planar-volume", "planar")
