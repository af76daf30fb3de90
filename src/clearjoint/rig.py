"""The virtual test rig: the paper's experiment in software, writing real record files.

A steel beam (E = 2.06e11 Pa) fixed at its base carries a clevis-pin-tang joint
with clearance c at its other end; the jointed end (mass m: link plus the moving
part of a sliding bearing) is pushed by an exciter with F0 sin(2 pi f t). In
contact the beam and the joint act in series; inside the gap only the exciter's
suspension (k0) holds the mass. The same beam without the joint is the
non-jointed structure. The beam stiffens mildly with frequency and with its own
deformation amplitude F0 / k_beam (installation effects, as the paper found).

Each test is simulated exactly (``clearjoint.simulate``) from rest, and measured
the way a lab would: the motion is sampled ``oversampling`` times faster than
the recorder, passed through the same Butterworth anti-alias filter on every
channel, decimated, given Gaussian sensor noise and quantised by an ADC. The
truth of every test (its joint, and the steady cycle's energy from the
simulator's ledger) goes to ``manifest.csv`` beside the records.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from clearjoint.checks import refuse_to_overwrite
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.io_toml import quantity, read_toml
from clearjoint.joint import Friction, Joint, Losses, Pin
from clearjoint.parallel import process_pool, run_unordered
from clearjoint.progress import report, silenced
from clearjoint.records import Record, record_suffixes, write_record
from clearjoint.simulate import SimulationError, steady_state, time_response

FloatArray = NDArray[np.float64]

#: Columns of manifest.csv, in order.
MANIFEST_COLUMNS = (
    "file",
    "structure",
    "clearance_m",
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "force_amplitude_n",
    "frequency_hz",
    "energy_per_cycle_j",
    "gap_stiffness_n_per_m",
    "mass_kg",
    "beam_stiffness_n_per_m",
    "joint_compression_stiffness_n_per_m",
    "joint_tension_stiffness_n_per_m",
    "friction_force_n",
    "damping_ratio",
    "restitution",
    "amplitude_m",
    "compression_penetration_m",
    "tension_penetration_m",
    "period_multiple",
    "seed",
)

#: Kind of quantity of every campaign key that carries a unit.
_KINDS = {
    "rig.mass": "mass",
    "rig.bearing_lateral_load": "force",
    "rig.exciter_suspension_stiffness": "stiffness",
    "rig.beam.youngs_modulus": "pressure",
    "rig.beam.length": "length",
    "rig.beam.width": "length",
    "rig.beam.height": "length",
    "rig.joint.compression_stiffness": "stiffness",
    "rig.joint.tension_stiffness": "stiffness",
    "rig.joint.pin_radius": "length",
    "rig.joint.pin_length": "length",
    "rig.sensors.sampling_rate": "frequency",
    "rig.sensors.displacement_noise": "length",
    "rig.sensors.displacement_range": "length",
    "rig.sensors.force_noise": "force",
    "rig.sensors.force_range": "force",
    "rig.sensors.acceleration_noise": "acceleration",
    "rig.sensors.acceleration_range": "acceleration",
    "grid.frequencies": "frequency",
    "grid.force_amplitudes": "force",
    "structures.clearance": "length",
}


class CampaignError(ClearjointError, ValueError):
    """A campaign file is unusable; the message names the file and the key."""


@dataclass(frozen=True)
class Sensors:
    """The recorder: sampling, anti-alias filter, noise and ADC of each channel (SI)."""

    sampling_rate: float
    oversampling: int
    filter_order: int
    cutoff: float
    bits: int
    noise: dict[str, float]
    span: dict[str, float]


@dataclass(frozen=True)
class Rig:
    """Everything fixed across a campaign (SI)."""

    mass: float
    damping_ratio: float
    restitution: float
    bearing_friction: Friction
    suspension_stiffness: float
    youngs_modulus: float
    beam_length: float
    beam_width: float
    beam_height: float
    frequency_sensitivity: float
    amplitude_sensitivity: float
    joint_compression_stiffness: float
    joint_tension_stiffness: float
    pin_radius: float
    pin_length: float
    contact_friction_coefficient: float
    sensors: Sensors

    def losses(self, pin: Pin | None = None) -> Losses:
        """The rig's losses (MODEL.md sec. 2): damping, bearing friction, restitution, and
        with ``pin`` its contact friction (evaluated along the cycle, no feedback)."""
        return Losses(
            damping_ratio=self.damping_ratio,
            friction=self.bearing_friction,
            restitution=self.restitution,
            pin=pin,
            contact_friction_coefficient=self.contact_friction_coefficient
            if pin is not None
            else 0.0,
        )

    @property
    def beam_stiffness(self) -> float:
        """Axial stiffness of the bare beam E w h / L, N/m."""
        return self.youngs_modulus * self.beam_width * self.beam_height / self.beam_length

    def beam_stiffness_at(self, frequency_hz: float, force_amplitude: float) -> float:
        """The beam's stiffness in one test: k (1 + s_f f / 100 Hz + s_a (F0 / k) / 50 um)."""
        k = self.beam_stiffness
        return k * (
            1.0
            + self.frequency_sensitivity * frequency_hz / 100.0
            + self.amplitude_sensitivity * (force_amplitude / k) / 50e-6
        )


