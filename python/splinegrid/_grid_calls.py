"""The grid resource: get (BASIC view, or FULL with the splines as NumPy arrays), list (every
page), delete, and watch (the revisions as they are stored)."""

from __future__ import annotations

from typing import Any, Iterable, Literal, Optional, Union, overload

from splinegrid._args import _integer, _set_step, grid_name
from splinegrid._calls import _Calls
from splinegrid._splines import decode_full_grid
from splinegrid._transport import _routing_grid
from splinegrid.results import FullGrid
from splinegrid.watch import RevisionWatch
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

LIST_PAGE_SIZE = 500


def _get_request(name: str, revision: int, full: bool, blocks: Iterable[int],
                 step: Optional[int]) -> service_pb2.GetGridRequest:
    """The GetGridRequest of Client.get; ValueError for both a revision and a step."""
    request = service_pb2.GetGridRequest(
        name=grid_name(name), revision=revision, blocks=list(blocks),
        view=service_pb2.GRID_VIEW_FULL if full else service_pb2.GRID_VIEW_BASIC)
    _set_step(request, revision, step)
    return request


def _watch_request(name: str, after_revision: int) -> service_pb2.WatchGridRequest:
    """The WatchGridRequest of Client.watch; ValueError naming ``after_revision`` when it is
    not an integer >= -1."""
    after = _integer(after_revision, "after_revision")
    if after < -1:
        raise ValueError(f"after_revision = {after_revision}; must be >= -1")
    return service_pb2.WatchGridRequest(name=grid_name(name), after_revision=after)


class _GridCalls(_Calls):
    """The Client's calls on the grid resource."""

    def watch(self, name: str, after_revision: int = 0) -> RevisionWatch:
        """The grid's revisions as they are stored (WatchGrid): a generator of
        ``RevisionInfo`` (see :class:`RevisionWatch`).

        The revisions after ``after_revision`` that are stored already come first (0: all of
        them, -1: none), then each new one (a fit, a fairing, a deformation) as it is stored.
        The call has no deadline: it lasts until the grid is deleted, or the watch is closed or
        cancelled; when it breaks off (the replica died or stopped) it is resumed after the
        last revision received::

            with client.watch("naca") as revisions:
                for info in revisions:
                    print(info.revision, info.step)
        """
        request = _watch_request(name, after_revision)
        metadata = self._metadata(_routing_grid(request))

        def open_call(after: int) -> Any:
            resumed = service_pb2.WatchGridRequest(name=request.name, after_revision=after)
            return self.stub.WatchGrid(resumed, metadata=metadata)

        return RevisionWatch(open_call, request.name, request.after_revision, self.retry,
                             self._pause_before_retry)

    @overload
    def get(self, name: str, revision: int = 0, full: Literal[False] = False,
            blocks: Iterable[int] = (), step: Optional[int] = None) -> grid_pb2.Grid: ...

    @overload
    def get(self, name: str, revision: int = 0, *, full: Literal[True],
            blocks: Iterable[int] = (), step: Optional[int] = None) -> FullGrid: ...

    def get(self, name: str, revision: int = 0, full: bool = False,
            blocks: Iterable[int] = (), step: Optional[int] = None
            ) -> Union[grid_pb2.Grid, FullGrid]:
        """The grid with revision ``revision`` (0: latest): the ``Grid`` proto (BASIC view).

        ``full=True`` returns a :class:`FullGrid` instead: the FULL view's proto and the
        revision's splines as NumPy arrays (:class:`SplineArrays`: control points
        ``(nck, ncj, nci, s)``, knot vectors, point distributions), of ``blocks`` only when
        given, decoded without a step per value. ``step``: instead of a revision, the latest
        revision stamped with this solver time step (see :meth:`deform`); NOT_FOUND if there
        is none."""
        request = _get_request(name, revision, full, blocks, step)
        if not full:
            return self._unary(self.stub.GetGrid, request, grid_pb2.Grid)
        data = self._unary(self._get_grid_bytes, request, bytes)
        return decode_full_grid(data)

    def list(self) -> list[grid_pb2.Grid]:
        """Every grid (BASIC view), ordered by name, following the pages."""
        grids: list[grid_pb2.Grid] = []
        request = service_pb2.ListGridsRequest(page_size=LIST_PAGE_SIZE)
        while True:
            response = self._unary(self.stub.ListGrids, request,
                                   service_pb2.ListGridsResponse)
            grids.extend(response.grids)
            if not response.next_page_token:
                return grids
            request.page_token = response.next_page_token

    def delete(self, name: str) -> None:
        self._unary(self.stub.DeleteGrid, service_pb2.DeleteGridRequest(name=grid_name(name)),
                    object)
