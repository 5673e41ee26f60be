"""The requests the Client builds from its arguments, without a server: fit, fair, generate's
profile and layers, deform (motions, boundaries, checks), get and watch. A wrong argument raises
ValueError naming it (and its value) before any call."""

import numpy as np
import pytest

from splinegrid import BoundaryPoints
from splinegrid._deform_calls import _deform_request
from splinegrid._fit_calls import _fair_request, _fit_request
from splinegrid._generate_calls import _layers, _profile
from splinegrid._grid_calls import _get_request, _watch_request
from splinegrid._motion_args import _boundary_selection
from splinegrid.v1 import grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2


def fit(name="naca", control_counts=None, tolerance=None, order=4, max_controls=0,
        boundary_tolerances=None, fairing=None, allow_folds=False, ref_length=None,
        face_kinds=None):
    """_fit_request with Client.fit's defaults."""
    return _fit_request(name, control_counts, tolerance, order, max_controls,
                        boundary_tolerances, fairing, allow_folds, ref_length, face_kinds)


class TestFit:
    def test_control_counts_fill_missing_directions_with_zero(self):
        request = fit(control_counts=(12, 8), order=3, max_controls=40, allow_folds=True)
        assert request.name == "grids/naca"
        spec = request.spec
        assert spec.WhichOneof("resolution") == "control_counts"
        assert (spec.control_counts.i, spec.control_counts.j, spec.control_counts.k) == (12, 8, 0)
        assert (spec.order, spec.max_controls_per_direction, spec.allow_folds) == (3, 40, True)

    def test_ref_length_implies_default_tolerances_by_kind(self):
        spec = fit("grids/m6", ref_length=0.25, fairing="tol").spec
        assert spec.reference_length == 0.25
        assert spec.WhichOneof("resolution") == "boundary_tolerances"
        assert spec.boundary_tolerances == grid_pb2.BoundaryTolerances()  # all defaults
        assert spec.fairing.mode == grid_pb2.FAIRING_MODE_TO_TOLERANCE

    def test_given_tolerances_by_kind_are_kept(self):
        spec = fit(boundary_tolerances={"wall": 1e-4, "edge": 0.25, "first_layer": 0.05},
                   fairing=0.5).spec
        assert (spec.boundary_tolerances.wall, spec.boundary_tolerances.edge) == (1e-4, 0.25)
        assert spec.boundary_tolerances.first_layer == 0.05
        assert (spec.fairing.mode, spec.fairing.weight) == (grid_pb2.FAIRING_MODE_WEIGHT, 0.5)

    @pytest.mark.parametrize("kwargs, message", [
        (dict(ref_length=1.0, tolerance=1e-3), "ref_length applies to the tolerances by kind"),
        (dict(ref_length=1.0, control_counts=(4, 4)), "ref_length applies"),
        (dict(ref_length=0.0), r"ref_length = 0.0; give a positive length"),
        (dict(face_kinds="0:imin=wall", tolerance=1e-3), "face_kinds apply to the tolerances"),
        (dict(tolerance=1e-3, control_counts=(4, 4)), "give one of control_counts, tolerance"),
        (dict(boundary_tolerances={"wal": 1.0}), r"unknown kinds \['wal'\]"),
        (dict(control_counts=(1, 2, 3, 4)), r"control_counts = \[1, 2, 3, 4\]"),
        (dict(fairing="smooth"), "fairing = 'smooth': give 'tol' or a positive weight"),
        (dict(fairing=-1.0), "fairing = -1.0"),
    ])
    def test_wrong_arguments_are_named(self, kwargs, message):
        with pytest.raises(ValueError, match=message):
            fit(**kwargs)

    def test_fair_sends_a_fairing_only_when_given(self):
        plain = _fair_request("naca", 3, None, True)
        assert (plain.name, plain.revision, plain.allow_folds) == ("grids/naca", 3, True)
        assert not plain.HasField("fairing")
        weighted = _fair_request("grids/naca", 0, 2.5, False)
        assert (weighted.fairing.mode, weighted.fairing.weight) == (
            grid_pb2.FAIRING_MODE_WEIGHT, 2.5)
        with pytest.raises(ValueError, match="fairing = 0"):
            _fair_request("naca", 0, 0, False)


