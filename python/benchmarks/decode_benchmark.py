"""How fast bulk numbers get from wire bytes into NumPy arrays, per path (README figures).

    PYTHONPATH=build/python /usr/bin/python3 python/benchmarks/decode_benchmark.py

1. EvaluateGrid of a large grid (default 2 blocks of 129 x 129 x 65 points, 3 coordinates:
   6.5 M doubles, 52 MB) in the server's ~256 KiB chunks: through the generated
   ``EvaluateGridResponse`` class and ``np.asarray(chunk.values)`` ("generated"), and through
   the client's wire decoder (``_evaluation``, ``np.frombuffer``) into preallocated arrays.
2. GetGrid FULL with a large control net (default 1 M control points x 3): ``np.array`` of the
   generated ``control_points`` container vs ``_splines.decode_full_grid``.
Messages are serialized once up front; each path is timed over the same bytes (best of 3).
"""

from __future__ import annotations

import argparse
import time
from typing import Callable

import numpy as np

from splinegrid._evaluation import _assemble, _decode_evaluate_response
from splinegrid._splines import decode_full_grid
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

CHUNK_VALUES = 256 * 1024 // 8  # the server's chunk size in doubles


def best(seconds: Callable[[], float]) -> float:
    return min(seconds() for _ in range(3))


def evaluate_stream(blocks: int, ni: int, nj: int, nk: int) -> list[bytes]:
    rng = np.random.default_rng(0)
    header = service_pb2.EvaluateGridResponse()
    header.header.revision, header.header.spatial_dim = 1, 3
    for b in range(blocks):
        announced = header.header.blocks.add(block=b)
        announced.extents.i, announced.extents.j, announced.extents.k = ni, nj, nk
    messages = [header.SerializeToString()]
    for b in range(blocks):
        values = rng.normal(size=ni * nj * nk * 3)
        for at in range(0, values.size, CHUNK_VALUES):
            chunk = service_pb2.EvaluateGridResponse()
            chunk.chunk.block, chunk.chunk.field, chunk.chunk.offset = b, 1, at
            chunk.chunk.values.extend(values[at:at + CHUNK_VALUES])
            messages.append(chunk.SerializeToString())
    return messages


def generated_evaluate(messages: list[bytes]) -> float:
    start = time.perf_counter()
    arrays: dict[int, np.ndarray] = {}
    for data in messages:
        part = service_pb2.EvaluateGridResponse.FromString(data)
        if part.HasField("header"):
            for a in part.header.blocks:
                e = a.extents
                arrays[a.block] = np.empty(e.k * e.j * e.i * 3)
        else:
            c = part.chunk
            values = np.asarray(c.values, dtype=np.float64)
            arrays[c.block][c.offset:c.offset + values.size] = values
    return time.perf_counter() - start


def wire_evaluate(messages: list[bytes]) -> float:
    start = time.perf_counter()
    _assemble((_decode_evaluate_response(m) for m in messages), np.dtype(np.float64))
    return time.perf_counter() - start


def full_grid(controls: int) -> bytes:
    n = round(controls ** (1 / 3))
    grid = grid_pb2.Grid(name="grids/big")
    block = grid.revision.blocks.add(index=0, spatial_dim=3)
    for _ in range(3):
        block.directions.add(order=4, num_controls=n, knots=np.linspace(0, 1, n + 4).tolist())
    block.control_points.extend(np.random.default_rng(1).normal(size=n ** 3 * 3))
    return grid.SerializeToString()


def generated_full(data: bytes) -> float:
    start = time.perf_counter()
    grid = grid_pb2.Grid.FromString(data)
    for b in grid.revision.blocks:
        np.array(b.control_points, dtype=np.float64)
    return time.perf_counter() - start


def wire_full(data: bytes) -> float:
    start = time.perf_counter()
    decode_full_grid(data)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--blocks", type=int, default=2)
    parser.add_argument("--extents", default="129,129,65")
    parser.add_argument("--controls", type=int, default=1_000_000)
    args = parser.parse_args()
    ni, nj, nk = (int(v) for v in args.extents.split(","))
    messages = evaluate_stream(args.blocks, ni, nj, nk)
    values = args.blocks * ni * nj * nk * 3
    mb = sum(map(len, messages)) / 1e6
    for name, path in (("generated", generated_evaluate), ("wire", wire_evaluate)):
        s = best(lambda: path(messages))
        print(f"EvaluateGrid {values / 1e6:.1f} M doubles ({mb:.0f} MB, {len(messages)} "
              f"messages) {name:>9}: {s * 1e3:8.1f} ms  {mb / s:7.0f} MB/s")
    data = full_grid(args.controls)
    for name, path in (("generated", generated_full), ("wire", wire_full)):
        s = best(lambda: path(data))
        print(f"GetGrid FULL {len(data) / 1e6:.0f} MB control net {name:>9}: {s * 1e3:8.1f} ms"
              f"  {len(data) / 1e6 / s:7.0f} MB/s")


if __name__ == "__main__":
    main()
