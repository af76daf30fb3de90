"""Structure study TOML and `clearjoint structure`: units, outputs, one-line errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
import xarray as xr

from clearjoint.cli import main
from clearjoint.structure.study import StructureStudyError, load_structure_study

CHAIN = """
[structure]
kind = "chain"
masses = ["2kg", "1.5kg"]
stiffnesses = ["inf", "6e7N/m"]
dampers = ["50N*s/m", "30N s/m"]
joints = [true, false]

[joint]
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
gap_stiffness = "1e6N/m"

[excitation]
frequency = "600Hz"
force_dof = "n2x"
force_amplitude = "500N"
periods = 4

[decay]
dof = "n2x"
initial_amplitude = "0.5mm"
duration = "20ms"
"""


def _write(tmp_path: Path, text: str = CHAIN) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(text)
    return path


def test_study_reads_units_into_si(tmp_path: Path) -> None:
    study = load_structure_study(_write(tmp_path))
    assert study.omega == pytest.approx(2 * math.pi * 600.0)
    assert study.force is not None
    assert study.force.tolist() == [0.0, 500.0]
    law = study.structure.joint_laws[0]
    assert law.clearance == pytest.approx(1e-4)
    assert study.decay_initial is not None
    assert study.decay_initial[1] == pytest.approx(5e-4)


@pytest.mark.parametrize("task", ["modes", "respond", "decay"])
def test_cli_writes_netcdf_and_json(
    tmp_path: Path, task: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / f"{task}.nc"
    code = main(["structure", str(_write(tmp_path)), task, "--out", str(out), "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert "structure" in summary
    with xr.open_dataset(out, engine="h5netcdf") as data:
        assert len(data.data_vars) > 0
    if task == "respond":
        assert summary["balance_error"] < 1e-9
    assert main(["structure", str(_write(tmp_path)), task, "--out", str(out)]) == 2  # no overwrite


def test_cli_decay_text_says_n_a_for_the_last_cycle_without_a_damping_ratio(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "decay.nc"
    assert main(["structure", str(_write(tmp_path)), "decay", "--out", str(out)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("damping_ratio"))
    assert "None" not in line
    assert line.endswith("'n/a']")


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('force_dof = "n2x"', 'force_dof = "n9x"'), "names DOF 'n9x', which does not exist"),
        (('kind = "chain"', 'kind = "tower"'), "kind must be 'mast', 'chain' or 'truss'"),
        (('clearance = "0.1mm"', 'clearance = "0.1N"'), "clearance"),
        (
            ('dampers = ["50N*s/m", "30N s/m"]', 'dampers = ["50N*s/m"]'),
            "dampers must have one entry per link",
        ),
        (('clearance = "0.1mm"', "clearance = 0.1"), 'clearance = 0.1: give a unit, e.g. "0.1mm"'),
        (('"2kg", "1.5kg"', '2.0, "1.5kg"'), "masses = 2.0: give a unit"),
        (
            ('"50N*s/m", "30N s/m"', '50.0, "30N s/m"'),
            'dampers = 50.0: give a unit, e.g. "50.0N*s/m"',
        ),
        (('dampers = ["50N*s/m", "30N s/m"]', 'dampers = ["50N", "30N"]'), "is not a damping"),
        (("[decay]", "[decay]\nclearance_m = 1e-4"), "unknown key 'clearance_m' in [decay]"),
        (('frequency = "600Hz"', 'frequency = "0Hz"'), "frequency must be finite and > 0"),
        (("periods = 4", "periods = 0"), "periods must be at least 1, got 0"),
        (('dof = "n2x"\ninitial', 'dof = "n2x"\nmode = 0\ninitial'), "mode must be 1 to 2"),
        (('dof = "n2x"\ninitial', 'dof = "n2x"\nmode = 3\ninitial'), "mode must be 1 to 2"),
        (('initial_amplitude = "0.5mm"', 'initial_amplitude = "0mm"'), "must be finite and not 0"),
        (('duration = "20ms"', 'duration = "0ms"'), "duration must be finite and > 0"),
        (("[decay]", "[decays]"), "unknown section [decays]"),
        (
            ("[decay]", "[output]\nsamples_per_period = 4\n[decay]"),
            "[output] samples_per_period must be at least 8, got 4",
        ),
    ],
)
def test_cli_bad_study_is_one_line_and_exit_2(
    tmp_path: Path, change: tuple[str, str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _write(tmp_path, CHAIN.replace(*change))
    code = main(["structure", str(path), "modes", "--out", str(tmp_path / "x.nc")])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    assert err.count("\n") == 1


def test_study_error_is_a_value_error() -> None:
    assert issubclass(StructureStudyError, ValueError)


def test_truss_study_with_units_and_a_joint(tmp_path: Path) -> None:
    text = """
