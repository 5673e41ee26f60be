"""Plots of wall curvature before and after fairing (python3-matplotlib, no display needed).

    from splinegrid import Client
    from splinegrid.plot import plot_wall_curvature

    with Client() as client:
        before = client.wall_curvature("n0012", revision=1)
        after = client.wall_curvature("n0012", revision=2)
        plot_wall_curvature({"fit": before, "faired": after}, "curvature.png")
"""

from __future__ import annotations

import os
from typing import Mapping, Sequence, Union

import matplotlib

matplotlib.use("Agg")  # files only: no display on a server

import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

from splinegrid.results import WallCurvatureLine  # noqa: E402

__all__ = ["plot_wall_curvature"]


def plot_wall_curvature(curves: Mapping[str, Sequence[WallCurvatureLine]],
                        path: Union[str, "os.PathLike[str]"], title: str = "",
                        max_lines: int = 4) -> None:
    """Writes a PNG of curvature against arc length, one panel per wall line (the first
    ``max_lines`` of each set), every labelled set of lines (e.g. before/after fairing) overlaid.
    The sets must come from the same grid, so their lines correspond one to one."""
    if not curves:
        raise ValueError("curves: give at least one labelled set of wall lines")
    counts = {label: len(lines) for label, lines in curves.items()}
    if len(set(counts.values())) != 1:
        raise ValueError(f"curves: the sets have different numbers of wall lines {counts}")
    panels = min(next(iter(counts.values())), max_lines)
    if panels == 0:
        raise ValueError("curves: the grid has no wall lines")
    figure, axes = plt.subplots(panels, 1, figsize=(9, 3 * panels), squeeze=False)
    for p in range(panels):
        ax = axes[p][0]
        for label, lines in curves.items():
            line = lines[p]
            ax.plot(line.arc_length, line.curvature, label=label, linewidth=1.0)
        first = next(iter(curves.values()))[p]
        ax.set_title(f"block {first.block}, direction {'ijk'[first.direction]}, "
                     f"start {first.start}", fontsize=9)
        ax.set_xlabel("arc length")
        ax.set_ylabel("curvature")
        ax.grid(True, linewidth=0.3)
        ax.legend(fontsize=8)
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