@dataclass(frozen=True)
class Structure:
    """A structure under test: jointed (with its clearance, m) or the bare beam."""

    name: str
    jointed: bool
    clearance: float = 0.0


@dataclass(frozen=True)
class TestSpec:
    """One test of a campaign."""

    index: int
    structure: Structure
    frequency_hz: float
    force_amplitude: float

    @property
    def file_stem(self) -> str:
        return f"{self.structure.name}_{self.frequency_hz:g}Hz_{self.force_amplitude:g}N"


@dataclass(frozen=True)
class Campaign:
    """A grid of tests on each structure, with the rig, a seed and the record format."""

    rig: Rig
    structures: tuple[Structure, ...]
    frequencies: tuple[float, ...]
    force_amplitudes: tuple[float, ...]
    seed: int
    format: str
    periods: int
    source: str

    @property
    def tests(self) -> tuple[TestSpec, ...]:
        specs = [
            (structure, f, force)
            for structure in self.structures
            for f in self.frequencies
            for force in self.force_amplitudes
        ]
        return tuple(TestSpec(i, *spec) for i, spec in enumerate(specs))


# ---- reading a campaign -------------------------------------------------------------------


def default_campaign_path() -> Path:
    """The shipped default campaign file."""
    return Path(str(resources.files("clearjoint") / "data" / "campaign.toml"))


def _merge(base: dict[str, Any], given: dict[str, Any], where: str, prefix: str = "") -> None:
    for key, value in given.items():
        name = f"{prefix}{key}"
        if key not in base:
            known = ", ".join(sorted(base))
            raise CampaignError(f"{where}: unknown key {name!r}; known here: {known}")
        if isinstance(base[key], dict):
            if not isinstance(value, dict):
                raise CampaignError(f"{where}: {name} must be a table")
            _merge(base[key], value, where, f"{name}.")
        else:
            base[key] = value


def _quantity(where: str, key: str, value: Any) -> float:
    kind = _KINDS.get(key, "dimensionless")
    name = f"{where}: {key}"
    value = quantity(value, kind, name=name, error=CampaignError, unit_keys=False)
    return float(value)


def load_campaign(path: str | Path | None = None) -> Campaign:
    """Read a campaign TOML file over the shipped defaults (``None``: the defaults alone).

    Raises
    ------
    CampaignError
        The file is missing or not TOML, a key is unknown, or a value is invalid.
    """
    default_path = default_campaign_path()
    values = read_toml(default_path, what="campaign", error=CampaignError)
    where = str(default_path)
    if path is not None:
        where = str(path)
        given = read_toml(path, what="campaign", error=CampaignError)
        structures = given.pop("structures", None)
        _merge(values, given, where)
        if structures is not None:
            values["structures"] = structures
    try:
        return _build(values, where)
    except ParameterError as exc:
        raise CampaignError(f"{where}: {exc}") from None


