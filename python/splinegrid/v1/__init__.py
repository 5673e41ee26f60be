"""The generated stubs of the ``splinegrid.v1`` protos: ``grid_pb2``, ``archive_pb2``,
``splinegrid_service_pb2`` and ``splinegrid_service_pb2_grpc``.

An installed package (``pip install ./python``) and the CMake build's copy (``BUILD/python``)
hold them next to this file. A source checkout holds only this file: then the stubs are
generated from ``proto/splinegrid/v1/*.proto`` into the user's cache on first import (see
``splinegrid._stubs``) and that directory joins this package's ``__path__``, so
``PYTHONPATH=python`` works without a build.
"""

import os

if not os.path.isfile(os.path.join(os.path.dirname(__file__), "grid_pb2.py")):
    from splinegrid import _stubs

    _root = _stubs.find_proto_root(os.path.dirname(os.path.dirname(__file__)))
    if _root is None:
        raise ImportError("splinegrid.v1: the generated stubs are missing and no "
                          "proto/splinegrid/v1/*.proto is beside the package to generate them "
                          "from; install the package (pip install ./python) or build the CMake "
                          "target splinegrid_python (PYTHONPATH=BUILD/python)")
    try:
        __path__.append(_stubs.cached(_root))
    except _stubs.StubError as error:
        raise ImportError(f"splinegrid.v1: {error}") from error
