"""laws/clearance.py and every place the clearance law is evaluated (MODEL.md sec. 0, 5.2).

Each place is checked on its own against the law written out below (force, contact
force, contact state), its tangent against a central difference of its own force, and
its force against a central difference of its own potential where it has one: a
mistake in any one place fails that place's cases. The points stay away from the kinks.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Joint
from clearjoint.exact import kernel as kn
from clearjoint.harmonic import aft, modes, monodromy, system
from clearjoint.laws import clearance
from clearjoint.structure.builders import chain
from clearjoint.structure.motion import _Flow
from helpers import check_tangent_stiffness

Array = np.ndarray
Fn = Callable[[Array], Array]


# ---- the law, written out here ----------------------------------------------------------


def written_force(law: ClearanceJoint, delta: Array) -> Array:
    """MODEL.md sec. 0, case by case."""
    k0, k_c, k_t = law.gap_stiffness, law.compression_stiffness, law.tension_stiffness
    g_c, g_t = law.compression_gap, law.tension_gap
    return np.array(
        [
            k0 * d + k_c * (d - g_c)
            if d > g_c
            else k0 * d + k_t * (d + g_t)
            if d < -g_t
            else k0 * d
            for d in np.ravel(delta)
        ]
    ).reshape(np.shape(delta))


def written_contact_force(law: ClearanceJoint, delta: Array) -> Array:
    """The pin's normal force: the contact spring's share, as a magnitude."""
    return np.abs(written_force(law, delta) - law.gap_stiffness * np.asarray(delta))


def written_state(law: ClearanceJoint, delta: float, rate: float) -> int:
    """1 in compression contact, -1 in tension, 0 open; an edge goes the way the rate points."""
    if delta > law.compression_gap or (delta == law.compression_gap and rate > 0.0):
        return 1
    if delta < -law.tension_gap or (delta == -law.tension_gap and rate < 0.0):
        return -1
    return 0


def _laws() -> list[ClearanceJoint]:
    """Grid: k0 = 0 and > 0, symmetric and not, centred and offset gaps, no gap, in series."""
    laws = [
        ClearanceJoint(1e-4, k_c, k_t, gap_stiffness=k0, gap_offset=offset)
        for k0, (k_c, k_t), offset in itertools.product(
            (0.0, 3e5), ((8e7, 8e7), (8e7, 2.5e7)), (0.0, 3e-5, -4.5e-5)
        )
    ]
    laws.append(ClearanceJoint(0.0, 6e7, 9e7, gap_stiffness=1e6))
    laws.append(ClearanceJoint(1e-4, 8e7, 4e7, gap_stiffness=2e5, gap_offset=2e-5).in_series(5e7))
    return laws


LAWS = _laws()


def _points(law: ClearanceJoint, step: float) -> Array:
    """Points over both contacts and the gap, at least 4 steps from either kink."""
    span = 3.0 * max(law.clearance, 1e-4)
    grid = np.linspace(-span, span, 241)
    far = (np.abs(grid - law.compression_gap) > 4 * step) & (
        np.abs(grid + law.tension_gap) > 4 * step
    )
    return grid[far]


# ---- the places ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Place:
    """One place the law is evaluated: its force, and its tangent and potential if it has them."""

    force: Fn
    tangent: Fn | None = None
    potential: Fn | None = None


def _scalar(function: Callable[..., float], law: ClearanceJoint) -> Fn:
    args = (
        law.gap_stiffness,
        law.compression_stiffness,
        law.tension_stiffness,
        law.compression_gap,
        law.tension_gap,
    )
    return lambda delta: np.array([function(float(d), *args) for d in np.ravel(delta)]).reshape(
        np.shape(delta)
    )


def _columns(function: Callable[..., tuple[Array, Array]], which: int, law: ClearanceJoint) -> Fn:
    def evaluate(delta: Array) -> Array:
        column = np.ascontiguousarray(np.reshape(delta, (-1, 1)), dtype=np.float64)
        return function(column, *clearance.parameters((law,)))[which].reshape(np.shape(delta))

    return evaluate


def laws_scalar(law: ClearanceJoint) -> Place:
    return Place(
        _scalar(clearance.force, law),
        _scalar(clearance.tangent, law),
        _scalar(clearance.potential, law),
    )


def laws_scalar_pair(law: ClearanceJoint) -> Place:
    def pair(which: int) -> Fn:
        return _scalar(lambda *a: clearance.force_and_tangent(*a)[which], law)

    return Place(pair(0), pair(1))


def laws_arrays(law: ClearanceJoint) -> Place:
    def energy(delta: Array) -> Array:
        column = np.ascontiguousarray(np.reshape(delta, (-1, 1)), dtype=np.float64)
        return clearance.potentials(column, *clearance.parameters((law,))).reshape(np.shape(delta))

    return Place(
        _columns(clearance.forces_and_tangents, 0, law),
        _columns(clearance.forces_and_tangents, 1, law),
        energy,
    )


def laws_state_law(law: ClearanceJoint) -> Place:
    """f = K delta - offset with (K, offset) of the state clearance.contact_state gives."""
    k0, k_c, k_t, g_c, g_t = (float(a[0]) for a in clearance.parameters((law,)))

    def pick(delta: float) -> tuple[float, float]:
        state = clearance.contact_state(delta, 0.0, g_c, g_t)
        return clearance.state_law(state, k0, k_c, k_t, g_c, g_t)

    return _per_state(pick)


def laws_state_tables(law: ClearanceJoint) -> Place:
    stiffness, offset = clearance.state_tables(*clearance.parameters((law,)))
    _, _, _, g_c, g_t = clearance.parameters((law,))

    def pick(delta: float) -> tuple[float, float]:
        state = clearance.contact_states(np.array([delta]), np.zeros(1), g_c, g_t)[0] + 1
        return stiffness[0, state], offset[0, state]

    return _per_state(pick)


def _per_state(pick: Callable[[float], tuple[float, float]]) -> Place:
    def force(delta: Array) -> Array:
        values = [k * d - offset for d in np.ravel(delta) for k, offset in [pick(float(d))]]
        return np.array(values).reshape(np.shape(delta))

    def tangent(delta: Array) -> Array:
        return np.array([pick(float(d))[0] for d in np.ravel(delta)]).reshape(np.shape(delta))

    return Place(force, tangent)


def clearance_joint(law: ClearanceJoint) -> Place:
    return Place(law.force, law.tangent_stiffness, law.potential_energy)


def _joint(law: ClearanceJoint) -> Joint:
    return Joint(
        2.0,
        law.clearance,
        law.compression_stiffness,
        law.tension_stiffness,
        law.gap_stiffness,
        law.gap_offset,
    )


def joint(law: ClearanceJoint) -> Place:
    j = _joint(law)
    return Place(j.restoring_force, None, j.potential_energy)


def _linear_system(law: ClearanceJoint, structure: bool) -> system.LinearSystem:
    if structure:
        return system.from_structure(chain([2.0], [math.inf], [law]))
    return system.from_joint(_joint(law), None)


def _harmonic(law: ClearanceJoint, structure: bool) -> Place:
    model = _linear_system(law, structure)
    b = float(model.directions[0, 0])

    def pair(which: int) -> Fn:
        def evaluate(delta: Array) -> Array:
            column = np.reshape(np.asarray(delta, dtype=np.float64), (-1, 1))
            return model.joint_forces(column)[which].reshape(np.shape(delta))

        return evaluate

    def energy(delta: Array) -> Array:
        u = np.reshape(np.asarray(delta, dtype=np.float64), (-1, 1)) / b
        return modes.potential_energy(model, u).reshape(np.shape(delta))

    return Place(pair(0), pair(1), energy)


def harmonic_joint(law: ClearanceJoint) -> Place:
    """LinearSystem.joint_forces and harmonic.modes.potential_energy of a Joint."""
    return _harmonic(law, structure=False)


def harmonic_structure(law: ClearanceJoint) -> Place:
    """The same of a one-link chain (its law taken through the Structure)."""
    return _harmonic(law, structure=True)


def aft_one_dof(law: ClearanceJoint) -> Place:
    """aft._evaluate_one_dof's own law loop: with identity DFTs and no linear part R = f."""
    model = _linear_system(law, structure=False)

    def pair(which: int) -> Fn:
        def evaluate(delta: Array) -> Array:
            q = np.ravel(np.asarray(delta, dtype=np.float64)).copy()
            n = q.size
            eye = np.eye(n)
            zero = np.zeros(n)
            residual, _, _, kt = aft._evaluate_one_dof(
                q,
                1.0,
                0.0,
                0.0,
                0.0,
                0.0,
                model.directions[:, 0].copy(),
                model.k0,
                model.k_c,
                model.k_t,
                model.g_c,
                model.g_t,
                eye,
                eye,
                np.zeros((n, n)),
                zero,
                np.zeros((1, n)),
                np.zeros((1, n * n)),
            )
            return (residual if which == 0 else kt[:, 0]).reshape(np.shape(delta))

        return evaluate

    return Place(pair(0), pair(1))


