#!/usr/bin/python3
"""SciPy's separable least-squares fit of a volume, the baseline of bench/fit_benchmark.cc.

Reads a block written by the benchmark (the same points, parameters and knot vectors as its own
fit), fits it with scipy.interpolate.make_lsq_spline one direction at a time (k, then j, then i:
the order of the kernel's passes), and prints one line of JSON with the wall time per fit:
    {"scipy": "1.10.1", "repeats": 7, "seconds_median": 0.061, "seconds_min": 0.060,
     "controls": [24, 24, 24]}

make_lsq_spline is the plain least-squares fit (free ends; the kernel also pins the end
controls to the data), by normal equations and a banded Cholesky factorisation, applied to every
line of a direction at once (y of shape (m, lines)).

Input file, little-endian: int32 ni, nj, nk, spatial_dim, order; then per direction d = i, j, k:
int32 m_d, m_d float64 parameters, int32 t_d, t_d float64 knots; then ni*nj*nk*spatial_dim
float64 points, i fastest, coordinates interleaved.

Usage: scipy_separable_fit.py BLOCK_FILE [REPEATS]   (run with /usr/bin/python3: Debian's
python3-scipy)
"""
import json
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.interpolate import make_lsq_spline


def read_block(path):
    with open(path, "rb") as f:
        data = f.read()
    offset = 0

    def take(dtype, count):
        nonlocal offset
        values = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
        offset += values.nbytes
        # A copy: aligned (the file's doubles are not 8-byte aligned, and NumPy takes slow
        # paths for unaligned arrays) and writable (SciPy refuses read-only arrays).
        return values.copy()

    ni, nj, nk, dim, order = (int(v) for v in take("<i4", 5))
    params, knots = [], []
    for _ in range(3):
        params.append(take("<f8", int(take("<i4", 1)[0])))
        knots.append(take("<f8", int(take("<i4", 1)[0])))
    points = take("<f8", ni * nj * nk * dim).reshape(nk, nj, ni, dim)
    if offset != len(data):
        raise ValueError(f"{path}: {len(data) - offset} bytes after the points")
    return points, params, knots, order


def separable_fit(points, params, knots, degree):
    # Array axes are (k, j, i, coordinate): direction d is axis 2 - d.
    control = points
    for d in (2, 1, 0):
        control = make_lsq_spline(params[d], control, knots[d], k=degree, axis=2 - d).c
    return control


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    points, params, knots, order = read_block(sys.argv[1])
    repeats = int(sys.argv[2]) if len(sys.argv) == 3 else 7
    control = separable_fit(points, params, knots, order - 1)  # warm up
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        separable_fit(points, params, knots, order - 1)
        times.append(time.perf_counter() - start)
    print(json.dumps({
        "scipy": scipy.__version__,
        "repeats": repeats,
        "seconds_median": statistics.median(times),
        "seconds_min": min(times),
        "controls": [control.shape[2], control.shape[1], control.shape[0]],
    }))


if __name__ == "__main__":
    main()
