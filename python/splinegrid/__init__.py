"""Python client of the splinegrid.v1 gRPC service (structured CFD grids as B-spline mappings).

    from splinegrid import Client

    with Client("localhost:50051") as client:
        grid = client.import_plot3d("n0012_225-65.p2dfmt", grid_id="n0012")
        fit = client.fit(grid.name, tolerance=1e-3)
        fine = client.evaluate(grid.name, level=2)   # [EvaluatedBlock], points (nk, nj, ni, s)

The generated stubs live in ``splinegrid.v1`` (built next to this package by the
``splinegrid_python`` CMake target, so ``BUILD/python`` is the PYTHONPATH). See ``client`` for
the conventions (names, array layout, deadlines, retries, routing, errors);
``splinegrid.records`` reads and writes the framed record files of ``.sgrid`` archives
(``Client.export_grid`` / ``Client.import_archive``).
"""

from splinegrid.client import (  # __all__: the public names, listed once in client.py
    __all__,
    GRID_ROUTING_HEADER,
    SERVICE,
    ArchiveSummary,
    BoundaryPoints,
    Client,
    EvaluatedBlock,
    EvaluatedGrid,
    EvaluatedPoints,
    RetryPolicy,
    RevisionWatch,
    SplinegridError,
    WallCurvatureLine,
    grid_name,
)