def _kernel_parameters(law: ClearanceJoint) -> Array:
    p = np.zeros(kn.N_PARAMS)
    p[kn.P_MASS] = 2.0
    p[kn.P_K0] = law.gap_stiffness
    p[kn.P_KC] = law.compression_stiffness
    p[kn.P_KT] = law.tension_stiffness
    p[kn.P_GC] = law.compression_gap
    p[kn.P_GT] = law.tension_gap
    return p


def kernel(law: ClearanceJoint) -> Place:
    """The single-joint kernel: region_of, then region_force's (K, Fc), f = K x - Fc."""
    p = _kernel_parameters(law)
    return _per_state(lambda x: kn.region_force(p, kn.region_of(p, x, 0.0)))


def structure_pattern(law: ClearanceJoint) -> Place:
    """Structure.pattern_stiffness (structure.model) of a one-link chain: f = K_s u - r_s."""
    s = chain([2.0], [math.inf], [law])
    b = s.joint_directions[0]

    def pick(delta: float) -> tuple[float, float]:
        k_s, r_s = s.pattern_stiffness([written_state(law, delta, 0.0)])
        return float(b @ k_s @ b) / float(b @ b) ** 2, float(b @ r_s) / float(b @ b)

    return _per_state(pick)


def structure_motion(law: ClearanceJoint) -> Place:
    """structure.motion's flow: states_at, then its k_table and r_table."""
    flow = _Flow(chain([2.0], [math.inf], [law]), np.zeros(1), 1.0)

    def pick(delta: float) -> tuple[float, float]:
        state = int(flow.states_at(np.array([delta]), np.zeros(1))[0]) + 1
        return float(flow.k_table[0, state]), float(flow.r_table[0, state])

    return _per_state(pick)


