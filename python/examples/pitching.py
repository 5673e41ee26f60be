#!/usr/bin/python3
"""A fluid-structure coupling client: the pitching NACA 0012, deformed and evaluated per step.

Imports the 257 x 129 pitching-airfoil C-grid (its 2-D view), fits it once to the paper's
tolerances by boundary kind, then runs a solver's time loop against the server. Every step

  1. deforms the grid (DeformGrid): the wall turned by alpha(n) = amplitude sin(2 pi n / period)
     about the quarter chord (0.25, 0), with reference_revision = the fit (motions are absolute,
     no drift), base_revision = the last acknowledged step's revision (a concurrent change is
     ABORTED, so a step never forks the history), and the step's time and number stamped on
     the new revision;
  2. evaluates that revision at refinement level 1 (EvaluateGrid), what a solver computes on;
  3. checks for folds client-side: the signed area of every cell of the evaluated grid (NumPy)
     against its sign in the fitted grid at the same level (step 0).

Prints latency percentiles (p50, p90, p99, max) of the deform call, the evaluate call and the
whole step, and the number of folded cells. Exits 1 if a cell folded, the server refused a
step (a fold it found itself) or a step failed, 3 when the setup (import, fit) failed.

Surviving a replica's death: every call that breaks off (UNAVAILABLE, or INTERNAL "RST_STREAM"
from a balancer) is made again with backoff (--attempts, the client's RetryPolicy; an
evaluation from its start). A DeformGrid attempt whose answer was lost may still have been
stored; its retry then meets base_revision and answers ABORTED. So when a deform fails with
anything but a fold (FAILED_PRECONDITION) or a bad request, the client asks
``get(name, step=n)`` whether that step's revision landed and, if so, takes it as
acknowledged. ``--acked FILE`` records one line "step revision" per acknowledged step (flushed
at once), so every acknowledged revision can be checked afterwards.

Run from the repository root, after building the target splinegrid_python:

    PYTHONPATH=build/python /usr/bin/python3 python/examples/pitching.py \\
        --server localhost:50051 --steps 100 [--amplitude 10]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import pathlib
import sys
import time
from typing import NamedTuple

import numpy as np

try:
    from splinegrid import Client, RetryPolicy, SplinegridError, grid_name
    from splinegrid.v1 import grid_pb2
except ImportError as error:
    sys.exit(f"cannot import splinegrid ({error}); build the target splinegrid_python and run "
             "with PYTHONPATH=BUILD/python")

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_GRID = REPO_ROOT / ".." / "shared" / "data" / "grids" / "n0012_pitch_257x129.fmt"
QUARTER_CHORD = (0.25, 0.0)


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--server", default="localhost:50051", help="host:port")
    parser.add_argument("--steps", type=int, default=100, help="time steps (default 100)")
    parser.add_argument("--amplitude", type=float, default=10.0,
                        help="pitch amplitude in degrees (default 10)")
    parser.add_argument("--period", type=int, default=0,
                        help="steps per pitch cycle (default: --steps, one whole cycle)")
    parser.add_argument("--dt", type=float, default=0.01,
                        help="time step of the stamped solver time (default 0.01)")
    parser.add_argument("--level", type=int, default=1,
                        help="refinement level the solver evaluates at (default 1)")
    parser.add_argument("--check-level", type=int, default=0,
                        help="refinement level of the server's fold check, 0 to 4 (default 0)")
    parser.add_argument("--grid", type=pathlib.Path, default=DEFAULT_GRID,
                        help="the pitching airfoil's Plot3D grid (default: %(default)s)")
    parser.add_argument("--name", default="pitching-py", help="grid id on the server")
    parser.add_argument("--keep", action="store_true", help="keep the grid on the server")
    parser.add_argument("--quiet", action="store_true", help="no line per step")
    parser.add_argument("--timeout", type=float, default=120.0,
                        help="seconds per call, retries included (default 120)")
    parser.add_argument("--attempts", type=int, default=8,
                        help="attempts per call while the server is UNAVAILABLE (default 8: "
                        "about 5 s of backoff, enough for a balancer to find another replica "
                        "or a server to restart)")
    parser.add_argument("--acked", type=pathlib.Path,
                        help="write one line 'step revision' per acknowledged step to this "
                        "file (flushed per step)")
    args = parser.parse_args()
    if args.steps < 1 or args.level < 0 or not math.isfinite(args.amplitude):
        parser.error("--steps must be >= 1, --level >= 0 and --amplitude finite")
    if args.attempts < 1 or not args.timeout > 0:
        parser.error("--attempts must be >= 1 and --timeout positive")
    return args


class DeformOutcome(NamedTuple):
    """What became of one step's deformation: ``kind`` "acknowledged" (stored as
    ``revision``), "refused" (the server's fold check: not stored), "failed" (not stored: a bad
    request, or the server could not be reached) or "conflict" (ABORTED, and not by an attempt
    of ours: someone else changed the grid); ``report`` the DeformReport of an acknowledged
    revision, ``answered`` whether the deform call itself answered, ``note`` what happened."""
    kind: str
    revision: int = 0
    report: object = None
    answered: bool = False
    note: str = ""


def revision_of_step(client: Client, name: str, step: int):
    """The revision stored for solver step ``step`` (get with step), None when there is none."""
    try:
        revision = client.get(name, step=step).revision
    except SplinegridError as error:
        if error.code == "NOT_FOUND":
            return None
        raise
    if revision.step != step or revision.origin != grid_pb2.REVISION_ORIGIN_DEFORM:
        return None
    return revision


def deform_step(client: Client, name: str, acked_step: int, late: list,
                **deform) -> DeformOutcome:
    """One step's deform (retried on UNAVAILABLE by the client) and, when it fails without a
    verdict, whether one of its attempts was stored anyway:

    - OK: acknowledged;
    - FAILED_PRECONDITION (a fold), INVALID_ARGUMENT, NOT_FOUND: nothing was stored;
    - anything else (UNAVAILABLE after all retries, DEADLINE_EXCEEDED, ABORTED because a retry
      met the revision its own earlier attempt stored, ...): ``get(step=n)`` says whether the
      step's revision landed; if it did, it is acknowledged. ABORTED without one means the grid
      moved past ``base_revision`` for another reason: the newest revision is adopted (appended
      to ``late``) when it is a deformation of this run (same reference) for an
      unacknowledged earlier step, whose lost attempt landed after the client gave up on it,
      and the step is made again on top of it; anything else is a conflict, never deformed
      over.
    """
    step = deform["step"]
    for round_ in range(2):
        try:
            moved = client.deform(name, **deform)
            return DeformOutcome("acknowledged", moved.revision, moved.report, True)
        except SplinegridError as error:
            failure = error
        if failure.code == "FAILED_PRECONDITION":
            return DeformOutcome("refused", note=str(failure))
        if failure.code in ("INVALID_ARGUMENT", "NOT_FOUND"):
            return DeformOutcome("failed", note=str(failure))
        try:
            landed = revision_of_step(client, name, step)
        except SplinegridError as error:
            return DeformOutcome("failed", note=f"{failure}; whether it was stored is unknown: "
                                 f"{error}")
        if landed is not None:
            return DeformOutcome("acknowledged", landed.revision, landed.deform_report, False,
                                 f"{failure}; its revision {landed.revision} had been stored: "
                                 "acknowledged")
        if failure.code != "ABORTED":
            return DeformOutcome("failed", note=f"{failure}; not stored")
        if round_ == 0:
            try:
                latest = client.get(name).revision
            except SplinegridError:
                latest = None
            if (latest is not None and latest.origin == grid_pb2.REVISION_ORIGIN_DEFORM
                    and latest.parent_revision == deform["reference_revision"]
                    and acked_step < latest.step < step):
                late.append(latest)
                deform = dict(deform, base_revision=latest.revision)
                continue
        break
    return DeformOutcome("conflict", note=f"{failure}; the grid was changed by another client")


def signed_cell_areas(points: np.ndarray) -> np.ndarray:
    """Signed areas of the cells of a 2-D block shaped (1, nj, ni, 2) (or (nj, ni, 2)):
    (p11 - p00) x (p01 - p10) / 2, shaped (nj - 1, ni - 1)."""
    p = points.reshape(points.shape[-3:])
    d1 = p[1:, 1:] - p[:-1, :-1]   # p11 - p00
    d2 = p[1:, :-1] - p[:-1, 1:]   # p01 - p10
    return 0.5 * (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0])


def grid_areas(grid) -> list[np.ndarray]:
    return [signed_cell_areas(block.points) for block in grid]


def percentile_row(label: str, ms: list[float]) -> str:
    """p50, p90, p99 (nearest rank) and max of ``ms``."""
    if not ms:
        return f"  {label:<16} {'-':>9} {'-':>9} {'-':>9} {'-':>9}"
    values = np.sort(np.asarray(ms))
    ranks = [max(1, math.ceil(q * len(values))) - 1 for q in (0.5, 0.9, 0.99)]
    return (f"  {label:<16} " + " ".join(f"{values[r]:9.3f}" for r in ranks)
            + f" {values[-1]:9.3f}")


def main() -> int:
    args = parse_args()
    period = args.period if args.period > 0 else args.steps
    name = grid_name(args.name)
    try:
        acked = open(args.acked, "w") if args.acked else contextlib.nullcontext()
    except OSError as error:
        print(f"--acked: {error}", file=sys.stderr)
        return 2
    retry = RetryPolicy(max_attempts=args.attempts)
    with acked, Client(args.server, timeout=args.timeout, retry=retry) as client:
        try:
            client.import_plot3d(args.grid, grid_id=args.name, display_name="pitching NACA 0012",
                                 planar_view=True)
        except (OSError, SplinegridError) as error:
            print(f"import: {error}", file=sys.stderr)
            return 3
        try:
            fit = client.fit(name, boundary_tolerances={})  # 0.15e-3 wall, 2e-3, 8e-3 outer
            start = client.evaluate(name, level=args.level, revision=fit.revision)
        except SplinegridError as error:
            print(f"fit: {error}", file=sys.stderr)
            client.delete(name)
            return 3
        print(f"{name} revision {fit.revision}: {fit.num_points} points -> "
              f"{fit.num_control_points} control points ({fit.compression_ratio:.1f}x), "
              f"max deviation {fit.max_deviation:.3g}")
        reference = grid_areas(start)
        cells = sum(a.size for a in reference)
        print(f"{args.steps} steps, pitch +-{args.amplitude:g} degrees about {QUARTER_CHORD}, "
              f"period {period} steps; {cells} cells at level {args.level} checked per step")

        deform_ms: list[float] = []
        server_ms: list[float] = []
        evaluate_ms: list[float] = []
        step_ms: list[float] = []
        folded = refused = failed = 0
        # The base of every deformation: the last acknowledged revision (the fit's at first). A
        # step whose deformation was not stored leaves it, so the next step builds on it.
        previous = fit.revision
        acked_step = 0

        def acknowledge(step: int, revision: int) -> None:
            if args.acked:
                acked.write(f"{step} {revision}\n")
                acked.flush()

        for n in range(1, args.steps + 1):
            alpha = args.amplitude * math.sin(2.0 * math.pi * n / period)
            t0 = time.perf_counter()
            late: list = []
            outcome = deform_step(
                client, name, acked_step, late, rotate_degrees=alpha, about=QUARTER_CHORD,
                reference_revision=fit.revision, base_revision=previous, time=n * args.dt,
                step=n, check_level=args.check_level)
            t1 = time.perf_counter()
            deform_ms.append(1e3 * (t1 - t0))
            for revision in late:
                print(f"step {n}: the revision {revision.revision} of step {revision.step} had "
                      "been stored after all: acknowledged")
                acknowledge(revision.step, revision.revision)
                previous, acked_step = revision.revision, revision.step
            if outcome.kind != "acknowledged":
                print(f"step {n} alpha {alpha:.3f}: {outcome.note}")
                if outcome.kind == "refused":
                    refused += 1
                else:
                    failed += 1
                if outcome.kind == "conflict":
                    break  # never deform over someone else's revision
                continue
            if outcome.note:
                print(f"step {n} alpha {alpha:.3f}: {outcome.note}")
            acknowledge(n, outcome.revision)
            previous, acked_step = outcome.revision, n
            if outcome.answered:
                server_ms.append(1e3 * outcome.report.seconds)
            try:
                grid = client.evaluate(name, level=args.level, revision=outcome.revision)
            except SplinegridError as error:
                print(f"step {n}: evaluate: {error}")
                failed += 1
                continue
            t2 = time.perf_counter()
            evaluate_ms.append(1e3 * (t2 - t1))
            areas = grid_areas(grid)
            if [a.shape for a in areas] != [a.shape for a in reference]:
                print(f"step {n}: cells {[a.shape for a in areas]}, expected "
                      f"{[a.shape for a in reference]}")
                failed += 1
                continue
            folds = int(sum(np.count_nonzero((r != 0.0) & ~(a * r > 0.0))
                            for a, r in zip(areas, reference)))
            folded += folds
            step_ms.append(1e3 * (time.perf_counter() - t0))
            if not args.quiet:
                print(f"step {n:3d} t {n * args.dt:.3f} alpha {alpha:8.3f} revision "
                      f"{outcome.revision:4d} min Jacobian ratio "
                      f"{outcome.report.min_jacobian_ratio:.4f} deform {deform_ms[-1]:7.3f} ms "
                      f"evaluate {evaluate_ms[-1]:7.3f} ms folds {folds}")

        print(f"latency over {args.steps} steps, ms:      p50       p90       p99       max")
        print(percentile_row("deform", deform_ms))
        print(percentile_row("  (server)", server_ms))
        print(percentile_row("evaluate", evaluate_ms))
        print(percentile_row("step", step_ms))
        print(f"folds: {folded} (folded cells over all steps), {refused} steps refused by the "
              f"server, {failed} failed")
        if not args.keep:
            client.delete(name)
    return 0 if folded == 0 and refused == 0 and failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
