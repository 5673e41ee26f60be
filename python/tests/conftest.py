"""Shared fixtures: the real server binary on a loopback port, fake servers in this process,
and paths of the shared data."""

import contextlib
import os
import pathlib
import socket
import subprocess
import time
from concurrent import futures

import grpc
import pytest

from splinegrid import Client, RetryPolicy
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

REPO = pathlib.Path(__file__).resolve().parents[2]
# The shared data set: $SPLINEGRID_SHARED_DATA, else ../shared/data beside the repository (as
# tests/core/test_data.h finds it).
DATA = pathlib.Path(os.environ.get("SPLINEGRID_SHARED_DATA", REPO.parent / "shared" / "data"))


def server_binary() -> pathlib.Path:
    """``SPLINEGRID_BINARY`` (set by the CTest registration), else ``REPO/build/splinegrid``."""
    return pathlib.Path(os.environ.get("SPLINEGRID_BINARY", REPO / "build" / "splinegrid"))


@contextlib.contextmanager
def fake_client(servicer, workers: int = 2):
    """A Client (no retries, 10 s deadline) of an in-process gRPC server on a free loopback port
    that serves ``servicer`` (a ``SplineGridServicer``); the server stops on exit."""
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=workers))
    service_grpc.add_SplineGridServicer_to_server(servicer, server)
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    try:
        with Client(f"127.0.0.1:{port}", timeout=10,
                    retry=RetryPolicy(max_attempts=1)) as client:
            yield client
    finally:
        server.stop(0)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server():
    """``host:port`` of a real ``splinegrid serve`` (in-memory store) for the module's tests.
    Skipped when the binary is not built (pytest run by hand before a CMake build); CTest
    always passes it."""
    binary = server_binary()
    if not binary.is_file():
        pytest.skip(f"{binary} is not built (set SPLINEGRID_BINARY)")
    port = _free_port()
    process = subprocess.Popen([str(binary), "serve", f"--address=127.0.0.1:{port}",
                                "--drain_notice=0s", "--shutdown_grace=1s"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 20
    try:
        while True:
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", port)) == 0:
                    break
            if process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"splinegrid serve did not start: "
                                   f"{process.stderr.read().decode() if process.stderr else ''}")
            time.sleep(0.05)
        yield f"127.0.0.1:{port}"
    finally:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