def _build(values: dict[str, Any], where: str) -> Campaign:
    def q(key: str) -> float:
        node: Any = values
        for part in key.split("."):
            node = node[part]
        return _quantity(where, key, node)

    rig_t = values["rig"]
    sens = rig_t["sensors"]
    channels = ("displacement", "force", "acceleration")
    sensors = Sensors(
        sampling_rate=q("rig.sensors.sampling_rate"),
        oversampling=int(sens["oversampling"]),
        filter_order=int(sens["filter_order"]),
        cutoff=float(sens["cutoff"]),
        bits=int(sens["bits"]),
        noise={c: q(f"rig.sensors.{c}_noise") for c in channels},
        span={c: q(f"rig.sensors.{c}_range") for c in channels},
    )
    if not 0.0 < sensors.cutoff < 0.5:
        raise CampaignError(f"{where}: rig.sensors.cutoff must lie in (0, 0.5) of the rate")
    if sensors.oversampling < 2 or sensors.bits < 4 or sensors.filter_order < 1:
        raise CampaignError(f"{where}: oversampling >= 2, bits >= 4 and filter_order >= 1")
    rig = Rig(
        mass=q("rig.mass"),
        damping_ratio=float(rig_t["damping_ratio"]),
        restitution=float(rig_t["restitution"]),
        bearing_friction=Friction(
            float(rig_t["bearing_friction_coefficient"]), q("rig.bearing_lateral_load")
        ),
        suspension_stiffness=q("rig.exciter_suspension_stiffness"),
        youngs_modulus=q("rig.beam.youngs_modulus"),
        beam_length=q("rig.beam.length"),
        beam_width=q("rig.beam.width"),
        beam_height=q("rig.beam.height"),
        frequency_sensitivity=float(rig_t["beam"]["frequency_sensitivity"]),
        amplitude_sensitivity=float(rig_t["beam"]["amplitude_sensitivity"]),
        joint_compression_stiffness=q("rig.joint.compression_stiffness"),
        joint_tension_stiffness=q("rig.joint.tension_stiffness"),
        pin_radius=q("rig.joint.pin_radius"),
        pin_length=q("rig.joint.pin_length"),
        contact_friction_coefficient=float(rig_t["joint"]["contact_friction_coefficient"]),
        sensors=sensors,
    )
    structures = []
    for entry in values["structures"]:
        unknown = sorted(set(entry) - {"name", "clearance", "jointed"})
        if unknown or "name" not in entry:
            raise CampaignError(
                f"{where}: each [[structures]] needs a name, and takes only "
                f"name, clearance, jointed; got {sorted(entry)}"
            )
        jointed = bool(entry.get("jointed", True))
        clearance = 0.0
        if jointed and "clearance" in entry:
            clearance = _quantity(where, "structures.clearance", entry["clearance"])
        if jointed and clearance <= 0.0:
            raise CampaignError(f"{where}: structure {entry['name']!r} needs a clearance > 0")
        structures.append(Structure(str(entry["name"]), jointed, clearance))
    grid = values["grid"]
    frequencies = tuple(_quantity(where, "grid.frequencies", v) for v in grid["frequencies"])
    forces = tuple(_quantity(where, "grid.force_amplitudes", v) for v in grid["force_amplitudes"])
    if not frequencies or not forces or min(frequencies) <= 0 or min(forces) <= 0:
        raise CampaignError(
            f"{where}: grid.frequencies and grid.force_amplitudes must be non-empty and positive"
        )
    fmt = str(values["format"])
    writable = [suffix.lstrip(".") for suffix in record_suffixes(writable=True)]
    if fmt not in writable:
        choices = " or ".join(repr(name) for name in writable)
        raise CampaignError(f"{where}: format must be {choices}, got {fmt!r}")
    return Campaign(
        rig=rig,
        structures=tuple(structures),
        frequencies=frequencies,
        force_amplitudes=forces,
        seed=int(values["seed"]),
        format=fmt,
        periods=int(values["periods"]),
        source=where,
    )


