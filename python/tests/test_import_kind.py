"""The import path decides what a file is before uploading it, and uploads it once: file kinds
by content, one ImportGrid call per import (counted by a fake server) asking for the planar view
of two-plane files, and the real server deciding it for the shared grids in every Plot3D layout
(text, Fortran records, C stream; either byte order, single or double, with and without
iblank)."""

import itertools
import re
import struct

import numpy as np
import pytest

from splinegrid import Client, FileKind, detect_file_kind, records
from splinegrid.v1 import archive_pb2, grid_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

from conftest import DATA, fake_client

RAE = DATA / "grids" / "rae2822_257x97.fmt"          # 2 x 257 x 97, planes y = 0 and y = -1
PITCH = DATA / "grids" / "n0012_pitch_257x129.fmt"   # a two-plane grid as well
NACA = DATA / "grids" / "n0012_225-65.p2dfmt"        # 2-D
BOX = DATA / "surfaces" / "ffd_box_6x2x6.fmt"        # 3-D with an extent of 2, a real box
M6 = DATA / "surfaces" / "m6_small.fmt"


def text_blocks(path):
    """The blocks of a 3-D formatted Plot3D file with a block count, as (nk, nj, ni, 3) arrays
    (Fortran ``n*value`` repeats and ``D`` exponents expanded): enough for the shared files."""
    values = []
    for token in re.split(r"[\s,]+", path.read_text().strip()):
        count, _, value = token.rpartition("*")
        values += [float(value.replace("D", "E").replace("d", "e"))] * int(count or 1)
    nblocks = int(values[0])
    extents = [tuple(int(v) for v in values[1 + 3 * b:4 + 3 * b]) for b in range(nblocks)]
    at, blocks = 1 + 3 * nblocks, []
    for ni, nj, nk in extents:
        n = ni * nj * nk
        xyz = np.array(values[at:at + 3 * n]).reshape(3, nk, nj, ni)
        blocks.append(np.moveaxis(xyz, 0, -1))
        at += 3 * n
    assert at == len(values), path
    return blocks


def fortran_records(blocks, order="<", real="f8", iblank=False, count=True):
    """A Fortran unformatted Plot3D file of ``blocks`` ((nk, nj, ni, 3) arrays)."""
    def record(payload):
        return struct.pack(order + "i", len(payload)) + payload + struct.pack(
            order + "i", len(payload))
    out = record(struct.pack(order + "i", len(blocks))) if count else b""
    out += record(b"".join(struct.pack(order + "3i", b.shape[2], b.shape[1], b.shape[0])
                           for b in blocks))
    for b in blocks:
        payload = np.moveaxis(b, -1, 0).astype(order + real).tobytes()
        if iblank:
            payload += np.ones(b.shape[:3], dtype=order + "i4").tobytes()
        out += record(payload)
    return out


def c_stream(blocks, order="<", real="f8", iblank=False, count=True):
    """A C-stream binary Plot3D file (no record markers)."""
    out = struct.pack(order + "i", len(blocks)) if count else b""
    out += b"".join(struct.pack(order + "3i", b.shape[2], b.shape[1], b.shape[0])
                    for b in blocks)
    for b in blocks:
        out += np.moveaxis(b, -1, 0).astype(order + real).tobytes()
        if iblank:
            out += np.ones(b.shape[:3], dtype=order + "i4").tobytes()
    return out


class TestFileKind:
    def test_kinds_by_content(self, tmp_path):
        archive = tmp_path / "grid.x"  # the extension does not decide
        with records.RecordWriter(str(archive)) as writer:
            writer.append(b"\x0a\x00")
        assert detect_file_kind(archive) is FileKind.ARCHIVE
        assert detect_file_kind(b"\x89HDF\r\n\x1a\n" + bytes(100)) is FileKind.CGNS
        assert detect_file_kind(bytes(512) + b"\x89HDF\r\n\x1a\n") is FileKind.CGNS
        assert detect_file_kind(b"@(#)ADF Database Version A02011>") is FileKind.CGNS
        assert detect_file_kind(RAE) is FileKind.PLOT3D
        assert detect_file_kind(fortran_records(text_blocks(RAE))) is FileKind.PLOT3D
        assert detect_file_kind(b"") is FileKind.PLOT3D

    def test_missing_file_raises(self, tmp_path):
        with pytest.raises(OSError):
            detect_file_kind(tmp_path / "none.x")


_ids = itertools.count()


