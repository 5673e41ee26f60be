"""Python client of the splinegrid.v1 gRPC service (structured CFD grids as B-spline mappings).

    from splinegrid import Client

    with Client("localhost:50051") as client:
        grid = client.import_file("n0012_225-65.p2dfmt", grid_id="n0012")
        fit = client.fit(grid.name, tolerance=1e-3)
        fine = client.evaluate(grid.name, level=2)   # [EvaluatedBlock], points (nk, nj, ni, s)

The generated stubs live in ``splinegrid.v1`` (generated when the package is built by pip, by
the ``splinegrid_python`` CMake target into ``BUILD/python``, or on first import from a source
checkout; see ``splinegrid._stubs``). See ``splinegrid.client`` for the conventions (names,
array layout, deadlines, retries, routing, errors); ``splinegrid.records`` reads and writes the
framed record files of ``.sgrid`` archives (``Client.export_grid`` / ``Client.import_archive``).
"""

from splinegrid.client import Client
from splinegrid._args import grid_name
from splinegrid._transport import GRID_ROUTING_HEADER, SERVICE
from splinegrid.distributions import Distribution
from splinegrid.errors import SplinegridError
from splinegrid.filekind import FileKind, detect_file_kind
from splinegrid.results import (ArchiveSummary, BoundaryPoints, EvaluatedBlock, EvaluatedGrid,
                                EvaluatedPoints, FullGrid, SplineArrays, WallCurvatureLine)
from splinegrid.retry import RetryPolicy
from splinegrid.watch import RevisionWatch

__all__ = [
    "GRID_ROUTING_HEADER",
    "SERVICE",
    "ArchiveSummary",
    "BoundaryPoints",
    "Client",
    "Distribution",
    "EvaluatedBlock",
    "EvaluatedGrid",
    "EvaluatedPoints",
    "FileKind",
    "FullGrid",
    "RetryPolicy",
    "RevisionWatch",
    "SplineArrays",
    "SplinegridError",
    "WallCurvatureLine",
    "detect_file_kind",
    "grid_name",
]
