"""The Python client's token and TLS options against an in-process fake SplineGrid server: the
``authorization`` metadata on every kind of call (argument, environment, none), argument
checks that never echo the token, and a TLS channel with certificates made by ``openssl``."""

import shutil
import subprocess
from concurrent import futures

import grpc
import pytest

from splinegrid import Client, RetryPolicy, SplinegridError
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

ONCE = RetryPolicy(max_attempts=1)


class RecordingSplineGrid(service_grpc.SplineGridServicer):
    """Records the ``authorization`` metadata of every call."""

    def __init__(self):
        self.authorization = []

    def _enter(self, context):
        self.authorization.append(dict(context.invocation_metadata()).get("authorization"))

    def GetGrid(self, request, context):
        self._enter(context)
        return grid_pb2.Grid(name=request.name)

    def ListGrids(self, request, context):
        self._enter(context)
        return service_pb2.ListGridsResponse(grids=[grid_pb2.Grid(name="grids/a")])

    def WatchGrid(self, request, context):
        self._enter(context)
        yield service_pb2.WatchGridResponse(revision=grid_pb2.RevisionInfo(revision=1))


def start(credentials=None):
    servicer = RecordingSplineGrid()
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=2))
    service_grpc.add_SplineGridServicer_to_server(servicer, server)
    if credentials is None:
        servicer.port = server.add_insecure_port("127.0.0.1:0")
    else:
        servicer.port = server.add_secure_port("127.0.0.1:0", credentials)
    server.start()
    return server, servicer


@pytest.fixture
def fake():
    server, servicer = start()
    yield servicer
    server.stop(None)


def test_the_token_goes_with_unary_and_streaming_calls(fake, monkeypatch):
    monkeypatch.delenv("SPLINEGRID_TOKEN", raising=False)
    with Client(f"127.0.0.1:{fake.port}", retry=ONCE, token="s3cret-token") as client:
        client.get("naca")
        client.list()
        with client.watch("naca") as revisions:
            next(iter(revisions))
    assert fake.authorization == ["Bearer s3cret-token"] * 3


def test_the_token_comes_from_the_environment_unless_given(fake, monkeypatch):
    monkeypatch.setenv("SPLINEGRID_TOKEN", "from-the-env")
    with Client(f"127.0.0.1:{fake.port}", retry=ONCE) as client:
        client.get("naca")
    with Client(f"127.0.0.1:{fake.port}", retry=ONCE, token="") as client:
        client.get("naca")
    monkeypatch.delenv("SPLINEGRID_TOKEN")
    with Client(f"127.0.0.1:{fake.port}", retry=ONCE) as client:
        client.list()
    assert fake.authorization == ["Bearer from-the-env", None, None]


def test_bad_arguments_are_refused_without_echoing_the_token(tmp_path):
    with pytest.raises(ValueError) as error:
        Client("127.0.0.1:1", token="two words")
    assert "two words" not in str(error.value)
    with pytest.raises(ValueError, match="tls_cert and tls_key"):
        Client("127.0.0.1:1", tls_cert=str(tmp_path / "c.pem"))
    with pytest.raises(ValueError, match="tls_ca: cannot read"):
        Client("127.0.0.1:1", tls_ca=str(tmp_path / "missing.pem"))


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")
def test_a_tls_channel_trusts_the_given_ca_and_plaintext_fails(tmp_path):
    key = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
    run = lambda *args: subprocess.run(args, cwd=tmp_path, check=True, capture_output=True)
    run("openssl", "req", "-x509", *key, "-keyout", "ca.key", "-out", "ca.pem", "-days", "1",
        "-subj", "/CN=test-ca")
    run("openssl", "req", *key, "-keyout", "server.key", "-out", "server.csr", "-subj",
        "/CN=localhost")
    (tmp_path / "ext").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    run("openssl", "x509", "-req", "-in", "server.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
        "-CAcreateserial", "-out", "server.pem", "-days", "1", "-extfile", "ext")
    credentials = grpc.ssl_server_credentials(
        [((tmp_path / "server.key").read_bytes(), (tmp_path / "server.pem").read_bytes())])
    server, servicer = start(credentials)
    try:
        target = f"127.0.0.1:{servicer.port}"
        with Client(target, retry=ONCE, tls_ca=str(tmp_path / "ca.pem"), token="tls-token-1") as c:
            assert [g.name for g in c.list()] == ["grids/a"]
        with Client(f"localhost:{servicer.port}", retry=ONCE,
                    tls_ca=str(tmp_path / "ca.pem")) as c:
            c.get("naca")
        with Client(target, retry=ONCE, timeout=2) as c, pytest.raises(SplinegridError) as error:
            c.list()
        assert error.value.code == "UNAVAILABLE"
        assert servicer.authorization == ["Bearer tls-token-1", None]
    finally:
        server.stop(None)


def test_a_deadline_the_client_sees_first_says_which_timeout():
    """A server that accepts the connection and never answers: the client's own deadline fires,
    and its error names the timeout instead of gRPC's bare "Deadline Exceeded"."""
    import socket
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        port = silent.getsockname()[1]
        with Client(f"127.0.0.1:{port}", retry=ONCE, timeout=1.5) as c, \
                pytest.raises(SplinegridError) as error:
            c.list()
    assert error.value.code == "DEADLINE_EXCEEDED"
    assert "the call's deadline passed before its answer came (the client's timeout, 1.5 s" \
        in error.value.message
