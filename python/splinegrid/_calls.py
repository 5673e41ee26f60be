"""What the families of calls (the mixins :class:`splinegrid.Client` is made of: ``_upload_calls``,
``_archive``, ``_grid_calls``, ``_fit_calls``, ``_generate_calls``, ``_deform_calls``,
``_evaluation_calls``) need of a client: the generated stub, the methods that exchange raw bytes,
and the call machinery. ``client.Client`` provides all of it (channel, deadline, routing header,
token, retries, error translation); the families only build requests and read responses, so each
stays one concept and none repeats how a call is made."""

from __future__ import annotations

import threading
from typing import Any, Callable, Optional, TypeVar, Union

from google.protobuf.message import Message

from splinegrid._transport import Metadata, _Attempt
from splinegrid.retry import RetryPolicy
from splinegrid.v1 import splinegrid_service_pb2_grpc as service_grpc

_T = TypeVar("_T")


class _Calls:
    """The interface of ``client.Client`` the call families use (see the module docstring)."""

    stub: service_grpc.SplineGridStub
    timeout: float
    retry: RetryPolicy
    max_evaluation_bytes: Optional[int]  # evaluate's cap on assembled bytes (None: none)
    # The bulk methods on hand-encoded bytes (see Client.__init__): grpc multi-callables.
    _import_grid: Any  # ImportGrid: requests as bytes or messages -> Grid
    _evaluate_grid: Any  # EvaluateGrid -> EvaluationHeader and _evaluation._Chunk
    _evaluate_points: Any  # EvaluatePoints -> EvaluatedPoints
    _get_grid_bytes: Any  # GetGrid -> the response's bytes (FULL view, see _splines)
    _export_grid: Any  # ExportGrid -> ArchiveRecord bytes
    _import_archive: Any  # ImportArchive: requests as bytes -> Grid

    def _call(self, attempt: Callable[[_Attempt], _T], grid: str = "") -> _T:
        """One call: ``attempt`` under the deadline, routing header and retries."""
        raise NotImplementedError

    def _metadata(self, grid: str) -> Optional[Metadata]:
        """The metadata of a call about ``grid``."""
        raise NotImplementedError

    def _pause_before_retry(self, wait: float, stop: Optional[threading.Event] = None) -> bool:
        """The wait before a retry; True when ``stop`` ended it early."""
        raise NotImplementedError

    def _unary(self, method: Callable[..., Any], request: Union[bytes, Message],
               response: type[_T], grid: Optional[str] = None) -> _T:
        """One unary call with :meth:`_call`, its response checked to be a ``response``."""
        raise NotImplementedError