class TestGenerate:
    def test_points_go_flat_in_selig_order(self):
        request = service_pb2.GenerateGridRequest()
        _profile(request, None, [[1.0, 0.0], [0.0, 0.1], [1.0, 0.0]], None)
        assert request.WhichOneof("profile") == "points"
        assert list(request.points.xy) == [1.0, 0.0, 0.0, 0.1, 1.0, 0.0]

    def test_stored_wall_forms(self):
        request = service_pb2.GenerateGridRequest()
        _profile(request, None, None, "naca")
        assert (request.stored_wall.name, request.stored_wall.block) == ("grids/naca", 0)
        _profile(request, None, None, ("grids/o", 2, 5))
        assert (request.stored_wall.name, request.stored_wall.block,
                request.stored_wall.revision) == ("grids/o", 2, 5)

    def test_airfoil_text_is_sent_as_is(self):
        request = service_pb2.GenerateGridRequest()
        _profile(request, b"NACA 0012\n1.0 0.0\n", None, None)
        assert request.airfoil_file == "NACA 0012\n1.0 0.0\n"

    @pytest.mark.parametrize("args, message", [
        ((None, None, None), "give exactly one of airfoil, points and stored_wall"),
        (("a\nb", [[0.0, 0.0]], None), "give exactly one of"),
        ((None, [1.0, 2.0, 3.0], None), r"points has shape \(3,\); give an \(n, 2\) array"),
        ((None, None, ()), r"stored_wall = \(\); give name"),
        ((None, None, ("naca", -1)), "stored_wall block = -1; must not be negative"),
        ((None, None, ("naca", 0, 1.5)), "stored_wall revision = 1.5; must be an integer"),
    ])
    def test_wrong_profiles_are_named(self, args, message):
        with pytest.raises(ValueError, match=message):
            _profile(service_pb2.GenerateGridRequest(), *args)

    def test_layers_set_only_what_is_given(self):
        request = service_pb2.GenerateGridRequest()
        _layers(request, "elliptic", 129, np.int64(64), 2e-5, None, False, None)
        assert request.method == service_pb2.LAYER_METHOD_ELLIPTIC
        assert (request.wall_points, request.layers, request.first_height) == (129, 64, 2e-5)
        assert not request.HasField("distance") and not request.HasField("fit_tolerance")
        assert request.HasField("orthogonalize") and request.orthogonalize is False

    def test_wrong_layers_are_named(self):
        with pytest.raises(ValueError, match="method = 'spline'; give one of "
                           r"\['elliptic', 'offsets', 'transfinite'\]"):
            _layers(service_pb2.GenerateGridRequest(), "spline", None, None, None, None, None,
                    None)
        with pytest.raises(ValueError, match="layers = 64.0; must be an integer"):
            _layers(service_pb2.GenerateGridRequest(), None, None, 64.0, None, None, None, None)


def deform(name="naca", rotate_degrees=None, about=None, axis=None, translate=None,
           boundary=None, reference_revision=0, base_revision=0, time=0.0, step=0,
           check_level=0, control_displacements=None, boundary_points=None,
           propagation="blend", decay_radius=0.0, rigid_radius=0.0, smoothing_iterations=0,
           max_boundary_error=0.0):
    """_deform_request with Client.deform's defaults."""
    return _deform_request(name, rotate_degrees, about, axis, translate, boundary,
                           reference_revision, base_revision, time, step, check_level,
                           control_displacements, boundary_points, propagation, decay_radius,
                           rigid_radius, smoothing_iterations, max_boundary_error)


