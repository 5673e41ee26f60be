#!/usr/bin/python3
"""Fit a grid to the paper's tolerances by boundary kind, fair it, and plot its wall curvature.

Imports the grid, fits it watertight to 0.15e-3 on walls, 2e-3 on block interfaces and 8e-3 on
outer boundaries (in the grid's length unit), creates a faired revision with FairGrid (the
largest fairing weight within the same tolerances), prints both reports, and writes the wall
curvature of both revisions against arc length to a PNG. Exits non-zero if a tolerance is not
met or a cell folds in either revision.

Run from the repository root, after building the target splinegrid_python:

    PYTHONPATH=build/python /usr/bin/python3 python/examples/fair_and_plot.py \
        --server localhost:50051 --png curvature.png
"""

from __future__ import annotations

import argparse
import pathlib
import sys

try:
    from splinegrid import Client, SplinegridError
    from splinegrid.plot import plot_wall_curvature
except ImportError as error:
    sys.exit(f"cannot import splinegrid ({error}); build the target splinegrid_python and run "
             "with PYTHONPATH=BUILD/python")

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_GRID = REPO_ROOT / ".." / "shared" / "data" / "grids" / "n0012_225-65.p2dfmt"


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--server", default="localhost:50051", help="host:port")
    parser.add_argument("--grid", type=pathlib.Path, default=DEFAULT_GRID,
                        help="Plot3D file (default: %(default)s)")
    parser.add_argument("--name", default="fair-and-plot", help="grid id on the server")
    parser.add_argument("--png", type=pathlib.Path, default=pathlib.Path("curvature.png"),
                        help="output image (default: %(default)s)")
    parser.add_argument("--keep", action="store_true", help="keep the grid on the server")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per call")
    return parser.parse_args()


def describe(label: str, fit) -> str:
    r = fit.report
    lines = [f"{label}: revision {fit.revision}, {fit.num_points} points -> "
             f"{fit.num_control_points} control points ({fit.compression_ratio:.1f}x), "
             f"tolerances {'met' if r.tolerance_met else 'NOT met'}, "
             f"{r.folded_cells} folded sub-cells, worst Jacobian ratio {r.min_jacobian_ratio:.3g}"]
    if r.fairing_weight > 0:
        lines.append(f"  fairing weight {r.fairing_weight:.3g}")
    for name, c in (("walls unfaired", r.unfaired_wall_curvature), ("walls", r.wall_curvature)):
        if c.lines:
            lines.append(f"  {name}: {c.samples} samples, {c.extrema} curvature extrema, "
                         f"sum of squared differences {c.sum_squared_differences:.4g}")
    return "\n".join(lines)


def main() -> int:
    args = parse_args()
    with Client(args.server, timeout=args.timeout) as client:
        try:
            grid = client.import_plot3d(args.grid, grid_id=args.name)
        except SplinegridError as error:
            if error.code != "ALREADY_EXISTS":
                raise
            client.delete(args.name)
            grid = client.import_plot3d(args.grid, grid_id=args.name)
        try:
            fit = client.fit(grid.name, boundary_tolerances={})
            print(describe("fit", fit))
            faired = client.fair(grid.name, revision=fit.revision)
            print(describe("faired", faired))
            before = client.wall_curvature(grid.name, revision=fit.revision)
            after = client.wall_curvature(grid.name, revision=faired.revision)
            plot_wall_curvature({f"fit (revision {fit.revision})": before,
                                 f"faired (revision {faired.revision})": after},
                                args.png, title=f"{grid.name}: wall curvature")
            print(f"wrote {args.png}")
            ok = all(f.report.tolerance_met and f.report.folded_cells == 0
                     for f in (fit, faired))
        finally:
            if not args.keep:
                client.delete(grid.name)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
