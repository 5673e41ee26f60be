"""Upload and archive requests as the Client builds them, without a server (file pieces,
PointChunks, ImportArchive messages, the archive shape checks), and import_points and list
against an in-process fake server that keeps what it was sent."""

import numpy as np
import pytest

from splinegrid._archive import _ArchiveShape, _export_record_bytes, _import_archive_request
from splinegrid._upload_calls import (UPLOAD_CHUNK_BYTES, _cgns_header, _file_requests,
                                      _plot3d_header, _points_header, _points_requests)
from splinegrid.v1 import archive_pb2, grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

from conftest import fake_client


def decoded(requests):
    """The ImportGridRequests as the server reads them (bytes or messages alike)."""
    return [service_pb2.ImportGridRequest.FromString(
        r if isinstance(r, bytes) else r.SerializeToString()) for r in requests]


class TestFileUploads:
    def test_planar_view_is_three_way(self):
        decide = _plot3d_header(10, "grids/g", "g.x", None).plot3d
        assert (decide.total_bytes, decide.planar_view, decide.planar_view_if_two_planes) == (
            10, False, True)
        assert _plot3d_header(10, "g", "", True).plot3d.planar_view
        as_read = _plot3d_header(10, "g", "", False)
        assert as_read.grid_id == "g"
        assert not as_read.plot3d.planar_view and not as_read.plot3d.planar_view_if_two_planes

    def test_the_file_goes_in_pieces_after_the_header(self):
        data = bytes(range(256)) * ((2 * UPLOAD_CHUNK_BYTES + 100) // 256 + 1)
        data = data[:2 * UPLOAD_CHUNK_BYTES + 100]
        header = _cgns_header(len(data), "grids/c", "c.cgns")
        sent = decoded(_file_requests(header, 4, memoryview(data)))
        assert sent[0].header == header and header.cgns.total_bytes == len(data)
        assert header.grid_id == "c"
        assert [len(r.cgns_chunk) for r in sent[1:]] == [UPLOAD_CHUNK_BYTES,
                                                        UPLOAD_CHUNK_BYTES, 100]
        assert b"".join(r.cgns_chunk for r in sent[1:]) == data
        plot3d = decoded(_file_requests(header, 2, memoryview(b"1\n2 1\n")))
        assert [r.WhichOneof("part") for r in plot3d] == ["header", "plot3d_chunk"]
        assert plot3d[1].plot3d_chunk == b"1\n2 1\n"

    def test_an_empty_file_is_the_header_alone(self):
        assert len(decoded(_file_requests(_cgns_header(0, "", ""), 4, memoryview(b"")))) == 1


class TestPointUploads:
    def test_header_extents_and_4d_blocks(self):
        curve = np.arange(10.0).reshape(5, 2)              # (ni, s)
        surface = np.zeros((3, 4, 2))                     # (nj, ni, s)
        header, arrays = _points_header([curve, surface], "grids/p", "two")
        assert (header.grid_id, header.display_name, header.points.spatial_dim) == ("p", "two", 2)
        assert [(e.i, e.j, e.k) for e in header.points.blocks] == [(5, 1, 1), (4, 3, 1)]
        assert [a.shape for a in arrays] == [(1, 1, 5, 2), (1, 3, 4, 2)]

    @pytest.mark.parametrize("blocks, message", [
        ([], "blocks is empty: a grid needs a block"),
        ([np.zeros((4, 2)), np.zeros((4, 3))], "all blocks must have the same number of "
                                               "coordinates"),
        ([np.zeros((4, 2)), np.zeros((4, 4))], r"blocks\[1\] has shape \(4, 4\)"),
        ([np.zeros(6)], r"blocks\[0\] has shape \(6,\)"),
    ])
    def test_wrong_blocks_are_named(self, blocks, message):
        with pytest.raises(ValueError, match=message):
            _points_header(blocks, "", "")

    def test_coordinates_go_in_point_chunks_per_block(self):
        per_chunk = UPLOAD_CHUNK_BYTES // 8
        big = np.random.default_rng(1).random((per_chunk + 6) // 3 * 3).reshape(-1, 3)
        header, arrays = _points_header([np.ones((2, 3)), big], "", "")
        sent = decoded(_points_requests(header, arrays))
        assert sent[0].header == header
        chunks = [r.points for r in sent[1:]]
        assert [(c.block, len(c.coordinates)) for c in chunks] == [
            (0, 6), (1, per_chunk), (1, big.size - per_chunk)]
        assert list(chunks[0].coordinates) == [1.0] * 6
        assert np.array_equal(np.concatenate([c.coordinates for c in chunks[1:]]),
                              big.reshape(-1))


class TestArchiveRequests:
    def test_the_new_id_rides_on_the_first_record_only(self):
        payload = archive_pb2.ArchiveRecord(
            header=archive_pb2.ArchiveHeader(id="naca")).SerializeToString()
        first = service_pb2.ImportArchiveRequest.FromString(
            _import_archive_request(payload, True, "copy"))
        assert (first.grid_id, first.record.header.id) == ("copy", "naca")
        later = service_pb2.ImportArchiveRequest.FromString(
            _import_archive_request(payload, False, "copy"))
        assert later.grid_id == "" and later.record.SerializeToString() == payload
        assert service_pb2.ImportArchiveRequest.FromString(
            _import_archive_request(payload, True, "")).grid_id == ""

    def test_export_record_bytes_are_the_record_field(self):
        record = archive_pb2.ArchiveRecord(revision=archive_pb2.StoredRevision())
        response = service_pb2.ExportGridResponse(record=record).SerializeToString()
        assert _export_record_bytes(response) == record.SerializeToString()
        assert _export_record_bytes(b"") == b""

    @staticmethod
    def shape(*records_):
        shape = _ArchiveShape(lambda what: ValueError(what))
        for record in records_:
            shape.add(record.SerializeToString())
        return shape

    def test_shape_counts_and_summary(self):
        header = archive_pb2.ArchiveHeader(id="naca", num_source_chunks=2, num_revisions=1)
        chunk = archive_pb2.ArchiveRecord(source=archive_pb2.SourceChunk(block=0))
        revision = archive_pb2.ArchiveRecord(revision=archive_pb2.StoredRevision())
        shape = self.shape(archive_pb2.ArchiveRecord(header=header), chunk, chunk, revision)
        shape.complete()
        summary = shape.summary(1234)
        assert (summary.header.id, summary.source_chunks, summary.revisions, summary.bytes) == (
            "naca", 2, 1, 1234)
        short = self.shape(archive_pb2.ArchiveRecord(header=header), chunk)
        with pytest.raises(ValueError, match="announces 2 source chunks and 1 revisions, there "
                           "are 1 and 0"):
            short.complete()

    def test_shape_faults(self):
        header = archive_pb2.ArchiveRecord(header=archive_pb2.ArchiveHeader(id="a"))
        with pytest.raises(ValueError, match="record 1 is a second header"):
            self.shape(header, header)
        with pytest.raises(ValueError, match="the first record is not an archive header"):
            self.shape(archive_pb2.ArchiveRecord(revision=archive_pb2.StoredRevision()))
        with pytest.raises(ValueError, match="no records"):
            self.shape().complete()
        with pytest.raises(ValueError, match="record 0 is not an archive record"):
            _ArchiveShape(lambda what: ValueError(what)).add(b"\xff")


class KeepingServer(service_grpc.SplineGridServicer):
    """Keeps the points of ImportGrid calls; lists ``grids`` in pages of ``page`` names."""

    def __init__(self, grids=(), page=2):
        self.uploads, self.list_requests = [], []
        self.grids, self.page = list(grids), page

    def ImportGrid(self, request_iterator, context):
        header, chunks = None, []
        for request in request_iterator:
            if request.HasField("header"):
                header = request.header
            else:
                chunks.append((request.points.block, list(request.points.coordinates)))
        self.uploads.append((header, chunks))
        return grid_pb2.Grid(name=f"grids/{header.grid_id}")

    def ListGrids(self, request, context):
        self.list_requests.append((request.page_size, request.page_token))
        start = int(request.page_token or 0)
        end = start + self.page
        return service_pb2.ListGridsResponse(
            grids=[grid_pb2.Grid(name=f"grids/{g}") for g in self.grids[start:end]],
            next_page_token=str(end) if end < len(self.grids) else "")


@pytest.fixture
def keeping():
    fake = KeepingServer(grids=["a", "b", "c", "d", "e"])
    with fake_client(fake) as client:
        yield fake, client


def test_import_points_sends_every_coordinate_in_order(keeping):
    fake, client = keeping
    block = np.arange(24.0).reshape(2, 4, 3)  # (nj, ni, s)
    assert client.import_points([block], grid_id="pts", display_name="P").name == "grids/pts"
    ((header, chunks),) = fake.uploads
    assert (header.display_name, header.points.spatial_dim) == ("P", 3)
    assert (header.points.blocks[0].i, header.points.blocks[0].j) == (4, 2)
    assert chunks == [(0, list(np.arange(24.0)))]


def test_import_points_refuses_one_bare_array(keeping):
    # Iterated, a (nj, ni, s) array was 3 blocks of one line each, stored without a word.
    fake, client = keeping
    with pytest.raises(ValueError, match=r"blocks is one array of shape \(3, 4, 2\); give a "
                                         r"list of blocks \(e.g. \[points\] for one block\)"):
        client.import_points(np.zeros((3, 4, 2)), grid_id="pts")
    assert fake.uploads == []


def test_empty_files_are_refused_before_the_call(keeping, tmp_path):
    fake, client = keeping
    with pytest.raises(ValueError, match="the bytes given are empty: no grid to import"):
        client.import_plot3d(b"", grid_id="e")
    empty = tmp_path / "empty.cgns"
    empty.write_bytes(b"")
    with pytest.raises(ValueError, match=r"empty.cgns is empty: no grid to import"):
        client.import_cgns(empty, grid_id="e")
    assert fake.uploads == []


def test_list_follows_every_page(keeping):
    fake, client = keeping
    assert [g.name for g in client.list()] == [f"grids/{g}" for g in "abcde"]
    assert fake.list_requests == [(500, ""), (500, "2"), (500, "4")]