# ---- one test -----------------------------------------------------------------------------


def _series(k1: float, k2: float) -> float:
    return k1 * k2 / (k1 + k2)


def structure_under_test(rig: Rig, spec: TestSpec) -> tuple[Joint, Pin | None, float]:
    """The Joint the simulator sees in one test, its pin (None for the bare beam), and k_beam."""
    k_beam = rig.beam_stiffness_at(spec.frequency_hz, spec.force_amplitude)
    structure = spec.structure
    if not structure.jointed:
        joint = Joint(
            mass=rig.mass,
            clearance=0.0,
            compression_stiffness=k_beam,
            gap_stiffness=rig.suspension_stiffness,
        )
        return joint, None, k_beam
    joint = Joint(
        mass=rig.mass,
        clearance=structure.clearance,
        compression_stiffness=_series(k_beam, rig.joint_compression_stiffness),
        tension_stiffness=_series(k_beam, rig.joint_tension_stiffness),
        gap_stiffness=rig.suspension_stiffness,
    )
    pin = Pin.for_clearance(rig.pin_radius, structure.clearance, rig.pin_length)
    return joint, pin, k_beam


def _measure(
    true: FloatArray,
    sos: FloatArray,
    oversampling: int,
    noise: float,
    span: float,
    bits: int,
    rng: np.random.Generator,
) -> FloatArray:
    """Anti-alias filter, decimate, add noise, quantise to an ADC of +-span with ``bits``."""
    filtered = signal.sosfilt(sos, true)[::oversampling]
    noisy = filtered + rng.normal(0.0, noise, filtered.size)
    step = 2.0 * span / 2**bits
    quantised: FloatArray = np.clip(np.round(noisy / step) * step, -span, span - step)
    return quantised


