"""Client.fit(face_kinds=...) (issue 13, point 5): the accepted forms become FitSpec.face_kinds,
a bad entry is refused naming it, and the request carries the kinds to the server."""

from concurrent import futures

import grpc
import pytest

from splinegrid import Client
from splinegrid._args import _face_kinds
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc


def as_tuples(kinds):
    return [(k.block, k.face, k.kind) for k in kinds]


WALL_IMIN = (0, grid_pb2.BLOCK_FACE_I_MIN, grid_pb2.BOUNDARY_KIND_WALL)
OUTER_JMAX = (2, grid_pb2.BLOCK_FACE_J_MAX, grid_pb2.BOUNDARY_KIND_OUTER)


@pytest.mark.parametrize("given", [
    {(0, "imin"): "wall", (2, "jmax"): "outer"},
    ["0:imin=wall", "2:jmax=outer"],
    "0:imin=wall, 2:JMAX=Outer",
    ["0:imin=wall", "2:jmax=outer", "0:imin=wall"],  # a repetition with the same kind
])
def test_every_form_gives_the_same_face_kinds(given):
    assert as_tuples(_face_kinds(given)) == [WALL_IMIN, OUTER_JMAX]


@pytest.mark.parametrize("given, named", [
    (["0:lmin=wall"], "'0:lmin=wall'"),
    (["0:imin=symmetry"], "no symmetry kind"),
    (["x:imin=wall"], "'x:imin=wall'"),
    (["0:imin"], "'0:imin'"),
    (["-1:imin=wall"], "'-1:imin=wall'"),
    ({(0, "imin"): "inlet"}, "'inlet'"),
    (["0:imin=wall", "0:imin=outer"], "another kind"),
])
def test_a_bad_entry_is_named(given, named):
    with pytest.raises(ValueError, match=named.replace("(", r"\(")):
        _face_kinds(given)


class RecordingFit(service_grpc.SplineGridServicer):
    def FitGrid(self, request, context):
        self.request = request
        return service_pb2.FitGridResponse(revision=1)


@pytest.fixture
def server():
    servicer = RecordingFit()
    grpc_server = grpc.server(futures.ThreadPoolExecutor(max_workers=2))
    service_grpc.add_SplineGridServicer_to_server(servicer, grpc_server)
    servicer.port = grpc_server.add_insecure_port("127.0.0.1:0")
    grpc_server.start()
    yield servicer
    grpc_server.stop(None)


def test_fit_sends_the_kinds_with_tolerances_by_kind(server):
    with Client(f"127.0.0.1:{server.port}") as client:
        client.fit("nozzle", face_kinds={(1, "imin"): "wall"})
        spec = server.request.spec
        assert spec.HasField("boundary_tolerances")  # implied: the kinds matter only there
        assert as_tuples(spec.face_kinds) == [
            (1, grid_pb2.BLOCK_FACE_I_MIN, grid_pb2.BOUNDARY_KIND_WALL)]
        with pytest.raises(ValueError, match="face_kinds apply"):
            client.fit("nozzle", tolerance=1e-4, face_kinds=["1:imin=wall"])
