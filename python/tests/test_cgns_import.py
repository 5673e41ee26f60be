"""CGNS files through the Python client and the real server: ``import_file`` sends a CGNS file
once, as a CGNS upload (the server decodes it in its splinegrid-cgns-decode child), the grid
fits to the same points as its Plot3D original, and a damaged file is INVALID_ARGUMENT after
which the server keeps serving. The CGNS files are written by Debian's ``plot3d_to_cgns``
(cgns-convert, installed by .ci/setup)."""

import shutil
import subprocess

import numpy as np
import pytest

from splinegrid import Client, SplinegridError

from conftest import DATA

M6 = DATA / "surfaces" / "m6_small.fmt"  # 9 surface patches, 16,001 points

pytestmark = pytest.mark.skipif(shutil.which("plot3d_to_cgns") is None,
                                reason="plot3d_to_cgns (Debian cgns-convert) is not installed")


@pytest.fixture(scope="module")
def m6_cgns(tmp_path_factory):
    path = tmp_path_factory.mktemp("cgns") / "m6.cgns"
    subprocess.run(["plot3d_to_cgns", "-f", "-d", str(M6), str(path)], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return path


def test_import_file_uploads_cgns_and_fits_like_plot3d(server, m6_cgns):
    with Client(server, timeout=120) as client:
        grid = client.import_file(m6_cgns, grid_id="m6-cgns")
        assert grid.source.format == "cgns hdf5, 3d, 9 zones, double"
        assert grid.display_name == "m6.cgns"
        assert grid.source.num_points == 16001
        assert len(grid.source.boundaries.block_names) == 9
        plot3d = client.import_file(M6, grid_id="m6-plot3d")
        assert [(b.i, b.j, b.k) for b in grid.source.blocks] == \
            [(b.i, b.j, b.k) for b in plot3d.source.blocks]
        for name in ("grids/m6-cgns", "grids/m6-plot3d"):
            client.fit(name, control_counts=(12, 12))
        a = client.evaluate("grids/m6-cgns", level=1)
        b = client.evaluate("grids/m6-plot3d", level=1)
        assert len(a) == len(b) == 9
        for block_a, block_b in zip(a, b):
            np.testing.assert_array_equal(block_a.points, block_b.points)


def test_import_cgns_bytes_and_a_damaged_file(server, m6_cgns):
    data = m6_cgns.read_bytes()
    with Client(server, timeout=120) as client:
        grid = client.import_cgns(data, grid_id="m6-bytes", display_name="bytes")
        assert grid.source.num_points == 16001
        with pytest.raises(SplinegridError) as error:
            client.import_cgns(data[:len(data) // 2], grid_id="half")
        assert error.value.code == "INVALID_ARGUMENT"
        assert "cgns: " in error.value.message
        assert client.get("grids/m6-bytes").source.num_points == 16001  # still serving
