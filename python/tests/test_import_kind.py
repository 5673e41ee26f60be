"""The import path decides what a file is before uploading it, and uploads it once: file kinds
by content, the two-plane (planar view) decision on the shared grids in every layout read
locally, one ImportGrid call per import (counted by a fake server), and the real server
agreeing with the decision."""

import struct
from concurrent import futures

import grpc
import numpy as np
import pytest

from splinegrid import Client, FileKind, RetryPolicy, detect_file_kind, plot3d, records
from splinegrid.v1 import archive_pb2, grid_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

from conftest import DATA

RAE = DATA / "grids" / "rae2822_257x97.fmt"          # 2 x 257 x 97, planes y = 0 and y = -1
PITCH = DATA / "grids" / "n0012_pitch_257x129.fmt"   # a two-plane grid as well
NACA = DATA / "grids" / "n0012_225-65.p2dfmt"        # 2-D
BOX = DATA / "surfaces" / "ffd_box_6x2x6.fmt"        # 3-D with an extent of 2, a real box
M6 = DATA / "surfaces" / "m6_small.fmt"


def text_blocks(path):
    blocks = plot3d.read_3d_blocks(path.read_bytes())
    assert blocks is not None, path
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


class TestTwoPlane:
    def test_shared_grids(self):
        assert plot3d.two_plane_file(RAE.read_bytes())
        assert plot3d.two_plane_file(PITCH.read_bytes())
        assert not plot3d.two_plane_file(NACA.read_bytes())   # 2-D: nothing to drop
        assert not plot3d.two_plane_file(M6.read_bytes())     # no extent 2
        box = text_blocks(BOX)
        assert box[0].shape == (6, 2, 6, 3)
        assert not plot3d.two_plane_file(BOX.read_bytes())    # planes differ in-plane

    def test_text_layout_is_whole(self):
        (block,) = text_blocks(RAE)
        assert block.shape == (97, 257, 2, 3)                 # (nk, nj, ni, 3)
        assert np.all(block[:, :, 0, 1] == 0.0) and np.all(block[:, :, 1, 1] == -1.0)
        assert block[0, 0, 0, 0] == 20.0                      # "2*20." expands along i

    @pytest.mark.parametrize("order", "<>")
    @pytest.mark.parametrize("real", ["f8", "f4"])
    @pytest.mark.parametrize("iblank", [False, True])
    @pytest.mark.parametrize("writer", [fortran_records, c_stream])
    def test_binary_layouts(self, order, real, iblank, writer):
        rae = text_blocks(RAE)
        data = writer(rae, order=order, real=real, iblank=iblank)
        blocks = plot3d.read_3d_blocks(data)
        assert blocks is not None and blocks[0].shape == rae[0].shape
        np.testing.assert_allclose(blocks[0], rae[0], rtol=1e-6 if real == "f4" else 0)
        assert plot3d.two_plane_file(data)
        assert not plot3d.two_plane_file(writer(text_blocks(BOX), order=order, real=real,
                                                 iblank=iblank))

    def test_single_block_without_count(self):
        assert plot3d.two_plane_file(fortran_records(text_blocks(RAE), count=False))
        assert plot3d.two_plane_file(c_stream(text_blocks(RAE), count=False))

    def test_one_moved_point_breaks_it(self):
        (block,) = text_blocks(RAE)
        block = block.copy()
        block[40, 100, 1, 0] += 1e-3                          # x differs between the planes
        assert not plot3d.is_two_plane_block(block)
        assert not plot3d.two_plane_file(fortran_records([block]))
        block[40, 100, 1, 0] -= 1e-3
        block[40, 100, 1, 1] = -1.0 + 1e-3                    # y not constant on plane 1
        assert not plot3d.is_two_plane_block(block)

    def test_unreadable_files_are_not_two_plane(self):
        good = RAE.read_bytes()
        assert not plot3d.two_plane_file(good[:-200])          # truncated: counts differ
        assert not plot3d.two_plane_file(fortran_records(text_blocks(RAE))[:-4])
        assert not plot3d.two_plane_file(b"\x00\x01garbage")
        assert not plot3d.two_plane_file(b"")


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
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=4))
    service_grpc.add_SplineGridServicer_to_server(fake, server)
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    with Client(f"127.0.0.1:{port}", timeout=10, retry=RetryPolicy(max_attempts=1)) as client:
        yield fake, client
    server.stop(0)


class TestOneUpload:
    @pytest.mark.parametrize("path, planar", [(RAE, True), (PITCH, True), (NACA, False),
                                              (BOX, False)])
    def test_planar_decided_before_the_upload(self, counting, path, planar):
        fake, client = counting
        client.import_plot3d(str(path), grid_id="g")
        assert len(fake.imports) == 1
        header, size = fake.imports[0]
        assert header.plot3d.planar_view is planar
        assert size == header.plot3d.total_bytes == path.stat().st_size

    def test_import_file_uses_the_file_name(self, counting):
        fake, client = counting
        client.import_file(RAE, grid_id="rae")
        (header, _), = fake.imports
        assert (header.grid_id, header.display_name) == ("rae", RAE.name)
        assert header.plot3d.planar_view

    def test_explicit_planar_view_is_kept(self, counting):
        fake, client = counting
        client.import_plot3d(RAE.read_bytes(), grid_id="g", planar_view=False)
        assert fake.imports[0][0].plot3d.planar_view is False

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


class TestRealServer:
    """The server reads the files as the local decision assumed."""

    def test_two_plane_file_is_stored_planar(self, server):
        with Client(server, timeout=60) as client:
            grid = client.import_file(RAE, grid_id="rae-planar")
            assert grid.source.spatial_dim == 2
            assert [(b.i, b.j, b.k) for b in grid.source.blocks] == [(257, 97, 1)]
            naca = client.import_file(NACA, grid_id="naca-as-read")
            assert naca.source.spatial_dim == 2
            box = client.import_file(BOX, grid_id="box-as-read")
            assert box.source.spatial_dim == 3
            assert {g.name for g in client.list()} >= {"grids/rae-planar",
                                                       "grids/naca-as-read",
                                                       "grids/box-as-read"}
