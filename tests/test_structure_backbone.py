"""decay_backbone: per-cycle frequency and damping against known linear and joint values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Joint
from clearjoint.stiffness import natural_frequency
from clearjoint.structure import StructureError, chain, decay_backbone, free_decay, time_response


def test_linear_decay_gives_its_damped_frequency_and_damping_ratio() -> None:
    m, k, zeta = 2.0, 8e6, 0.03
    c = 2.0 * zeta * math.sqrt(k * m)
    one = chain([m], [k], dampers=[c])
    w_n = math.sqrt(k / m)
    decay = free_decay(one, ([1e-3], [0.0]), 12 * 2 * math.pi / w_n, samples_per_period=128)
    backbone = decay_backbone(decay, 0)
    assert backbone.amplitude.size >= 10
    np.testing.assert_allclose(backbone.omega, w_n * math.sqrt(1 - zeta**2), rtol=1e-6)
    np.testing.assert_allclose(backbone.damping_ratio[:-1], zeta, rtol=1e-5)
    assert np.isnan(backbone.damping_ratio[-1])


def test_undamped_joint_backbone_is_the_papers_amplitude_dependent_frequency() -> None:
    joint = Joint(2.0, 1e-4, 8e7)  # symmetric, k0 = 0: X = A + c/2
    one = chain([2.0], [math.inf], [joint.element])
    x0 = 1e-4 + 0.5e-4  # start at rest 1e-4 m into compression contact
    w_guess = float(natural_frequency(joint, 1e-4))
    decay = free_decay(one, ([x0], [0.0]), 6 * 2 * math.pi / w_guess, samples_per_period=256)
    backbone = decay_backbone(decay, 0)
    np.testing.assert_allclose(backbone.amplitude, 1e-4 + 0.5e-4, rtol=1e-7)
    # peaks are interpolated between samples: 1e-6 at 256 samples a period
    np.testing.assert_allclose(backbone.omega, w_guess, rtol=1e-6)
    np.testing.assert_allclose(backbone.damping_ratio[:-1], 0.0, atol=1e-7)


def test_modal_projection_and_bad_dof() -> None:
    two = chain([1.0, 1.0], [4e6, 4e6], dampers=[20.0, 0.0])
    modes = two.modes()
    u0 = 1e-3 * modes.shapes[:, 0] / np.abs(modes.shapes[:, 0]).max()
    decay = free_decay(two, (u0, np.zeros(2)), 8 * 2 * math.pi / modes.omega[0])
    backbone = decay_backbone(decay, 1, mode=1)
    np.testing.assert_allclose(backbone.omega, modes.omega[0], rtol=2e-3)
    with pytest.raises(StructureError, match="dof must be an index from 0 to 1"):
        decay_backbone(decay, 2)
    with pytest.raises(StructureError, match="mode must be from 1 to 2"):
        decay_backbone(decay, 0, mode=3)


def test_backbone_result_has_short_repr_and_xarray() -> None:
    one = chain([1.0], [math.inf], [ClearanceJoint(1e-4, 1e7, gap_stiffness=1e5)], dampers=[5.0])
    decay = free_decay(one, ([5e-4], [0.0]), 0.2)
    backbone = decay_backbone(decay, 0)
    assert "cycles" in repr(backbone)
    assert backbone.to_xarray()["omega"].attrs["units"] == "rad/s"


def test_a_forced_motion_is_refused_not_read_as_a_decay() -> None:
    """The decrement of a forced response is no damping ratio: refused with the fix."""
    one = chain([2.0], [1e6], dampers=[10.0])
    forced = time_response(one, [1.0], 700.0, 0.1)
    assert forced.energy.input != 0.0
    with pytest.raises(StructureError, match=r"was forced .* use structure.free_decay") as info:
        decay_backbone(forced, 0)
    assert "\n" not in str(info.value)
    # the same call on the free decay of the same structure is read
    free = free_decay(one, ([1e-3], [0.0]), 0.1)
    assert decay_backbone(free, 0).amplitude.size > 5


def test_backbone_to_pandas_is_one_row_per_cycle() -> None:
    from clearjoint.structure import Backbone

    bb = Backbone(
        time=np.array([0.01, 0.02, 0.03]),
        amplitude=np.array([3e-4, 2e-4, 1e-4]),
        omega=np.array([600.0, 620.0, 640.0]),
        damping_ratio=np.array([0.02, 0.03, np.nan]),
        dof=2,
        mode=1,
    )
    table = bb.to_pandas()
    np.testing.assert_array_equal(table.index.to_numpy(), bb.time)
    np.testing.assert_array_equal(table["amplitude_m"].to_numpy(), bb.amplitude)
    np.testing.assert_allclose(table["frequency_hz"].to_numpy(), bb.omega / (2 * math.pi))
    np.testing.assert_array_equal(table["damping_ratio"].to_numpy(), bb.damping_ratio)
    assert bb.to_xarray()["omega"].attrs["units"] == "rad/s"