[structure]
kind = "truss"
nodes = [["0m", "0m"], ["1m", "0m"], ["0m", "1000mm"], ["1m", "1m"]]
members = [[0, 2], [1, 3], [1, 2], [2, 3]]
supports = [0, 1]
member_stiffness = "1e7N/m"
masses = ["0kg", "0kg", "2kg", "2kg"]
joint_members = [0]

[joint]
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
"""
    study = load_structure_study(_write(tmp_path, text))
    s = study.structure
    assert s.n_dof == 4
    assert s.joint_members == (0,)
    assert s.nodes[2].tolist() == [0.0, 1.0]
    # the joint in series with member 0: closed stiffness k k_m / (k + k_m)
    assert s.joint_laws[0].compression_stiffness == pytest.approx(8e7 * 1e7 / 9e7)


def test_keys_that_name_their_si_unit_take_bare_numbers(tmp_path: Path) -> None:
    """masses_kg, dampers_n_s_per_m, clearance_m: the same study as with units."""
    bare = (
        CHAIN.replace('masses = ["2kg", "1.5kg"]', "masses_kg = [2, 1.5]")
        .replace('dampers = ["50N*s/m", "30N s/m"]', "dampers_n_s_per_m = [50, 30]")
        .replace('clearance = "0.1mm"', "clearance_m = 1e-4")
        .replace('frequency = "600Hz"', "frequency_hz = 600")
    )
    assert bare != CHAIN
    a = load_structure_study(_write(tmp_path, CHAIN)).structure
    b = load_structure_study(_write(tmp_path, bare)).structure
    assert b.mass_matrix().diagonal().tolist() == [2.0, 1.5]
    assert b.damping_matrix().tolist() == a.damping_matrix().tolist()
    assert b.joint_laws[0].clearance == pytest.approx(1e-4)
    assert load_structure_study(_write(tmp_path, bare)).omega == pytest.approx(2 * math.pi * 600)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('masses = ["2kg", "1.5kg"]\nmasses_kg = [2, 1.5]', "masses is given twice"),
        ('masses_kg = ["2kg", "1.5kg"]', "the key names its unit, so give a bare number"),
    ],
)
def test_unit_keys_are_checked(tmp_path: Path, text: str, message: str) -> None:
    path = _write(tmp_path, CHAIN.replace('masses = ["2kg", "1.5kg"]', text))
    with pytest.raises(StructureStudyError, match=message):
        load_structure_study(path)


@pytest.mark.parametrize(("make", "message"), [("folder", "is a folder"), ("", "no such")])
def test_study_path_errors_come_from_the_one_toml_reader(
    tmp_path: Path, make: str, message: str
) -> None:
    path = tmp_path / "s.toml"
    if make == "folder":
        path.mkdir()
    with pytest.raises(StructureStudyError, match=message):
        load_structure_study(path)


@pytest.mark.parametrize("task", ["modes", "respond", "decay"])
def test_cli_plot_writes_a_figure(
    tmp_path: Path, task: str, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "figure.png"
    args = ["structure", str(_write(tmp_path)), task, "--out", str(tmp_path / "r.nc")]
    assert main([*args, "--plot", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"and {target}" in capsys.readouterr().out


@pytest.mark.parametrize(("task", "section"), [("respond", "[excitation]"), ("decay", "[decay]")])
def test_cli_missing_section_says_to_put_it_in_the_study_file(
    tmp_path: Path, task: str, section: str, capsys: pytest.CaptureFixture[str]
) -> None:
    text = CHAIN.split("[excitation]")[0] if task == "respond" else CHAIN.split("[decay]")[0]
    out = tmp_path / "r.nc"
    assert main(["structure", str(_write(tmp_path, text)), task, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"needs a{'n' if task == 'respond' else ''} {section} section" in err
    assert "put it in the study file" in err
    assert not out.exists()


# ---- Rayleigh damping read with its true dimensions (alpha in 1/s, beta in s) -------------

TWO_MASS = """
[structure]
kind = "chain"
masses = ["2kg", "1.5kg"]
stiffnesses = ["6e7N/m", "4e7N/m"]
{alpha}
rayleigh_beta = "2e-6s"
"""


@pytest.mark.parametrize(
    "alpha",
    [
        'rayleigh_alpha = "20rad/s"',
        'rayleigh_alpha = "20/s"',
        'rayleigh_alpha = "20 1/s"',
        'rayleigh_alpha = "1200/min"',
        "rayleigh_alpha_per_s = 20",
    ],
)
def test_rayleigh_damping_of_a_two_mass_chain_is_the_textbook_one(
    tmp_path: Path, alpha: str
) -> None:
    """zeta_k = alpha / (2 w_k) + beta w_k / 2 on the chain's closed-form modes.

    w_k^2 are the roots of m1 m2 w^4 - (m1 k2 + m2 (k1 + k2)) w^2 + k1 k2 = 0; the damping
    ratio is read from the eigenvalues of the first-order system, -zeta w +- i w sqrt(1 -
    zeta^2), so neither side uses the structure's own modes.
    """
    import numpy as np

    s = load_structure_study(_write(tmp_path, TWO_MASS.format(alpha=alpha))).structure
    m1, m2, k1, k2, a, b = 2.0, 1.5, 6e7, 4e7, 20.0, 2e-6
    assert s.rayleigh == pytest.approx((a, b), rel=1e-15)
    w2 = np.sort(np.roots([m1 * m2, -(m1 * k2 + m2 * (k1 + k2)), k1 * k2]).real)
    w = np.sqrt(w2)
    textbook = a / (2 * w) + b * w / 2
    m, c = np.diag([m1, m2]), s.damping_matrix()
    k = np.array([[k1 + k2, -k2], [-k2, k2]])
    system = np.block(
        [[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(m, k), -np.linalg.solve(m, c)]]
    )
    poles = np.linalg.eigvals(system)
    poles = poles[poles.imag > 0]
    poles = poles[np.argsort(np.abs(poles))]
    np.testing.assert_allclose(np.abs(poles), w, rtol=1e-9)
    np.testing.assert_allclose(-poles.real / np.abs(poles), textbook, rtol=1e-9)
    assert textbook.min() > 1e-3  # both terms matter: alpha's and beta's


@pytest.mark.parametrize(
    ("alpha", "message"),
    [
        ('rayleigh_alpha = "20Hz"', "ambiguous for a rate in 1/s"),
        ('rayleigh_alpha = "20m"', "is not a rate"),
        ("rayleigh_alpha = 20", 'give a unit, e.g. "20/s", or name the SI unit in the key'),
    ],
)
def test_rayleigh_alpha_refuses_cycles_and_wrong_units(
    tmp_path: Path, alpha: str, message: str
) -> None:
    with pytest.raises(StructureStudyError, match=message.replace("(", r"\(").replace(".", r"\.")):
        load_structure_study(_write(tmp_path, TWO_MASS.format(alpha=alpha)))


# ---- a [joint] that no member carries, a mast without joints ----------------------------

MAST = """
[structure]
kind = "mast"
bays = 2
longeron_rigidity = "2e7N"
node_mass = "0.5kg"