def simulate_test(
    rig: Rig, spec: TestSpec, periods: int, seed: np.random.SeedSequence
) -> tuple[Record, dict[str, Any]]:
    """Simulate and measure one test; return the record and its truth (manifest row)."""
    joint, _, k_beam = structure_under_test(rig, spec)
    omega = 2.0 * math.pi * spec.frequency_hz
    losses = rig.losses()
    truth: dict[str, Any] = {
        "structure": spec.structure.name,
        "clearance_m": joint.clearance,
        "compression_stiffness_n_per_m": joint.compression_stiffness,
        "tension_stiffness_n_per_m": joint.tension_stiffness,
        "force_amplitude_n": spec.force_amplitude,
        "frequency_hz": spec.frequency_hz,
        "gap_stiffness_n_per_m": joint.gap_stiffness,
        "mass_kg": rig.mass,
        "beam_stiffness_n_per_m": k_beam,
        "joint_compression_stiffness_n_per_m": rig.joint_compression_stiffness
        if spec.structure.jointed
        else math.inf,
        "joint_tension_stiffness_n_per_m": rig.joint_tension_stiffness
        if spec.structure.jointed
        else math.inf,
        "friction_force_n": rig.bearing_friction.force,
        "damping_ratio": rig.damping_ratio,
        "restitution": rig.restitution,
        # the test's generator is SeedSequence(campaign seed).spawn(tests)[index]
        "seed": f"{seed.entropy}.{spec.index}",
    }
    try:
        with silenced():  # the campaign reports in tests, not in this cycle's periods
            cycle = steady_state(
                joint,
                spec.force_amplitude,
                omega,
                max_periods=5000,
                samples_per_period=16,
                losses=losses,
            )
        truth.update(
            energy_per_cycle_j=cycle.energy.input / cycle.period_multiple,
            amplitude_m=cycle.amplitude,
            compression_penetration_m=cycle.compression_penetration,
            tension_penetration_m=cycle.tension_penetration,
            period_multiple=cycle.period_multiple,
        )
    except SimulationError:
        truth.update(
            energy_per_cycle_j=math.nan,
            amplitude_m=math.nan,
            compression_penetration_m=math.nan,
            tension_penetration_m=math.nan,
            period_multiple=0,
        )
    sensors = rig.sensors
    fast = sensors.sampling_rate * sensors.oversampling
    with silenced():  # the campaign reports in tests, not in this transient's seconds
        motion = time_response(
            joint,
            spec.force_amplitude,
            omega,
            periods / spec.frequency_hz,
            sampling_rate=fast,
            losses=losses,
        )
    sos = signal.butter(
        sensors.filter_order, sensors.cutoff * sensors.sampling_rate, fs=fast, output="sos"
    )
    rng = np.random.default_rng(seed)
    channels = {
        "displacement": motion.displacement,
        "force": motion.excitation,
        "acceleration": motion.acceleration,
    }
    measured = {
        name: _measure(
            values,
            sos,
            sensors.oversampling,
            sensors.noise[name],
            sensors.span[name],
            sensors.bits,
            rng,
        )
        for name, values in channels.items()
    }
    record = Record(
        time=motion.time[:: sensors.oversampling],
        force=measured["force"],
        displacement=measured["displacement"],
        acceleration=measured["acceleration"],
        control="force",
        joint_id=spec.structure.name,
        clearance=spec.structure.clearance if spec.structure.jointed else None,
        force_amplitude=spec.force_amplitude,
        frequency_hz=spec.frequency_hz,
        mass=rig.mass,
        notes=f"clearjoint virtual rig, test {spec.index}",
    )
    return record, truth


def _run_one(args: tuple[Rig, TestSpec, int, np.random.SeedSequence, str, bool]) -> dict[str, Any]:
    rig, spec, periods, seed, path, force = args
    record, truth = simulate_test(rig, spec, periods, seed)
    write_record(record, path, force=force)
    truth["file"] = Path(path).name
    return truth


def _tasks(
    campaign: Campaign, out_dir: Path, force: bool
) -> Iterator[tuple[Rig, TestSpec, int, np.random.SeedSequence, str, bool]]:
    seeds = np.random.SeedSequence(campaign.seed).spawn(len(campaign.tests))
    for spec, seed in zip(campaign.tests, seeds, strict=True):
        path = out_dir / f"{spec.file_stem}.{campaign.format}"
        yield campaign.rig, spec, campaign.periods, seed, str(path), force


#: The finished tests of a campaign still running or interrupted, one JSON line each (after
#: a first line naming the campaign): a rerun into the same folder keeps those records.
JOURNAL_NAME = "campaign-progress.jsonl"


def _fingerprint(campaign: Campaign) -> str:
    """A digest of everything that decides a campaign's records (rig, grid, seed, format)."""
    return hashlib.sha256(repr(campaign).encode()).hexdigest()


def _journal_lines(campaign: Campaign, journal: Path) -> list[str]:
    """The journal's lines, or [] when there is none or it belongs to another campaign."""
    try:
        lines = journal.read_text(encoding="utf-8").splitlines()
        if json.loads(lines[0]).get("campaign") == _fingerprint(campaign):
            return lines
    except (OSError, IndexError, ValueError, AttributeError):
        pass
    return []