class TestServerDecidesPlanarView:
    def test_text_reader_of_these_tests(self):
        (block,) = text_blocks(RAE)
        assert block.shape == (97, 257, 2, 3)                 # (nk, nj, ni, 3)
        assert np.all(block[:, :, 0, 1] == 0.0) and np.all(block[:, :, 1, 1] == -1.0)
        assert block[0, 0, 0, 0] == 20.0                      # "2*20." expands along i
        assert text_blocks(BOX)[0].shape == (6, 2, 6, 3)

    def test_shared_grids(self, server):
        with Client(server, timeout=60) as client:
            for path, dim, planar in [(RAE, 2, True), (PITCH, 2, True), (NACA, 2, False),
                                      (M6, 3, False), (BOX, 3, False)]:
                grid = client.import_plot3d(str(path), grid_id=f"shared-{next(_ids)}")
                assert grid.source.spatial_dim == dim, path
                assert grid.source.format.endswith(", planar view") is planar, path

    @pytest.mark.parametrize("order", "<>")
    @pytest.mark.parametrize("real", ["f8", "f4"])
    @pytest.mark.parametrize("iblank", [False, True])
    @pytest.mark.parametrize("writer", [fortran_records, c_stream])
    def test_binary_layouts(self, server, order, real, iblank, writer):
        with Client(server, timeout=60) as client:
            rae = writer(text_blocks(RAE), order=order, real=real, iblank=iblank)
            grid = client.import_plot3d(rae, grid_id=f"rae-{next(_ids)}")
            assert grid.source.spatial_dim == 2
            assert [(b.i, b.j, b.k) for b in grid.source.blocks] == [(257, 97, 1)]
            box = writer(text_blocks(BOX), order=order, real=real, iblank=iblank)
            assert client.import_plot3d(box, grid_id=f"box-{next(_ids)}").source.spatial_dim == 3

    def test_single_block_without_count(self, server):
        with Client(server, timeout=60) as client:
            for writer in (fortran_records, c_stream):
                data = writer(text_blocks(RAE), count=False)
                assert client.import_plot3d(data, grid_id=f"one-{next(_ids)}").source.spatial_dim == 2

    def test_one_moved_point_keeps_the_file_as_read(self, server):
        (block,) = text_blocks(RAE)
        with Client(server, timeout=60) as client:
            moved = block.copy()
            moved[40, 100, 1, 0] += 1e-3                      # x differs between the planes
            grid = client.import_plot3d(fortran_records([moved]), grid_id=f"moved-{next(_ids)}")
            assert grid.source.spatial_dim == 3
            moved = block.copy()
            moved[40, 100, 1, 1] = -1.0 + 1e-3                # y not constant on plane 1
            grid = client.import_plot3d(fortran_records([moved]), grid_id=f"moved-{next(_ids)}")
            assert grid.source.spatial_dim == 3


class CountingImports(service_grpc.SplineGridServicer):
    """Counts ImportGrid calls and keeps each one's header and byte count."""

    def __init__(self):
        self.imports = []
        self.archives = []

    def ImportGrid(self, request_iterator, context):
        header, size = None, 0
        for request in request_iterator:
            if request.HasField("header"):
                header = request.header
            size += len(request.plot3d_chunk) + len(request.cgns_chunk)
        self.imports.append((header, size))
        return grid_pb2.Grid(name=f"grids/{header.grid_id}")

    def ImportArchive(self, request_iterator, context):
        records_sent = [request.record for request in request_iterator]
        self.archives.append(records_sent)
        return grid_pb2.Grid(name=f"grids/{records_sent[0].header.id}")


@pytest.fixture
def counting():
    fake = CountingImports()
    with fake_client(fake, workers=4) as client:
        yield fake, client


class TestOneUpload:
    @pytest.mark.parametrize("path", [RAE, NACA, BOX])
    def test_the_server_decides_the_planar_view(self, counting, path):
        fake, client = counting
        client.import_plot3d(str(path), grid_id="g")
        assert len(fake.imports) == 1
        header, size = fake.imports[0]
        assert header.plot3d.planar_view_if_two_planes and not header.plot3d.planar_view
        assert size == header.plot3d.total_bytes == path.stat().st_size

    def test_import_file_uses_the_file_name(self, counting):
        fake, client = counting
        client.import_file(RAE, grid_id="rae")
        (header, _), = fake.imports
        assert (header.grid_id, header.display_name) == ("rae", RAE.name)
        assert header.plot3d.planar_view_if_two_planes

    def test_explicit_planar_view_is_kept(self, counting):
        fake, client = counting
        client.import_plot3d(RAE.read_bytes(), grid_id="g", planar_view=False)
        client.import_plot3d(RAE.read_bytes(), grid_id="h", planar_view=True)
        as_read, planar = (header.plot3d for header, _ in fake.imports)
        assert not as_read.planar_view and not as_read.planar_view_if_two_planes
        assert planar.planar_view and not planar.planar_view_if_two_planes

    def test_archive_goes_to_import_archive(self, counting, tmp_path):
        fake, client = counting
        path = tmp_path / "naca.x"  # an archive under a Plot3D name
        record = archive_pb2.ArchiveRecord()
        record.header.id = "naca"
        with records.RecordWriter(str(path)) as writer:
            writer.append(record.SerializeToString())
        assert client.import_file(path).name == "grids/naca"
        assert fake.imports == [] and len(fake.archives) == 1
        assert fake.archives[0][0].header.id == "naca"

    def test_cgns_goes_to_a_cgns_upload(self, counting, tmp_path):
        fake, client = counting
        path = tmp_path / "grid.x"  # a CGNS file under a Plot3D name
        path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(64))
        client.import_file(path, grid_id="g")
        (header, size), = fake.imports
        assert header.WhichOneof("source") == "cgns"
        assert size == header.cgns.total_bytes == 72
        assert header.display_name == "grid.x"