[joint]
clearance = "50um"
compression_stiffness = "5e7N/m"
gap_stiffness = "1e5N/m"
"""


def test_mast_study_with_a_joint_has_joints_whose_opening_lowers_the_modes(
    tmp_path: Path,
) -> None:
    s = load_structure_study(_write(tmp_path, MAST)).structure
    assert len(s.joint_members) == 4  # 2 bays, a hinge in each longeron
    assert s.modes("open").omega[0] < 0.5 * s.modes("closed").omega[0]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (MAST.split("[joint]")[0], "a mast needs a [joint] section"),
        (CHAIN.replace("joints = [true, false]", ""), "[joint] is given but no link carries it"),
        (CHAIN.replace("joints = [true, false]", "joints = [false, false]"), "no link carries"),
    ],
    ids=["mast without [joint]", "chain without joints", "chain with no joint on"],
)
def test_a_study_never_drops_its_joints_silently(
    tmp_path: Path, text: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["structure", str(_write(tmp_path, text)), "modes", "--out", str(tmp_path / "x.nc")]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    assert err.count("\n") == 1


# ---- issue 11's bad input, end to end on the command line --------------------------------

TRUSS = """
[structure]
kind = "truss"
nodes = [["0m", "0m"], ["1m", "0m"], ["0m", "1m"], ["1m", "1m"]]
members = [[0, 2], [1, 3], [1, 2], [2, 3]]
supports = [0, 1]
member_stiffness = "1e7N/m"
masses = ["0kg", "0kg", "2kg", "2kg"]
joint_members = [0]