def finished_tests(campaign: Campaign, out_dir: str | Path) -> dict[int, dict[str, Any]]:
    """The tests of ``campaign`` an interrupted run into ``out_dir`` finished: index -> truth.

    Read from ``out_dir/campaign-progress.jsonl``; empty when there is none, when it was
    written for another campaign, or when nothing in it is usable. A test counts only if
    its record file is still there (the journal line is written after the record).
    """
    out_dir = Path(out_dir)
    lines = _journal_lines(campaign, out_dir / JOURNAL_NAME)
    stems = {spec.index: spec.file_stem for spec in campaign.tests}
    kept: dict[int, dict[str, Any]] = {}
    for line in lines[1:]:
        try:
            entry = json.loads(line)
            index, truth = int(entry["index"]), dict(entry["truth"])
        except (ValueError, KeyError, TypeError):
            continue  # a line cut short by the interruption
        name = f"{stems.get(index)}.{campaign.format}"
        if index in stems and truth.get("file") == name and (out_dir / name).is_file():
            kept[index] = truth
    return kept


def run_campaign(
    campaign: Campaign,
    out_dir: str | Path,
    *,
    jobs: int | None = None,
    force: bool = False,
    progress: Callable[[int, int], None] | None = None,
    executor: Any = None,
    keep_journal: bool = False,
) -> Path:
    """Run every test of ``campaign`` and write its records and ``manifest.csv`` to ``out_dir``.

    Tests run in parallel over ``jobs`` processes (default: every core), or on
    ``executor`` when given (a concurrent.futures Executor or a dask.distributed
    Client whose workers see ``out_dir``: clearjoint.parallel). Each test has its
    own seed drawn from the campaign's, so the output is the same bit for bit
    whatever the order the workers finish in. ``progress(done, total)`` is called
    after each test. Returns the manifest's path.

    Each finished test is noted in ``out_dir/campaign-progress.jsonl``: a run of the same
    campaign into a folder that an interrupted run left keeps its finished records and
    simulates only the rest (the manifest is the same as an uninterrupted run's);
    ``force`` starts afresh. The note is removed once the manifest is written, unless
    ``keep_journal`` (a caller with more to do after the campaign removes it when that is
    done, so that a rerun after an interruption there still finds every record).

    Raises
    ------
    OutputExistsError
        A record or the manifest exists in ``out_dir``, ``force`` is False and the folder
        holds no interrupted run of this campaign.
    """
    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs must be >= 1 (--jobs), got {jobs}")
    out_dir = Path(out_dir)
    journal = out_dir / JOURNAL_NAME
    resuming = not force and bool(_journal_lines(campaign, journal))
    kept = finished_tests(campaign, out_dir) if resuming else {}
    tasks = list(_tasks(campaign, out_dir, force or resuming))
    if not resuming:
        refuse_to_overwrite([out_dir / "manifest.csv", *(Path(t[4]) for t in tasks)], force=force)
    todo = [task for task in tasks if task[1].index not in kept]
    out_dir.mkdir(parents=True, exist_ok=True)
    if not resuming:
        journal.write_text(json.dumps({"campaign": _fingerprint(campaign)}) + "\n", "utf-8")
    rows = dict(kept)
    if progress and kept:
        progress(len(rows), len(tasks))
    with contextlib.ExitStack() as stack:
        runner = executor if executor is not None else stack.enter_context(process_pool(jobs))
        with journal.open("a", encoding="utf-8") as log:
            for done in run_unordered(_run_one, todo, runner):
                if done.error is not None:
                    raise done.error
                index = todo[done.index][1].index
                rows[index] = done.result  # type: ignore[assignment]
                log.write(json.dumps({"index": index, "truth": done.result}) + "\n")
                log.flush()
                if progress:
                    progress(len(rows), len(tasks))
                report(len(rows), len(tasks))  # to a listening progress bar (clearjoint.progress)
    manifest = out_dir / "manifest.csv"
    with manifest.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=MANIFEST_COLUMNS)
        writer.writeheader()
        for index in sorted(rows):
            writer.writerow({key: rows[index][key] for key in MANIFEST_COLUMNS})
    if not keep_journal:
        journal.unlink()
    return manifest
