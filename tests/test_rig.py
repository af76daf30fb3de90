"""rig.py: campaigns, reproducibility, the records' energy balance, the manifest's truth."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from clearjoint.cli import main
from clearjoint.errors import OutputExistsError
from clearjoint.records import read_record
from clearjoint.rig import (
    MANIFEST_COLUMNS,
    CampaignError,
    load_campaign,
    run_campaign,
    structure_under_test,
)

SMALL = """
seed = 7
periods = 12
[grid]
frequencies = ["40Hz"]
force_amplitudes = ["1200N", "2500N"]
[[structures]]
name = "joint-1"
clearance = "0.106mm"
[[structures]]
name = "beam"
jointed = false
"""


def small(tmp_path: Path, text: str = SMALL) -> Path:
    path = tmp_path / "campaign.toml"
    path.write_text(text)
    return path


def manifest_rows(folder: Path) -> list[dict[str, str]]:
    with (folder / "manifest.csv").open() as handle:
        return list(csv.DictReader(handle))


def test_default_campaign_is_the_papers_two_joints_and_the_beam() -> None:
    campaign = load_campaign()
    names = [s.name for s in campaign.structures]
    assert names == ["joint-1", "joint-2", "beam"]
    assert [s.clearance for s in campaign.structures[:2]] == pytest.approx([0.106e-3, 0.196e-3])
    assert len(campaign.tests) == 3 * len(campaign.frequencies) * len(campaign.force_amplitudes)
    assert campaign.rig.youngs_modulus == pytest.approx(2.06e11)
    # the paper measured the tension stiffness lower than the compression one
    spec = campaign.tests[0]
    joint, pin, k_beam = structure_under_test(campaign.rig, spec)
    assert joint.tension_stiffness < joint.compression_stiffness
    assert 1 / joint.compression_stiffness == pytest.approx(
        1 / k_beam + 1 / campaign.rig.joint_compression_stiffness
    )
    assert pin is not None


def test_run_writes_records_and_the_manifest_and_is_reproducible(tmp_path: Path) -> None:
    campaign = load_campaign(small(tmp_path))
    one = run_campaign(campaign, tmp_path / "one", jobs=1)
    two = run_campaign(campaign, tmp_path / "two", jobs=2)
    rows = manifest_rows(one.parent)
    assert tuple(rows[0]) == MANIFEST_COLUMNS
    assert len(rows) == 4
    for row in rows:
        a = (one.parent / row["file"]).read_bytes()
        b = (two.parent / row["file"]).read_bytes()
        ra, rb = read_record(one.parent / row["file"]), read_record(two.parent / row["file"])
        np.testing.assert_array_equal(ra.displacement, rb.displacement)  # bit for bit
        np.testing.assert_array_equal(ra.force, rb.force)
        assert len(a) == len(b)
    assert one.read_text() == two.read_text()
    other = load_campaign(small(tmp_path, SMALL.replace("seed = 7", "seed = 8")))
    run_campaign(other, tmp_path / "three", jobs=1)
    r1 = read_record(one.parent / rows[0]["file"])
    r3 = read_record(tmp_path / "three" / rows[0]["file"])
    assert not np.array_equal(r1.displacement, r3.displacement)  # the seed matters


def test_records_obey_the_simulators_energy_balance(tmp_path: Path) -> None:
    manifest = run_campaign(load_campaign(small(tmp_path)), tmp_path / "out", jobs=1)
    for row in manifest_rows(manifest.parent):
        r = read_record(manifest.parent / row["file"])
        n = round(r.sampling_rate / r.frequency_hz)
        last = slice(r.time.size - 5 * n, r.time.size)
        # the work of the measured force over the measured motion, per cycle
        loop = float(np.trapezoid(r.force[last], r.displacement[last])) / 5
        truth = float(row["energy_per_cycle_j"])
        tolerance = 0.01 if row["structure"] != "beam" else 0.05
        assert loop == pytest.approx(truth, rel=tolerance), row["file"]


def test_jointed_records_show_the_four_stages(tmp_path: Path) -> None:
    manifest = run_campaign(load_campaign(small(tmp_path)), tmp_path / "out", jobs=1)
    row = manifest_rows(manifest.parent)[0]
    r = read_record(manifest.parent / row["file"])
    c = float(row["clearance_m"])
    n = round(r.sampling_rate / r.frequency_hz)
    for k in range(r.time.size // n - 4, r.time.size // n):
        cycle = r.displacement[k * n : (k + 1) * n]
        assert cycle.max() > c / 2
        assert cycle.min() < -c / 2
    assert r.control == "force"
    assert r.mass == pytest.approx(1.5)
    assert r.acceleration is not None
    # the manifest's truth is the joint the simulator saw
    assert float(row["compression_stiffness_n_per_m"]) > float(row["tension_stiffness_n_per_m"])
    assert int(row["period_multiple"]) == 1


def test_never_overwrites_and_cli_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = small(tmp_path)
    out = tmp_path / "out"
    assert main(["rig", str(path), "--out", str(out), "--jobs", "1", "--quiet"]) == 0
    assert "wrote 4 records" in capsys.readouterr().out
    before = (out / "manifest.csv").read_bytes()
    with pytest.raises(OutputExistsError):
        run_campaign(load_campaign(path), out, jobs=1)
    assert main(["rig", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "will not overwrite" in err
    assert len(err.strip().splitlines()) == 1
    assert (out / "manifest.csv").read_bytes() == before


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[rig]\nmas = 3\n", "unknown key 'rig.mas'"),
        ('[rig.sensors]\nsampling_rate = "12kN"\n', "is not a frequency"),
        ("[grid]\nfrequencies = []\n", "must be non-empty"),
        ('format = "xlsx"\n', "format must be"),
        ('[[structures]]\nname = "j"\n', "needs a clearance"),
        ("this is = = not toml", "not valid TOML"),
        ("[rig]\nmass = 1.5\n", 'rig.mass = 1.5: give a unit, e.g. "1.5kg"'),
        ('[grid]\nfrequencies = ["20rad"]\n', "is not a frequency"),
        ("\n", "empty file"),
    ],
)
def test_bad_campaigns(tmp_path: Path, text: str, words: str) -> None:
    with pytest.raises(CampaignError) as info:
        load_campaign(small(tmp_path, text))
    assert words in str(info.value)


def test_a_bare_number_is_refused_without_pointing_to_a_unit_key(tmp_path: Path) -> None:
    """A campaign takes no rig.mass_kg: the hint is the unit alone."""
    with pytest.raises(CampaignError) as info:
        load_campaign(small(tmp_path, "[rig]\nmass = 1.5\n"))
    assert str(info.value).endswith('rig.mass = 1.5: give a unit, e.g. "1.5kg"')


def test_missing_campaign(tmp_path: Path) -> None:
    with pytest.raises(CampaignError, match="no such campaign file"):
        load_campaign(tmp_path / "none.toml")


def test_campaign_frequencies_keep_their_two_pi(tmp_path: Path) -> None:
    campaign = load_campaign(small(tmp_path, '[grid]\nfrequencies = ["125.66rad/s", "600rpm"]\n'))
    assert campaign.frequencies == pytest.approx((125.66 / (2 * math.pi), 10.0), rel=1e-12)


def test_beam_stiffness_varies_mildly_with_frequency_and_amplitude() -> None:
    rig = load_campaign().rig
    k = rig.beam_stiffness
    assert k == pytest.approx(2.06e11 * 20e-3 * 10e-3 / 0.6)
    assert rig.beam_stiffness_at(100.0, 0.0) == pytest.approx(k * 1.03)
    assert 1.0 < rig.beam_stiffness_at(20.0, 3000.0) / k < 1.05
    assert math.isfinite(rig.beam_stiffness_at(0.0, 0.0))


def test_jobs_must_be_positive_and_default_to_every_core(tmp_path: Path) -> None:
    from clearjoint.errors import ParameterError

    campaign = load_campaign(small(tmp_path))
    with pytest.raises(ParameterError, match="jobs must be >= 1"):
        run_campaign(campaign, tmp_path / "zero", jobs=0)
    assert not (tmp_path / "zero").exists()
    manifest = run_campaign(campaign, tmp_path / "default")  # every core
    assert len(manifest_rows(manifest.parent)) == 4