[joint]
clearance = "0.1mm"
compression_stiffness = "8e7N/m"

[excitation]
frequency = "100Hz"
force_dof = "n3x"
force_amplitude = "10N"
"""


def test_the_truss_of_the_bad_input_cases_is_good(tmp_path: Path) -> None:
    out = tmp_path / "x.nc"
    assert main(["structure", str(_write(tmp_path, TRUSS)), "modes", "--out", str(out)]) == 0


@pytest.mark.parametrize(
    ("change", "message"),
    [
        pytest.param(
            ('["1m", "1m"]]', '["0m", "1000mm"]]'),
            "member 3 (nodes 2-3) has zero length; move its nodes apart",
            id="zero-length member",
        ),
        pytest.param(
            ("[1, 3], [1, 2]", "[1, 7], [1, 2]"),
            "member 1 end names node 7, which does not exist (nodes are 0 to 3)",
            id="unknown node",
        ),
        pytest.param(
            ("supports = [0, 1]", "supports = [0, 5]"),
            "support names node 5, which does not exist (nodes are 0 to 3)",
            id="unknown support",
        ),
        pytest.param(
            ("joint_members = [0]", "joint_members = [0, 6]"),
            "joint_members names member 6, which does not exist (members are 0 to 3)",
            id="unknown joint member",
        ),
        pytest.param(
            ("[2, 3]]", "[2, 3], [0, 1]]", "joint_members = [0]", "joint_members = [4]"),
            "member 4 joins two supports (nodes 0, 1), so a joint there can never move; "
            "remove it or free one of its nodes",
            id="joint on a support",
        ),
        pytest.param(
            ("supports = [0, 1]", "supports = [0]"),
            "node 1 is free but has mass 0.0 kg; give it a mass > 0 or make it a support",
            id="massless free node",
        ),
        pytest.param(
            (
                'supports = [0, 1]\nmember_stiffness = "1e7N/m"\nmasses = ["0kg", "0kg",',
                'supports = [0]\nmember_stiffness = "1e7N/m"\nmasses = ["0kg", "2kg",',
            ),
            "the structure is singular: it can move as a rigid body or mechanism",
            id="singular structure",
        ),
        pytest.param(
            ('force_dof = "n3x"', 'force_dof = "n1x"'),
            "names DOF 'n1x' of node 1, a support (fixed); give a DOF of a free node",
            id="force on a support",
        ),
        pytest.param(
            ('force_dof = "n3x"', 'force_dof = "n3z"'),
            "names DOF 'n3z', which does not exist",
            id="force on a DOF the structure lacks",
        ),
        pytest.param(
            (
                'compression_stiffness = "8e7N/m"',
                'compression_stiffness = "8e7N/m"\nrestitution = 0.8',
            ),
            "restitution 0.8 on a joint in series with a member of stiffness 10000000.0 N/m is "
            "not defined (no mass between them to stop); set restitution=1",
            id="restitution in series with a member",
        ),
        pytest.param(
            (
                'compression_stiffness = "8e7N/m"',
                'compression_stiffness = "8e7N/m"\nfriction_coefficient = 0.2',
            ),
            "[joint] friction_coefficient: Coulomb friction in a structure's joints is not carried",
            id="friction in a structure joint",
        ),
        pytest.param(
            ('member_stiffness = "1e7N/m"', 'member_stiffness = "0N/m"'),
            "member stiffness must be > 0",
            id="member without stiffness",
        ),
    ],
)
def test_bad_structure_is_one_line_naming_the_item_and_the_fix(
    tmp_path: Path, change: tuple[str, ...], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    text = TRUSS
    for old, new in zip(change[::2], change[1::2], strict=True):
        assert old in text
        text = text.replace(old, new)
    path = _write(tmp_path, text)
    out = tmp_path / "x.nc"
    code = main(["structure", str(path), "modes", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    assert err.startswith(f"clearjoint structure: error: {path}: ")
    assert err.count("\n") == 1
    assert "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            CHAIN.replace('kind = "chain"', 'kind = "chain"\nbays = 3'),
            "bays is not read for a chain",
        ),
        (MAST.replace("bays = 2", 'bays = 2\nmasses = ["1kg"]'), "masses is not read for a mast"),
        (
            TRUSS.replace("supports = [0, 1]", 'supports = [0, 1]\nstiffnesses = ["1N/m"]'),
            "stiffnesses is not read for a truss",
        ),
        (
            CHAIN.replace('kind = "chain"', 'kind = "chain"\nmember_damping = "5N*s/m"'),
            "member_damping is not read for a chain; a chain takes masses, stiffnesses, "
            "dampers, joints",
        ),
    ],
    ids=["bays in a chain", "masses in a mast", "stiffnesses in a truss", "damping in a chain"],
)
def test_a_structure_key_of_another_kind_is_refused_not_dropped(
    tmp_path: Path, text: str, message: str
) -> None:
    with pytest.raises(StructureStudyError, match=message):
        load_structure_study(_write(tmp_path, text))


def test_cli_decay_reads_the_backbone_of_the_study_mode(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import numpy as np

    from clearjoint.structure import decay_backbone, free_decay

    path = _write(tmp_path)
    out = tmp_path / "decay.nc"
    assert main(["structure", str(path), "decay", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    study = load_structure_study(path)
    assert study.decay_mode == 1
    assert study.decay_initial is not None
    assert study.decay_duration is not None
    motion = free_decay(
        study.structure,
        (study.decay_initial, np.zeros(2)),
        study.decay_duration,
        samples_per_period=64,
    )
    on_mode = decay_backbone(motion, 1, mode=1).amplitude
    raw = decay_backbone(motion, 1).amplitude
    assert np.allclose(summary["amplitude_m"], on_mode, rtol=1e-12)
    assert not np.allclose(on_mode, raw, rtol=1e-6)  # the projection is not a no-op here