PLACES = [
    laws_scalar,
    laws_scalar_pair,
    laws_arrays,
    laws_state_law,
    laws_state_tables,
    clearance_joint,
    joint,
    harmonic_joint,
    harmonic_structure,
    aft_one_dof,
    kernel,
    structure_pattern,
    structure_motion,
]

CASES = [
    pytest.param(place, law, id=f"{place.__name__}-{n}")
    for place in PLACES
    for n, law in enumerate(LAWS)
]


@pytest.mark.parametrize(("make", "law"), CASES)
def test_every_place_gives_the_written_law_its_tangent_and_its_potential(
    make: Callable[[ClearanceJoint], Place], law: ClearanceJoint
) -> None:
    step = 1e-3 * max(law.clearance, 1e-4)
    points = _points(law, step)
    place = make(law)
    expected = written_force(law, points)
    scale = float(np.max(np.abs(expected)))
    np.testing.assert_allclose(place.force(points), expected, rtol=0.0, atol=1e-12 * scale)
    if place.tangent is not None:
        check_tangent_stiffness(place.force, place.tangent, points, step=step)
    if place.potential is not None:
        check_tangent_stiffness(place.potential, place.force, points, step=step)


CONTACT_FORCES = {
    "laws.contact_force": lambda law: _scalar(
        lambda d, k0, k_c, k_t, g_c, g_t: clearance.contact_force(d, k_c, k_t, g_c, g_t), law
    ),
    "laws.contact_forces": lambda law: (
        lambda delta: clearance.contact_forces(
            np.reshape(delta, (-1, 1)).copy(), *clearance.parameters((law,))[1:]
        ).reshape(np.shape(delta))
    ),
    "ClearanceJoint.contact_force": lambda law: law.contact_force,
}


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("name", list(CONTACT_FORCES))
def test_the_pins_normal_force_is_the_contact_springs_share(name: str, law: ClearanceJoint) -> None:
    points = _points(law, 1e-3 * max(law.clearance, 1e-4))
    points = np.concatenate((points, [law.compression_gap, -law.tension_gap]))
    expected = written_contact_force(law, points)
    scale = float(np.max(expected))
    np.testing.assert_allclose(
        CONTACT_FORCES[name](law)(points), expected, rtol=0.0, atol=1e-12 * scale
    )


def _state_places(law: ClearanceJoint) -> dict[str, Callable[[float, float], int]]:
    _, _, _, g_c, g_t = clearance.parameters((law,))
    p = _kernel_parameters(law)
    flow = _Flow(chain([2.0], [math.inf], [law]), np.zeros(1), 1.0)
    return {
        "laws.contact_state": lambda d, r: clearance.contact_state(d, r, g_c[0], g_t[0]),
        "laws.contact_states": lambda d, r: int(
            clearance.contact_states(np.array([d]), np.array([r]), g_c, g_t)[0]
        ),
        "kernel.region_of": lambda d, r: kn.region_of(p, d, r),
        "structure.motion states_at": lambda d, r: int(
            flow.states_at(np.array([d]), np.array([r]))[0]
        ),
    }


@pytest.mark.parametrize("law", LAWS)
def test_every_contact_state_agrees_with_the_written_one_edges_included(
    law: ClearanceJoint,
) -> None:
    points = list(_points(law, 1e-3 * max(law.clearance, 1e-4)))
    points += [law.compression_gap, -law.tension_gap]
    model = _linear_system(law, structure=False)
    for name, state in _state_places(law).items():
        for delta, rate in itertools.product(points, (-1.0, 0.0, 1.0)):
            assert state(delta, rate) == written_state(law, delta, rate), (name, delta, rate)
    # harmonic.monodromy sorts samples by state without a rate (an edge is open)
    deltas = np.array(points)[:, None]
    np.testing.assert_array_equal(
        monodromy._states(deltas, model)[:, 0],
        [written_state(law, d, 0.0) for d in points],
    )


def test_the_states_are_defined_once() -> None:
    from clearjoint.exact import march
    from clearjoint.structure import model

    assert (clearance.OPEN, clearance.COMPRESSION, clearance.TENSION) == (0, 1, -1)
    for module in (kn, model, march):
        names = ("FREE" if module is kn else "OPEN", "COMPRESSION", "TENSION")
        assert tuple(getattr(module, name) for name in names) == (0, 1, -1)