class TestDeform:
    def test_a_rigid_motion_and_its_settings(self):
        request = deform(rotate_degrees=2.5, about=(0.25, 0.0), translate=(0.0, 0.1),
                         reference_revision=1, base_revision=4, time=0.5, step=12,
                         check_level=2, propagation="transfinite", decay_radius=3.0,
                         rigid_radius=1.0, smoothing_iterations=5)
        assert request.name == "grids/naca"
        assert request.WhichOneof("motion") == "rigid"
        assert request.rigid.angle_degrees == 2.5
        assert list(request.rigid.center) == [0.25, 0.0]
        assert list(request.rigid.translation) == [0.0, 0.1]
        assert (request.reference_revision, request.base_revision, request.time,
                request.step, request.check_level) == (1, 4, 0.5, 12, 2)
        assert request.propagation == service_pb2.PROPAGATION_TRANSFINITE
        assert (request.decay_radius, request.rigid_radius,
                request.smoothing_iterations) == (3.0, 1.0, 5)

    def test_control_displacements(self):
        request = deform(control_displacements={1: ([3, 7], [[0.0, 0.1], [0.0, 0.2]])})
        (block,) = request.controls.blocks
        assert (block.block, list(block.controls)) == (1, [3, 7])
        assert list(block.values) == [0.0, 0.1, 0.0, 0.2]

    def test_boundary_points_over_a_face_range(self):
        points = BoundaryPoints((0, "jmin", (0, 0), (2, 0)), np.zeros((3, 2)), level=1,
                                displacements=True)
        request = deform(boundary_points=[points], max_boundary_error=1e-3)
        assert request.max_boundary_error == 1e-3
        (moved,) = request.boundary_points.ranges
        assert (moved.range.block, moved.range.face) == (0, grid_pb2.BLOCK_FACE_J_MIN)
        assert (moved.range.end.i, moved.refinement_level, moved.displacements) == (2, 1, True)
        assert list(moved.coordinates) == [0.0] * 6

    @pytest.mark.parametrize("kwargs, message", [
        (dict(), "give one motion: rotate_degrees \\(and/or translate\\), "
                 "control_displacements or boundary_points$"),
        (dict(rotate_degrees=1.0, control_displacements={}),
         "; got rotate_degrees/translate, control_displacements$"),
        (dict(control_displacements={}, about=(0, 0)), "about and axis belong to a rotation"),
        (dict(rotate_degrees=1.0, check_level=5), r"check_level = 5; must be in \[0, 4\]"),
        (dict(rotate_degrees=1.0, propagation="smooth"), "propagation = 'smooth'"),
        (dict(rotate_degrees=1.0, decay_radius=1.0, rigid_radius=2.0),
         "rigid_radius = 2.0 exceeds decay_radius = 1.0"),
        (dict(rotate_degrees=1.0, time=float("nan")), "time = nan; must be finite"),
        (dict(rotate_degrees=1.0, base_revision=-2), "base_revision = -2; must not be negative"),
        (dict(rotate_degrees=1.0, axis=(0, 0, 0)), r"axis = \(0, 0, 0\); the rotation axis"),
        (dict(rotate_degrees=1.0, about=(1.0,)), r"about = \[1.0\]; give 2 or 3 numbers"),
        (dict(control_displacements={0: ([1], [[0.0, 0.1], [0.0, 0.2]])}),
         r"control_displacements\[0\]: displacements have shape \(2, 2\); expected \(1, s\)"),
        (dict(boundary_points=[]), "boundary_points is empty"),
        (dict(rotate_degrees=1.0, max_boundary_error=-1.0),
         "max_boundary_error = -1.0; must not be negative"),
        (dict(rotate_degrees=1.0, smoothing_iterations=1.5),
         "smoothing_iterations = 1.5; must be an integer"),
    ])
    def test_wrong_arguments_are_named(self, kwargs, message):
        with pytest.raises(ValueError, match=message):
            deform(**kwargs)

    def test_boundary_kinds_or_ranges(self):
        assert list(_boundary_selection(["wall", "OUTER"]).kinds) == [
            grid_pb2.BOUNDARY_KIND_WALL, grid_pb2.BOUNDARY_KIND_OUTER]
        (face,) = _boundary_selection({"block": 2, "face": "k_max", "begin": (0, 1, 4),
                                       "end": (3, 5, 4)}).ranges
        assert (face.block, face.face) == (2, grid_pb2.BLOCK_FACE_K_MAX)
        assert (face.begin.j, face.end.j, face.end.k) == (1, 5, 4)
        assert _boundary_selection(None) == service_pb2.BoundarySelection()
        with pytest.raises(ValueError, match="give boundary kinds or face ranges, not both"):
            _boundary_selection(["wall", (0, "imin", (0, 0), (0, 4))])
        with pytest.raises(ValueError, match=r"boundary\[0\] = 'symmetry'"):
            _boundary_selection("symmetry")
        with pytest.raises(ValueError, match=r"boundary\[1\]: j range \[4, 2\] is not"):
            _boundary_selection([(0, "imin", (0, 0), (0, 4)), (0, "imin", (0, 4), (0, 2))])
        # Bare numbers for begin and end (a trial wrote (0, "jmin", 128, 216)): a ValueError
        # naming them, not a TypeError from inside.
        with pytest.raises(ValueError, match=r"boundary\[0\] begin = 128; give 1 to 3 integers"):
            _boundary_selection((0, "jmin", 128, 216))
        with pytest.raises(ValueError, match=r"boundary\[0\] begin = '128'; give 1 to 3"):
            _boundary_selection((0, "jmin", "128", (216, 0)))
        with pytest.raises(ValueError, match=r"boundary\[0\] end = \(1.5, 0\); give 1 to 3"):
            _boundary_selection((0, "jmin", (1, 0), (1.5, 0)))
        with pytest.raises(ValueError, match=r"boundary\[0\] end = \(inf, 0\); give 1 to 3"):
            _boundary_selection((0, "jmin", (1, 0), (float("inf"), 0)))


class TestGridRequests:
    def test_get_views_blocks_and_step(self):
        basic = _get_request("naca", 2, False, (), None)
        assert (basic.name, basic.revision, basic.view) == ("grids/naca", 2,
                                                            service_pb2.GRID_VIEW_BASIC)
        assert not basic.HasField("step")
        full = _get_request("grids/naca", 0, True, iter([1, 3]), 40)
        assert (full.view, list(full.blocks), full.step) == (service_pb2.GRID_VIEW_FULL,
                                                             [1, 3], 40)
        with pytest.raises(ValueError, match=r"give revision \(2\) or step \(40\), not both"):
            _get_request("naca", 2, False, (), 40)

    def test_watch_after_revision(self):
        assert _watch_request("naca", -1).after_revision == -1
        assert _watch_request("grids/naca", 7).name == "grids/naca"
        with pytest.raises(ValueError, match="after_revision = -2; must be >= -1"):
            _watch_request("naca", -2)
        with pytest.raises(ValueError, match="after_revision = True; must be an integer"):
            _watch_request("naca", True)
