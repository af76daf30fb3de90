"""The study layer: values over a study file, the rules that derive a value, the refusals."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from clearjoint.errors import ParameterError
from clearjoint.structure.study import load_structure_study
from clearjoint.studies import (
    checked_samples,
    frequency_response_of,
    joint_at,
    load_study,
    losses_at,
    refuse_harmonic_losses,
    refuse_harmonic_structure,
    run_structure_task,
    study_at,
    write_structure_result,
)

STUDY = """
[joint]
mass = "2kg"
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
{tension}

[excitation]
force_amplitude = "100N"
frequency = "400Hz"

[losses]
{losses}

[pin]
radius = "5mm"
length = "25mm"
{hole}
"""

CHAIN = """
[joint]
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
restitution = 0.5

[structure]
kind = "chain"
joints = [true, false]
masses = ["2kg", "1.5kg"]
stiffnesses = ["inf", "6e7N/m"]

[excitation]
force_dof = "n2x"
force_amplitude = "500N"
frequency = "600Hz"
"""

CLI_NAMES = {"joint.mass": "--mass", "losses.friction_coefficient": "--friction-coefficient",
             "losses.lateral_load": "--lateral-load"}  # fmt: skip


def _study(tmp_path: Path, *, tension: str = "", losses: str = "", hole: str = "") -> Path:
    path = tmp_path / "study.toml"
    path.write_text(STUDY.format(tension=tension, losses=losses, hole=hole), encoding="utf-8")
    return path


def test_values_override_the_file_and_the_rest_stays(tmp_path: Path) -> None:
    study = load_study(_study(tmp_path, losses="damping_ratio = 0.02"))
    merged = study_at(study, {"joint.mass": 3.0, "excitation.frequency": 500.0})
    assert merged.joint.mass == 3.0
    assert merged.joint.clearance == pytest.approx(1e-4)
    assert merged.omega == pytest.approx(2 * math.pi * 500.0)
    assert merged.force_amplitude == pytest.approx(100.0)
    assert merged.damping_ratio == pytest.approx(0.02)


def test_a_default_hole_follows_the_clearance_and_the_pin_radius(tmp_path: Path) -> None:
    """R_h = R_p + c/2 (MODEL.md, under eq 13) when the file leaves the hole out."""
    study = load_study(_study(tmp_path))
    assert study.pin is not None
    assert study.pin.hole_radius == pytest.approx(5e-3 + 0.05e-3, rel=1e-12)
    wider = study_at(study, {"joint.clearance": 0.3e-3})
    assert wider.pin is not None
    assert wider.pin.hole_radius == pytest.approx(5e-3 + 0.15e-3, rel=1e-12)
    bigger = losses_at(study, study.joint, {"pin.radius": 6e-3})
    assert bigger.pin is not None
    assert bigger.pin.hole_radius == pytest.approx(6e-3 + 0.05e-3, rel=1e-12)


def test_a_hole_the_file_gives_is_kept(tmp_path: Path) -> None:
    study = load_study(_study(tmp_path, hole='hole_radius = "5.3mm"'))
    wider = study_at(study, {"joint.clearance": 0.3e-3})
    assert wider.pin is not None
    assert wider.pin.hole_radius == pytest.approx(5.3e-3)


def test_a_symmetric_joint_stays_symmetric_and_a_set_tension_is_kept(tmp_path: Path) -> None:
    """k_t left to its default is k_c (docs/simulate.md), so it follows a new k_c."""
    symmetric = load_study(_study(tmp_path))
    stiffer = joint_at(symmetric.joint, {"joint.compression_stiffness": 1e8})
    assert stiffer.tension_stiffness == 1e8
    own = load_study(_study(tmp_path, tension='tension_stiffness = "5e7N/m"'))
    stiffer = joint_at(own.joint, {"joint.compression_stiffness": 1e8})
    assert stiffer.tension_stiffness == pytest.approx(5e7)


def test_a_joint_without_a_study_needs_its_mass_named_as_the_caller_names_it() -> None:
    with pytest.raises(ParameterError, match="--mass is missing: give --mass"):
        joint_at(None, {"joint.clearance": 1e-4, "joint.compression_stiffness": 8e7}, CLI_NAMES)


def test_one_friction_value_alone_is_one_clear_error(tmp_path: Path) -> None:
    """mu_s without P gives no sliding force (MODEL.md eq 10): refused, naming both."""
    study = load_study(_study(tmp_path))
    with pytest.raises(ParameterError) as caught:
        losses_at(study, study.joint, {"losses.friction_coefficient": 0.2}, CLI_NAMES)
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith("--friction-coefficient needs --lateral-load too")


def test_harmonic_balance_refuses_an_impact_and_free_play_friction(tmp_path: Path) -> None:
    impact = load_study(_study(tmp_path, losses="restitution = 0.8"))
    with pytest.raises(ParameterError, match=r"restitution = 0\.8 is an impact"):
        refuse_harmonic_losses(impact, "frf")
    free_play = load_study(
        _study(
            tmp_path,
            losses='friction_coefficient = 0.2\nlateral_load = "300N"\n'
            'friction_region = "free-play"',
        )
    )
    with pytest.raises(ParameterError, match="friction_region = 'free-play' is not carried"):
        refuse_harmonic_losses(free_play, "modes")
    refuse_harmonic_losses(load_study(_study(tmp_path)), "frf")  # no loss it cannot carry


def test_a_structure_study_with_impacts_is_refused_by_harmonic_balance_not_by_shooting(
    tmp_path: Path,
) -> None:
    path = tmp_path / "chain.toml"
    path.write_text(CHAIN, encoding="utf-8")
    study = load_structure_study(path)
    with pytest.raises(ParameterError, match=r"restitution = 0\.5 is an impact"):
        refuse_harmonic_structure(study, "frf")
    # exact shooting carries the impacts (each one's saltation matrix in its monodromy)
    curve = frequency_response_of(study, 300.0, 350.0, method="shooting", max_points=3)
    assert curve.method == "shooting"
    assert curve.omega.size == 3


def test_a_structure_task_is_written_to_netcdf_as_its_dataset(tmp_path: Path) -> None:
    import xarray as xr

    path = tmp_path / "chain.toml"
    path.write_text(CHAIN, encoding="utf-8")
    result = run_structure_task(load_structure_study(path), "modes")
    out = write_structure_result(result, str(tmp_path / "modes.nc"))
    assert out == tmp_path / "modes.nc"
    with xr.open_dataset(out, engine="h5netcdf") as written:
        xr.testing.assert_identical(written.load(), result.data)


def test_too_few_samples_alias_and_are_refused() -> None:
    """AFT needs at least 2 (2H + 1) samples per period (MODEL.md 5.3)."""
    assert checked_samples(None, 7) is None
    assert checked_samples(30, 7) == 30
    with pytest.raises(ParameterError, match="at least 2 \\(2H \\+ 1\\) = 30"):
        checked_samples(29, 7, {"samples": "--samples", "harmonics": "--harmonics"})


def test_the_identify_command_loads_no_solver() -> None:
    # the study layer's package imports each name on first use: identify's start-up stays
    # free of numba, scipy and the solvers behind the other studies
    script = (
        "import sys, clearjoint.cli, clearjoint.studies.identify\n"
        "print(sorted(m for m in ('numba', 'scipy', 'clearjoint.structure', "
        "'clearjoint.periodic') if m in sys.modules))"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == "[]"
