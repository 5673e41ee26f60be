"""Generation of an O-grid around a profile, or of a volume grid off a stored surface grid
(GenerateGrid): the request built from the Client's arguments (the profile or surface, the
layers, the fit of revision 1; checked before any call), and the call."""

from __future__ import annotations

import os
from typing import Any, Optional, Union

import numpy as np
import numpy.typing as npt

from splinegrid._args import (_LAYER_METHODS, _MARCH_SIDES, Triple, _airfoil_text, _fit_spec, _grid_id,
                              _integer, _non_negative_int, grid_name)
from splinegrid._calls import _Calls
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2


def _profile(request: service_pb2.GenerateGridRequest,
             airfoil: Union[None, str, bytes, "os.PathLike[str]"],
             points: Optional[npt.ArrayLike],
             stored_wall: Union[None, str, tuple[Any, ...]]) -> None:
    """Sets the request's profile from exactly one of ``airfoil``, ``points`` and
    ``stored_wall`` (see Client.generate); ValueError naming the argument otherwise."""
    given = [airfoil is not None, points is not None, stored_wall is not None]
    if sum(given) != 1:
        raise ValueError("give exactly one of airfoil, points and stored_wall")
    if airfoil is not None:
        request.airfoil_file = _airfoil_text(airfoil)
    elif points is not None:
        xy = np.ascontiguousarray(points, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2:
            raise ValueError(f"points has shape {xy.shape}; give an (n, 2) array")
        request.points.xy.extend(xy.reshape(-1).tolist())
    else:
        wall: tuple[Any, ...] = ((stored_wall,) if isinstance(stored_wall, str)
                                 else tuple(stored_wall or ()))
        if not 1 <= len(wall) <= 3:
            raise ValueError(f"stored_wall = {stored_wall!r}; give name, (name, block) or "
                             "(name, block, revision)")
        request.stored_wall.name = grid_name(wall[0])
        if len(wall) > 1:
            request.stored_wall.block = _non_negative_int(wall[1], "stored_wall block")
        if len(wall) > 2:
            request.stored_wall.revision = _non_negative_int(wall[2], "stored_wall revision")


def _layers(request: service_pb2.GenerateGridRequest, method: Optional[str],
            wall_points: Optional[int], layers: Optional[int],
            first_height: Optional[float], distance: Optional[float],
            orthogonalize: Optional[bool], fit_tolerance: Optional[float]) -> None:
    """Sets the layer parameters given (None: the server's default); ValueError for an unknown
    ``method`` or a count that is not an integer."""
    if method is not None:
        if method not in _LAYER_METHODS:
            raise ValueError(f"method = {method!r}; give one of {sorted(_LAYER_METHODS)}")
        request.method = _LAYER_METHODS[method]
    for field, value in (("wall_points", wall_points), ("layers", layers)):
        if value is not None:
            setattr(request, field, _integer(value, field))
    for field, number in (("first_height", first_height), ("distance", distance),
                          ("fit_tolerance", fit_tolerance)):
        if number is not None:  # NaN and non-positive values: the server names them
            setattr(request, field, float(number))
    if orthogonalize is not None:
        request.orthogonalize = bool(orthogonalize)


def _set_fit(request: service_pb2.GenerateGridRequest, control_counts: Optional[Triple],
             tolerance: Optional[float], order: int, max_controls: int,
             boundary_tolerances: Optional[dict[str, float]],
             fairing: Union[None, str, float]) -> None:
    """The fit of revision 1 from :meth:`fit`'s arguments; none given: the server's default."""
    if any(v is not None for v in (control_counts, tolerance, boundary_tolerances, fairing)):
        request.spec.CopyFrom(_fit_spec(control_counts, tolerance, order, max_controls,
                                        boundary_tolerances, fairing))
        if not request.spec.HasField("resolution"):
            request.spec.boundary_tolerances.SetInParent()


def _volume_request(name: str, surface: str, revision: int, display_name: str,
                    layers: Optional[int], first_height: Optional[float],
                    distance: Optional[float], side: str, normal_smoothing: Optional[int],
                    symmetry_planes: Optional[bool],
                    allow_folds: bool) -> service_pb2.GenerateGridRequest:
    """The GenerateGrid request of :meth:`_GenerateCalls.generate_volume` without its fit;
    ValueError naming the argument."""
    if side not in _MARCH_SIDES:
        raise ValueError(f"side = {side!r}; give one of {sorted(_MARCH_SIDES)}")
    request = service_pb2.GenerateGridRequest(grid_id=_grid_id(name), display_name=display_name,
                                              allow_folds=bool(allow_folds),
                                              side=_MARCH_SIDES[side])
    request.stored_surface.name = grid_name(surface)
    request.stored_surface.revision = _non_negative_int(revision, "revision")
    _layers(request, None, None, layers, first_height, distance, None, None)
    if normal_smoothing is not None:  # the server names values outside [0, 1000]
        smoothing = _integer(normal_smoothing, "normal_smoothing")
        if not -2**31 <= smoothing < 2**31:
            raise ValueError(f"normal_smoothing = {smoothing}; must be in [0, 1000]")
        request.normal_smoothing = smoothing
    if symmetry_planes is not None:
        if not isinstance(symmetry_planes, (bool, np.bool_)):
            raise ValueError(f"symmetry_planes = {symmetry_planes!r}; must be True or False")
        request.symmetry_planes = bool(symmetry_planes)
    return request


class _GenerateCalls(_Calls):
    """The Client's grid generation (GenerateGrid)."""

    def generate(self, name: str = "", airfoil: Union[None, str, bytes,
                                                      "os.PathLike[str]"] = None,
                 points: Optional[npt.ArrayLike] = None,
                 stored_wall: Union[None, str, tuple[Any, ...]] = None,
                 display_name: str = "", method: Optional[str] = None,
                 wall_points: Optional[int] = None, layers: Optional[int] = None,
                 first_height: Optional[float] = None, distance: Optional[float] = None,
                 orthogonalize: Optional[bool] = None,
                 fit_tolerance: Optional[float] = None,
                 control_counts: Optional[Triple] = None, tolerance: Optional[float] = None,
                 order: int = 4, max_controls: int = 0,
                 boundary_tolerances: Optional[dict[str, float]] = None,
                 fairing: Union[None, str, float] = None, allow_folds: bool = False
                 ) -> service_pb2.GenerateGridResponse:
        """Generates an O-grid around a profile, stores it as the new grid ``name`` ("" lets the
        server pick an id; ALREADY_EXISTS if taken) and fits it as revision 1. Nothing is
        stored on an error.

        The profile is one of ``airfoil`` (a Selig or Lednicer file: its path, or its text as a
        str with line breaks, or bytes), ``points`` (an ``(n, 2)`` array in Selig order:
        trailing edge, upper surface, leading edge, lower surface, trailing edge) or
        ``stored_wall``: a grid's name, or ``(name, block)`` or ``(name, block, revision)``
        (the wall points of that 2-D block's j = 0 edge, revision 0 = latest).

        Layers (None: the server's defaults, core/generate/profile_grid.h): ``method``
        ``"offsets"`` (curvature-controlled offsets, default), ``"transfinite"`` or
        ``"elliptic"`` (transfinite, smoothed by the elliptic equations coarse to fine; odd
        ``wall_points``, even ``layers``),
        ``wall_points`` (257; the first repeated as the last), ``layers`` (128 cells outward),
        ``first_height`` (in the profile's unit; 1e-5 of its chord), ``distance`` (of the
        outer boundary from the wall; 50 chords), ``orthogonalize`` (transfinite: lines leave
        the wall normally; True),
        ``fit_tolerance`` (of the profile spline to the points, in their unit; default 1e-4 of
        the profile's chord).

        The fit of revision 1 takes :meth:`fit`'s arguments; with none of ``control_counts``,
        ``tolerance``, ``boundary_tolerances`` and ``fairing`` the server interpolates the grid
        (exact; wall j = 0, outer j = max, the seam an interface). A fit that folds cells is
        refused (nothing stored) unless ``allow_folds``.

        Returns the GenerateGridResponse proto: ``grid`` (BASIC view, revision 1), ``report``
        (GenerationReport: ``parameters`` used, ``extents``, ``profile`` fit, ``growth_ratio``,
        ``retries``, ``marched_layers`` (transfinite, elliptic: the offset layers the lines start
        from past a cove; 0 from the wall), ``quality`` with ``negative_cells``, ``first_height_min``/``max``,
        ``wall_orthogonality_degrees``, ...; stage seconds) and ``fit`` (as :meth:`fit`
        returns it).
        """
        request = service_pb2.GenerateGridRequest(grid_id=_grid_id(name),
                                                  display_name=display_name,
                                                  allow_folds=bool(allow_folds))
        _profile(request, airfoil, points, stored_wall)
        _layers(request, method, wall_points, layers, first_height, distance, orthogonalize,
                fit_tolerance)
        _set_fit(request, control_counts, tolerance, order, max_controls, boundary_tolerances,
                 fairing)
        return self._unary(self.stub.GenerateGrid, request,
                           service_pb2.GenerateGridResponse)

    def generate_volume(self, name: str, surface: str, revision: int = 0,
                        display_name: str = "", layers: Optional[int] = None,
                        first_height: Optional[float] = None, distance: Optional[float] = None,
                        side: str = "outward", normal_smoothing: Optional[int] = None,
                        symmetry_planes: Optional[bool] = None,
                        control_counts: Optional[Triple] = None,
                        tolerance: Optional[float] = None, order: int = 4, max_controls: int = 0,
                        boundary_tolerances: Optional[dict[str, float]] = None,
                        fairing: Union[None, str, float] = None, allow_folds: bool = False
                        ) -> service_pb2.GenerateGridResponse:
        """Marches hexahedral layers off every block of the stored surface grid ``surface``
        (revision ``revision``, 0 = latest; blocks ni x nj x 1 in 3-D), stores the volume grid
        as ``name`` ("" lets the server pick an id) and fits it as revision 1. The blocks march
        together: points they share stay shared (watertight), k = 0 is the surface, k = max the
        outer layer. Nothing is stored on an error.

        Layers (None: the server's defaults, core/generate/surface_offset.h): ``layers`` (32),
        ``first_height`` (1e-3), ``distance`` (0.5, of the last layer from the surface), ``side``
        ``"outward"`` (away from the volume the surface bounds), ``"along"`` or ``"against"``
        (the first block's i x j normal), ``normal_smoothing`` (80 sweeps at the last layer),
        ``symmetry_planes`` (True: free edges on a coordinate plane stay on it, e.g. a half
        wing's root).

        The fit takes :meth:`fit`'s arguments; with none the server interpolates with uniform
        parameters (exact, and watertight at every level). Returns the GenerateGridResponse:
        ``report.volume`` (VolumeReport: ``block_extents``, ``reversed_i``,
        ``symmetry_planes``, ``min_scaled_jacobian``, ``crease_vertices``, ...),
        ``report.parameters``, ``grid`` and ``fit``.
        """
        request = _volume_request(name, surface, revision, display_name, layers, first_height,
                                  distance, side, normal_smoothing, symmetry_planes, allow_folds)
        _set_fit(request, control_counts, tolerance, order, max_controls, boundary_tolerances,
                 fairing)
        return self._unary(self.stub.GenerateGrid, request,
                           service_pb2.GenerateGridResponse)
