"""A watch resumed across a real server's crash: ``splinegrid serve --store=dir:`` killed with
SIGKILL and started again on the same port and directory while the watch is open. The watch
goes on after the last revision it received (none again, none missed), which needs the
restarted server to know the grid as the same creation (the dir: store keeps it)."""

import socket
import subprocess
import threading
import time

import pytest

from splinegrid import Client, RetryPolicy

from conftest import DATA, _free_port, server_binary


class DirServer:
    """``splinegrid serve --store=dir:PATH`` on a fixed loopback port, restartable."""

    def __init__(self, directory):
        self.binary = server_binary()
        if not self.binary.is_file():
            pytest.skip(f"{self.binary} is not built (set SPLINEGRID_BINARY)")
        self.directory = directory
        self.port = _free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.process = None

    def start(self):
        self.process = subprocess.Popen(
            [str(self.binary), "serve", f"--address={self.address}",
             f"--store=dir:{self.directory}", "--drain_notice=0s", "--shutdown_grace=1s"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 20
        while True:
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", self.port)) == 0:
                    return
            assert self.process.poll() is None, "splinegrid serve exited during start-up"
            assert time.monotonic() < deadline, "splinegrid serve did not start in 20 s"
            time.sleep(0.05)

    def kill(self):
        self.process.kill()
        self.process.wait(timeout=10)

    def stop(self):
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


def test_a_watch_goes_on_after_its_server_crashed_and_restarted(tmp_path):
    server = DirServer(tmp_path / "store")
    server.start()
    try:
        # Retries for about 8 s: longer than the restart.
        patient = RetryPolicy(max_attempts=40, initial_backoff=0.05, max_backoff=0.2)
        with Client(server.address, timeout=60, retry=patient) as client:
            client.import_file(DATA / "grids" / "n0012_113-33.p2dfmt", grid_id="wing")
            assert client.fit("wing", boundary_tolerances={}).revision == 1
            seen, ended = [], []
            arrived = threading.Condition()

            def follow():
                with client.watch("wing") as revisions:
                    for info in revisions:
                        with arrived:
                            seen.append(info.revision)
                            arrived.notify_all()
                with arrived:
                    ended.append(True)
                    arrived.notify_all()

            watcher = threading.Thread(target=follow, daemon=True)
            watcher.start()

            def wait_for(count):
                with arrived:
                    arrived.wait_for(lambda: len(seen) >= count or ended, timeout=30)
                    return list(seen)

            assert wait_for(1) == [1]
            server.kill()
            server.start()
            for degrees in (0.5, 1.0):
                client.deform("wing", rotate_degrees=degrees, about=(0.25, 0.0))
            assert wait_for(3) == [1, 2, 3]
            assert not ended
            # The watch ends as it does for a grid deleted on a server it never left.
            client.delete("wing")
            with arrived:
                assert arrived.wait_for(lambda: ended, timeout=30)
            watcher.join(timeout=10)
            assert seen == [1, 2, 3]
    finally:
        server.stop()
