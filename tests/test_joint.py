"""Joint: validation at construction and the restoring force of MODEL.md sec. 0."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from clearjoint import Joint, ParameterError, ParameterTypeError


def make(**changes: object) -> Joint:
    values: dict[str, object] = {"mass": 2.0, "clearance": 1e-4, "compression_stiffness": 8e7}
    values.update(changes)
    return Joint(**values)  # type: ignore[arg-type]


def test_defaults_are_symmetric_centred_and_without_gap_spring() -> None:
    joint = make()
    assert joint.tension_stiffness == joint.compression_stiffness
    assert joint.gap_stiffness == 0.0
    assert joint.compression_gap == joint.tension_gap == pytest.approx(5e-5)


def test_is_frozen() -> None:
    joint = make()
    with pytest.raises(dataclasses.FrozenInstanceError):
        joint.mass = 3.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("mass", 0.0, "mass must be > 0"),
        ("mass", -1.0, "mass must be > 0"),
        ("mass", math.nan, "mass must be finite"),
        ("clearance", -1e-6, "clearance must be >= 0"),
        ("clearance", math.inf, "clearance must be finite"),
        ("compression_stiffness", 0.0, "compression_stiffness must be > 0"),
        ("tension_stiffness", -5.0, "tension_stiffness must be > 0"),
        ("gap_stiffness", -1.0, "gap_stiffness must be >= 0"),
        ("gap_stiffness", math.nan, "gap_stiffness must be finite"),
        ("gap_offset", 6e-5, "gap_offset must lie within the clearance"),
        ("gap_offset", -6e-5, "gap_offset must lie within the clearance"),
    ],
)
def test_invalid_values_name_the_field(field: str, value: float, words: str) -> None:
    with pytest.raises(ParameterError, match=words):
        make(**{field: value})


@pytest.mark.parametrize("value", [None, True, [1.0]])
def test_wrong_types_are_type_errors(value: object) -> None:
    with pytest.raises(ParameterTypeError, match="mass must be a real number"):
        make(mass=value)


def test_text_without_a_unit_is_refused() -> None:
    with pytest.raises(ParameterError, match=r"mass 1: give a unit, e\.g\. 1kg"):
        make(mass="1")


def test_errors_are_value_errors_for_generic_handlers() -> None:
    with pytest.raises(ValueError, match="clearance"):
        make(clearance=-1.0)


def test_offset_at_the_edge_of_the_clearance_is_allowed() -> None:
    joint = make(gap_offset=5e-5)
    assert joint.tension_gap == 0.0
    assert joint.compression_gap == pytest.approx(1e-4)


def test_restoring_force_by_stage() -> None:
    joint = make(tension_stiffness=3e7, gap_stiffness=1e5, gap_offset=1e-5)
    g_c, g_t = 6e-5, 4e-5
    x = np.array([-1e-4, -g_t, 0.0, 2e-5, g_c, 2e-4])
    expected = [
        1e5 * -1e-4 + 3e7 * (-1e-4 + g_t),
        1e5 * -g_t,
        0.0,
        1e5 * 2e-5,
        1e5 * g_c,
        1e5 * 2e-4 + 8e7 * (2e-4 - g_c),
    ]
    np.testing.assert_allclose(joint.restoring_force(x), expected, rtol=1e-12, atol=1e-12)


def test_potential_is_the_integral_of_the_force() -> None:
    from scipy.integrate import quad

    joint = make(tension_stiffness=3e7, gap_stiffness=1e5, gap_offset=-2e-5)
    for x in (-3e-4, -1e-5, 4e-5, 2.5e-4):
        numeric, _ = quad(lambda s: float(joint.restoring_force(s)), 0.0, x, points=[-7e-5, 3e-5])
        assert float(joint.potential_energy(x)) == pytest.approx(numeric, rel=1e-10)


def test_large_amplitude_stiffness_is_the_bilinear_oscillators() -> None:
    joint = make(tension_stiffness=2e7, gap_stiffness=1e6)
    big_c, big_t = 8.1e7, 2.1e7
    period = math.pi * math.sqrt(2.0 / big_c) + math.pi * math.sqrt(2.0 / big_t)
    assert joint.large_amplitude_stiffness == pytest.approx(2.0 * (2 * math.pi / period) ** 2)


# ---- the massless element and the Losses value ------------------------------------------

from clearjoint import ClearanceJoint, Friction, Losses  # noqa: E402
from helpers import check_tangent_stiffness  # noqa: E402


def _element() -> ClearanceJoint:
    return ClearanceJoint(1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)


def test_clearance_joint_force_matches_the_piecewise_law_by_hand() -> None:
    el = _element()
    g_c, g_t = 0.5e-4 + 2e-5, 0.5e-4 - 2e-5
    delta = np.array([[-2e-4, 0.0], [1e-4, 3e-4]])  # shape (N_t, n) as an element sees
    expected = np.where(
        delta > g_c,
        1e6 * delta + 8e7 * (delta - g_c),
        np.where(delta < -g_t, 1e6 * delta + 3e7 * (delta + g_t), 1e6 * delta),
    )
    np.testing.assert_allclose(el.force(delta), expected, rtol=1e-15)
    assert el.force(delta).shape == (2, 2)


def test_clearance_joint_tangent_stiffness_matches_finite_differences() -> None:
    el = _element()
    points = np.array([[-3e-4, -1e-4, -2e-5], [0.0, 4e-5, 2e-4]])
    check_tangent_stiffness(el.force, el.tangent_stiffness, points, step=1e-9)
    series = el.in_series(5e7)
    check_tangent_stiffness(series.force, series.tangent_stiffness, points, step=1e-9)


def test_clearance_joint_in_series_is_the_spring_and_joint_solved_together() -> None:
    # independent route: for a total elongation delta, solve s + f_J(s)/k_m = delta for the
    # joint's own displacement s by bisection; the member force is f_J(s)
    el, k_m = _element(), 5e7
    series = el.in_series(k_m)
    for delta in np.linspace(-4e-4, 4e-4, 41):
        lo, hi = -1e-2, 1e-2
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid + float(el.force(mid)) / k_m > delta:
                hi = mid
            else:
                lo = mid
        assert float(series.force(delta)) == pytest.approx(float(el.force(lo)), rel=1e-9, abs=1e-9)


def test_clearance_joint_validates_as_joint_does() -> None:
    with pytest.raises(ParameterError, match="clearance must be >= 0"):
        ClearanceJoint(-1e-4, 1e7)
    with pytest.raises(ParameterError, match="gap_offset must lie within"):
        ClearanceJoint(1e-4, 1e7, gap_offset=1e-4)
    with pytest.raises(ParameterError, match="restitution"):
        ClearanceJoint(1e-4, 1e7, restitution=1.5)
    with pytest.raises(ParameterError, match=r"restitution 0\.5 on a joint in series"):
        ClearanceJoint(1e-4, 1e7, restitution=0.5).in_series(1e8)
    assert ClearanceJoint(1e-4, 1e7, restitution=0.5).in_series(math.inf).restitution == 0.5


def test_joint_is_a_mass_on_its_element() -> None:
    joint = Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)
    x = np.linspace(-3e-4, 3e-4, 13)
    np.testing.assert_array_equal(joint.restoring_force(x), _element().force(x))
    assert joint.element == _element()


def test_element_is_built_once_and_is_not_part_of_the_value() -> None:
    import pickle

    joint = Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)
    assert joint.element is joint.element  # one element, not a new one per call
    # the gap edges g_c = c/2 + d, g_t = c/2 - d are the element's, bit for bit
    assert (
        (joint.compression_gap, joint.tension_gap)
        == (0.5e-4 + 2e-5, 0.5e-4 - 2e-5)
        == (
            joint.element.compression_gap,
            joint.element.tension_gap,
        )
    )
    twin = Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)
    assert twin == joint
    assert hash(twin) == hash(joint)
    assert twin.element is not joint.element
    assert "element" not in repr(joint)
    moved = dataclasses.replace(joint, clearance=2e-4)
    assert moved.element.clearance == 2e-4
    assert moved.compression_gap == 1e-4 + 2e-5
    copy = pickle.loads(pickle.dumps(joint))
    assert copy == joint
    assert copy.element == joint.element
    with pytest.raises(dataclasses.FrozenInstanceError):
        joint.element = _element()  # type: ignore[misc]


def test_losses_are_the_one_carrier_and_the_old_keywords_name_the_fix() -> None:
    from clearjoint.simulate import time_response

    joint = Joint(2.0, 1e-4, 8e7)
    losses = Losses(damping_ratio=0.02, friction=Friction(0.1, 50.0), restitution=0.8)
    moved = time_response(joint, 300.0, 5000.0, 0.01, losses=losses)
    assert moved.energy.impact > 0.0
    assert moved.energy.sliding_friction > 0.0
    assert moved.energy.viscous > 0.0
    with pytest.raises(ParameterTypeError, match=r"write losses=Losses\(damping_ratio=0.02\)"):
        time_response(joint, 300.0, 5000.0, 0.01, damping_ratio=0.02)  # type: ignore[call-arg]
    with pytest.raises(ParameterTypeError, match=r"losses must be a clearjoint\.Losses"):
        time_response(joint, 300.0, 5000.0, 0.01, losses=0.02)  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="damping_ratio must be >= 0"):
        Losses(damping_ratio=-1.0)
