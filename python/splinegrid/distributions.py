"""Point distributions on demand for :meth:`Client.evaluate`: per direction, how the points
between the block's (or box's) first and last index are spread. The count still comes from
``level`` or ``counts``; the end points are always those of the block (or ``index_box``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Optional, Union

from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

_KINDS = {
    "original": service_pb2.Distribution.KIND_ORIGINAL,
    "uniform_parameter": service_pb2.Distribution.KIND_UNIFORM_PARAMETER,
    "uniform_arc_length": service_pb2.Distribution.KIND_UNIFORM_ARC_LENGTH,
    "geometric": service_pb2.Distribution.KIND_GEOMETRIC,
}


@dataclass(frozen=True)
class Distribution:
    """``kind``: ``"original"`` (the original grid's clustering, the default),
    ``"uniform_parameter"`` (evenly spaced in the spline parameter), ``"uniform_arc_length"``
    (evenly spaced in arc length along every grid line) or ``"geometric"`` (a first interval of
    arc length ``first_spacing``, in the grid's length unit, then a constant ratio to the
    line's end; ``from_end`` puts the first interval at the last index). Arc length and
    geometric are measured along grid lines: at most one direction per request may use them.
    """
    kind: str = "original"
    first_spacing: float = 0.0
    from_end: bool = False

    @classmethod
    def geometric(cls, first_spacing: float, from_end: bool = False) -> "Distribution":
        """A wall-normal stretching with this first spacing (a new y+ at the wall)."""
        return cls("geometric", first_spacing, from_end)

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise ValueError(f"Distribution kind = {self.kind!r}; use one of {sorted(_KINDS)}")
        if self.kind == "geometric":
            if not (math.isfinite(self.first_spacing) and self.first_spacing > 0):
                raise ValueError(f"Distribution first_spacing = {self.first_spacing}; a geometric "
                                 "distribution needs a positive finite first spacing")
        elif self.first_spacing != 0 or self.from_end:
            raise ValueError(f"Distribution {self.kind!r}: first_spacing and from_end are only "
                             "for 'geometric'")


Distributions = Optional[Mapping[str, Union[Distribution, str]]]


def _set_distributions(request: service_pb2.EvaluateGridRequest,
                       distributions: Distributions) -> None:
    """Writes ``{"i": ..., "j": ..., "k": ...}`` (a :class:`Distribution` or a kind name) into
    the request; ValueError naming a key or value that is wrong."""
    for direction, wanted in (distributions or {}).items():
        if direction not in ("i", "j", "k"):
            raise ValueError(f"distributions key {direction!r}; use 'i', 'j' or 'k'")
        if isinstance(wanted, str):
            wanted = Distribution(wanted)
        if not isinstance(wanted, Distribution):
            raise ValueError(f"distributions[{direction!r}] = {wanted!r}; give a Distribution "
                             "or a kind name")
        out = getattr(request.distributions, direction)
        out.kind = _KINDS[wanted.kind]
        out.first_spacing = wanted.first_spacing
        out.from_end = wanted.from_end
