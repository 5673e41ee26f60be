#!/usr/bin/python3
"""Fit a Plot3D grid with B-splines on a splinegrid server and pull it back refined.

Imports the grid (two-plane CFL3D files are stored as their 2-D view), fits it to the
tolerances by boundary kind (default; fractions of the grid's reference length), to one
tolerance (--tol) or to given control point counts (--ctl), prints the fit report, evaluates it at the original
resolution and at refinement level L, checks that the refined grid passes through the
original-resolution points (every 2^L-th point of the refined grid is an original point),
checks the block corners against EvaluatePoints, and deletes the grid unless --keep.
Exits non-zero on any failure.

Run from the repository root, after building the target splinegrid_python:

    PYTHONPATH=build/python /usr/bin/python3 python/examples/fit_and_refine.py \
        --server localhost:50051

A fit whose cells fold at refinement levels 0-2 is refused by the server (e.g. --tol 1e-3 on
the C-grid's 500-chord far field); --allow_folds stores it anyway.
"""

from __future__ import annotations

import argparse
import pathlib
import re
import sys

import numpy as np

try:
    from splinegrid import Client, SplinegridError, grid_name
except ImportError as error:
    sys.exit(f"cannot import splinegrid ({error}); build the target splinegrid_python and run "
             "with PYTHONPATH=BUILD/python")

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_GRID = REPO_ROOT / ".." / "shared" / "data" / "grids" / "n0012_225-65.p2dfmt"
RELATIVE_MATCH = 1e-12  # refined vs original-resolution points, relative to the grid's size


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--server", default="localhost:50051", help="host:port")
    parser.add_argument("--grid", type=pathlib.Path, default=DEFAULT_GRID,
                        help="Plot3D file (default: %(default)s)")
    parser.add_argument("--name", default="",
                        help="grid id on the server (default: from the file name)")
    resolution = parser.add_mutually_exclusive_group()
    resolution.add_argument("--tol", type=float, default=None,
                            help="largest deviation, in the grid's length unit (default: "
                                 "tolerances by boundary kind)")
    resolution.add_argument("--ctl", default=None,
                            help="control points per direction instead, e.g. 60,24")
    parser.add_argument("--level", type=int, default=2, help="refinement level (default 2)")
    parser.add_argument("--keep", action="store_true", help="keep the grid on the server")
    parser.add_argument("--allow_folds", action="store_true",
                        help="store the fit even if its cells fold (else refused)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per call")
    return parser.parse_args()


def id_from_path(path: pathlib.Path) -> str:
    """A valid grid id from a file name: lower case [a-z0-9-], starting with a letter."""
    grid_id = re.sub(r"[^a-z0-9]", "-", path.stem.lower())
    return (grid_id if grid_id[:1].isalpha() else f"grid-{grid_id}")[:63]


def print_fit_report(name: str, fit, grid) -> None:
    print(f"{name} revision {fit.revision}: {fit.num_points} points -> "
          f"{fit.num_control_points} control points ({fit.compression_ratio:.1f}x), "
          f"max deviation {fit.max_deviation:.3g}, {1e3 * fit.seconds:.0f} ms")
    print(f"{'block':>5} {'points':>9} {'controls':>9} {'net':>12} {'ratio':>6} "
          f"{'max dev':>10} {'rms dev':>10}  tolerance")
    for b, (summary, block) in enumerate(zip(fit.blocks, grid.revision.blocks)):
        net = "x".join(str(d.num_controls) for d in block.directions)
        met = ("-" if not summary.HasField("tolerance_met")
               else "met" if summary.tolerance_met else f"NOT MET: {summary.unmet_reason}")
        print(f"{b:>5} {summary.num_points:>9} {summary.num_control_points:>9} {net:>12} "
              f"{summary.compression_ratio:>6.1f} {summary.max_deviation:>10.3e} "
              f"{summary.rms_deviation:>10.3e}  {met}")


def check(condition: bool, message: str, failures: list[str]) -> None:
    print(f"  {'ok  ' if condition else 'FAIL'} {message}")
    if not condition:
        failures.append(message)


def run(client: Client, args: argparse.Namespace, name: str) -> list[str]:
    """Fits, reports, evaluates and checks the imported grid `name`; returns the failures."""
    failures: list[str] = []
    if args.ctl is not None:
        fit = client.fit(name, control_counts=[int(c) for c in args.ctl.split(",")],
                         allow_folds=args.allow_folds)
    elif args.tol is not None:
        fit = client.fit(name, tolerance=args.tol, allow_folds=args.allow_folds)
    else:
        fit = client.fit(name, boundary_tolerances={}, allow_folds=args.allow_folds)
    print_fit_report(name, fit, client.get(name))
    if any(s.HasField("tolerance_met") and not s.tolerance_met for s in fit.blocks):
        failures.append("the tolerance was not met everywhere")

    step = 2 ** args.level
    original = client.evaluate(name, level=0)
    refined = client.evaluate(name, level=args.level)
    print(f"evaluated revision {refined.revision} at level 0 and level {args.level} "
          "(arrays shaped (nk, nj, ni, s)):")
    for coarse, fine in zip(original, refined):
        print(f"  block {fine.block}: level 0 {coarse.points.shape}, level {args.level} "
              f"{fine.points.shape} {fine.points.dtype}")
    print("checks:")
    for coarse, fine in zip(original, refined):
        b, p0 = fine.block, coarse.points
        scale = max(1.0, float(np.abs(p0).max()))
        expected = tuple((n - 1) * step + 1 for n in p0.shape[:3]) + p0.shape[3:]
        check(fine.points.shape == expected,
              f"block {b}: level {args.level} shape {fine.points.shape} == {expected}", failures)
        if fine.points.shape != expected:
            continue
        gap = float(np.abs(fine.points[::step, ::step, ::step] - p0).max())
        check(gap <= RELATIVE_MATCH * scale,
              f"block {b}: every level-0 point (the spline at the file's indices, not the "
              f"file's points) reappears at level {args.level} at index (i*{step}, j*{step}), "
              f"largest difference {gap:.1e}; the spline's largest deviation from the file's "
              f"points is {fit.blocks[b].max_deviation:.3e}", failures)
        # The parameters of the first and last grid index are 0 and 1 in every direction.
        corners = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0 if p0.shape[0] > 1 else 0.0]])
        at = client.evaluate_points(name, corners, blocks=b).points
        gap = float(np.abs(at - np.stack([p0[0, 0, 0], p0[-1, -1, -1]])).max())
        check(gap <= RELATIVE_MATCH * scale,
              f"block {b}: EvaluatePoints at the corners matches, difference {gap:.1e}",
              failures)
    return failures


def main() -> int:
    args = parse_args()
    path = args.grid.resolve()
    name = grid_name(args.name or id_from_path(path))
    with Client(args.server, timeout=args.timeout) as client:
        try:
            print(f"server {args.server}: {client.health()}")
            grid = client.import_plot3d(path, grid_id=name, display_name=path.name)
        except (SplinegridError, OSError) as error:
            hint = (" (delete it, or choose another --name)"
                    if getattr(error, "code", None) == "ALREADY_EXISTS" else "")
            print(f"error: {error}{hint}", file=sys.stderr)
            return 1
        source = grid.source
        print(f"imported {path.name} as {grid.name}: {len(source.blocks)} block(s), "
              f"{source.num_points} points, {source.spatial_dim}D ({source.format})")
        try:
            failures = run(client, args, grid.name)
        except SplinegridError as error:
            failures = [str(error)]
            print(f"error: {error}", file=sys.stderr)
        finally:
            if not args.keep:
                try:
                    client.delete(grid.name)
                    print(f"deleted {grid.name}")
                except SplinegridError as error:
                    print(f"error: delete: {error}", file=sys.stderr)
                    failures.append(f"delete: {error}")
    if failures:
        print(f"{len(failures)} failure(s)", file=sys.stderr)
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
