"""The numbers a refactor must not move: write them from one checkout, compare two (issue 23).

Issue 23 refactors clearjoint under the rule "the same results to 1e-9 relative". This
script writes those results from whichever clearjoint is first on the path, and compares
two such files entry by entry. It uses only what every checkout since 25cf33e has: the
command line (``python -m clearjoint ...`` with ``--json`` and the netCDF / CSV / JSON
files it writes) and the public Python names the docs use, so it runs unchanged on the
code before the refactor and after it.

Run on demand::

    python3.11 benchmarks/compare_numbers.py write OUT.json [--quick]
    python3.11 benchmarks/compare_numbers.py compare A.json B.json [--rtol 1e-9] [--floor 1e-6]
    python3.11 benchmarks/compare_numbers.py checkouts OLD NEW [--quick] [--out DIR]

``write`` runs everything below with the clearjoint it imports (it prints that module's
path: put ``PYTHONPATH=CHECKOUT/src`` first, since the editable install points at
/work/main) and reads the inputs (``examples/``, ``tests/data/brfd/``) from that
checkout (``--root``; default: the one holding the imported package). ``checkouts``
runs ``write`` in a subprocess per checkout with ``PYTHONPATH=CHECKOUT/src``, checks
the imported path, and compares the two files (``OLD.json`` and ``NEW.json`` in
``--out``, default a new folder /tmp/numbers-*).

What it covers (each entry keeps the command or call that made it):

- ``reproduce/...``: ``clearjoint reproduce --jobs 1`` (the default campaign, 90
  tests; with ``--quick`` a 27-test campaign of the same rig, 3 frequencies x 3
  forces, written to the scratch folder): every number of ``results.json``
  (identified tests, fitted laws, joint stiffness, normalised coefficients, the
  identification against the rig's truth, section 2 against the exact cycles, the
  findings table's verdicts and evidence, the control run), ``results.csv``,
  ``fits.csv``, the rig's ``records/manifest.csv``, and per record file each
  channel's sum, sum of squares, extremes and a few samples.
- ``identify/...``: ``clearjoint identify`` on the reproduction's rig records and on
  ``tests/data/brfd/*.json``.
- ``frf/...``, ``modes/...``: docs/periodic.md and docs/harmonic.md on
  ``examples/frf.toml``: the shooting curve over frequency (10-360 Hz) and over force
  (10-200 N at 300 Hz), the harmonic-balance curve (200-330 Hz, H = 15) and the joint's
  nonlinear mode (1 um..1 mm, 40 points); each both as ``--json`` and as its ``.nc``.
  With ``--quick``: 40 and 30 points at most (``--max-points``), H = 7, 10 amplitudes.
- ``structure/...``: docs/structure.md on ``examples/mast.toml``: ``modes``,
  ``respond`` and ``decay`` (``--json`` and ``.nc``) and the mast's nonlinear mode at 3
  amplitudes (``clearjoint modes examples/mast.toml --amplitude 1mm..7mm --points
  3``). With ``--quick`` the study is copied with ``periods = 1`` and a 0.3 s decay.
  The mast's harmonic-balance frf is left out: docs/harmonic.md shows it refused at
  the example's 20 N after a minute.
- ``cli/...``: ``clearjoint stiffness``, ``dissipation`` and ``simulate`` as the docs
  show them, with ``--json``.
- ``api/...``: the README's and the docs' Python examples (``stiffness``,
  ``simulate.steady_state``, ``dissipation.energies``, ``periodic.periodic_orbit``,
  ``structure.mast(...).modes``), each in its own try block: a name that is gone is
  written as missing (and ``compare`` reports it), not a crash.

Left out as not deterministic: the reproduction's timings (``timing`` law and
integration seconds per test, ``model_comparison``'s ``integration_s``) and the
finding "the fitted law is faster than integration" (its verdict and evidence are
timings); the random name of the control run's temporary folder is replaced by
``TMP``, and the scratch folder's path by ``SCRATCH``. The reproduction runs with
``--jobs 1`` (the rig is documented to be the same bit for bit for any number of
processes; one job keeps the measure free of that question). ``report.html``, the
figures and ``--plot`` output are not read. With these left out, two ``write`` runs
on one checkout (25cf33e) agreed to the last bit, with and without ``--quick``.
Nothing here is timed: speed is the other benchmarks' job.

The structure study's ``--json`` carries the structure's ``repr`` as a string: a
refactor that renames the class shows there as DIFFERS, by design (it is output).

The file is one JSON object: ``meta`` (the clearjoint path and version, ``quick``,
the root) and ``entries``, each named ``group/source/key`` and holding ``command``
and either ``kind`` ("float", "bool" or "str"), ``shape`` and the flat ``values``
(NaN written as NaN, JSON null read as NaN) or ``missing`` (why). ``compare`` takes
two numbers a and b of an entry as equal when |a - b| <= rtol max(|a|, |b|, floor s),
s being the largest finite magnitude in either array (the floor keeps values near
zero relative to the array's scale from failing on round-off), NaN equal to NaN,
infinities equal when they have the same sign; shapes must agree, strings and
booleans exactly. It prints one line per entry (``equal``, ``DIFFERS`` with the
largest relative difference, its index and both values, or ``missing``) and exits 1
when any entry differs or is missing on either side.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

Entry = dict[str, Any]
Entries = dict[str, Entry]

QUICK_CAMPAIGN = """\
# benchmarks/compare_numbers.py --quick: the shipped campaign on a 3 x 3 grid (27 tests)
[grid]
frequencies = ["20Hz", "60Hz", "100Hz"]
force_amplitudes = ["800N", "1600N", "3000N"]
"""

# a few sample positions read from every rig record (fractions of its length)
RECORD_SAMPLES = (0.0, 0.25, 0.5, 0.75, 1.0)


# ----------------------------------------------------------------------------- entries


def losses_for(func: Callable[..., Any], **values: Any) -> dict[str, Any]:
    """The losses as ``func`` takes them: one ``Losses`` (``losses=``, since issue 23), or
    the loose keywords of older checkouts, so both trees compute the same case."""
    import inspect

    import clearjoint

    if "losses" in inspect.signature(func).parameters:
        return {"losses": clearjoint.Losses(**values)}
    return values


def _float_or_nan(value: Any) -> float:
    return math.nan if value is None else float(value)


def _entry(command: str, kind: str, shape: Sequence[int], values: list[Any]) -> Entry:
    return {"command": command, "kind": kind, "shape": list(shape), "values": values}


def value_entry(command: str, value: Any) -> Entry:
    """Return one entry (kind, shape, flat values) for a number, string or array-like.

    Booleans stay booleans, strings stay strings; numbers (and JSON null, read as NaN)
    become a float array. A ragged or mixed list is written as its JSON text (a string).
    """
    array = value if isinstance(value, np.ndarray) else np.asarray(value, dtype=object)
    if array.dtype.kind == "c":
        return value_entry(command, np.stack([array.real, array.imag], axis=-1))
    flat = list(array.ravel())
    kind = {"U": "str", "S": "str", "b": "bool", "i": "float", "u": "float", "f": "float"}
    if array.dtype.kind in kind:
        pass
    elif flat and all(isinstance(v, bool | np.bool_) for v in flat):
        kind["O"] = "bool"
    elif any(v is not None for v in flat) and all(
        v is None or (isinstance(v, int | float | np.number) and not isinstance(v, bool))
        for v in flat
    ):
        kind["O"] = "float"
    elif all(isinstance(v, str) for v in flat):
        kind["O"] = "str"
    else:
        return _entry(command, "str", [], [json.dumps(_plain(value), sort_keys=True)])
    converters: dict[str, Callable[[Any], Any]] = {"str": str, "bool": bool, "float": _float_or_nan}
    convert = converters[kind[array.dtype.kind]]
    return _entry(command, kind[array.dtype.kind], array.shape, [convert(v) for v in flat])


def missing_entry(command: str, why: str) -> Entry:
    """Return an entry that records a result which could not be made, and why."""
    return {"command": command, "missing": why}


def _plain(obj: Any) -> Any:
    """Return ``obj`` as JSON-like data: dicts, lists, floats, bools, strings, None."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        # public fields only: a result's private helpers are not its numbers
        fields = [f.name for f in dataclasses.fields(obj) if not f.name.startswith("_")]
        return {name: _plain(getattr(obj, name)) for name in fields}
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if hasattr(obj, "_asdict"):
        return {str(k): _plain(v) for k, v in obj._asdict().items()}
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer | np.floating):
        return float(obj)
    if isinstance(obj, complex | np.complexfloating):
        return [float(obj.real), float(obj.imag)]
    if obj is None or isinstance(obj, bool | int | float | str):
        return obj
    return repr(obj)


def _is_table(value: list[Any]) -> bool:
    return bool(value) and all(isinstance(row, dict) for row in value)


def _is_rectangular(value: list[Any]) -> bool:
    try:
        array = np.asarray(value, dtype=object)
    except ValueError:
        return False
    if array.ndim == 0 or array.size == 0:
        return array.ndim == 1
    return not any(isinstance(v, list | dict) for v in array.ravel())


def flatten(name: str, data: Any, command: str, out: Entries) -> None:
    """Add the numbers of JSON-like ``data`` to ``out`` as entries named ``name/...``.

    A dict becomes one entry per key, a list of dicts (a table) one entry per column,
    a rectangular list of scalars one array entry, anything else recursively by index.
    """
    data = _plain(data)
    if isinstance(data, dict):
        for key, value in data.items():
            flatten(f"{name}/{key}", value, command, out)
    elif isinstance(data, list) and _is_table(data):
        columns: list[str] = []
        for row in data:
            columns += [k for k in row if k not in columns]
        for column in columns:
            values = [row.get(column) for row in data]
            if any(isinstance(v, dict | list) for v in values):
                for i, v in enumerate(values):
                    flatten(f"{name}/{column}/{i}", v, command, out)
            else:
                out[f"{name}/{column}"] = value_entry(command, values)
    elif isinstance(data, list) and not _is_rectangular(data):
        for i, value in enumerate(data):
            flatten(f"{name}/{i}", value, command, out)
    else:
        out[name] = value_entry(command, data)


# ----------------------------------------------------------------------------- readers


def read_csv(path: Path) -> dict[str, list[Any]]:
    """Return a CSV file's columns: floats where every cell is a number or blank."""
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    columns: dict[str, list[Any]] = {}
    for key in rows[0] if rows else []:
        cells = [row[key] for row in rows]
        try:
            columns[key] = [math.nan if c.strip() == "" else float(c) for c in cells]
        except ValueError:
            columns[key] = cells
        if all(c.strip() == "" for c in cells):
            columns[key] = cells
    return columns


def read_netcdf(path: Path) -> dict[str, Any]:
    """Return a netCDF file's variables (coordinates included) and attributes."""
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        data: dict[str, Any] = {str(k): ds[k].values for k in ds.variables}
        data.update({f"attrs/{k}": v for k, v in ds.attrs.items()})
    return data


def record_summary(path: Path) -> dict[str, Any]:
    """Return a record file in short: per channel, its size, sum, sum of squares, min, max
    and the samples at RECORD_SAMPLES of its length; its attributes as one JSON text."""
    summary: dict[str, Any] = {}
    attrs: dict[str, Any] = {}
    for key, values in read_netcdf(path).items():
        array = np.asarray(values)
        if key.startswith("attrs/"):
            attrs[key.removeprefix("attrs/")] = _plain(values)
        elif array.dtype.kind not in "iuf" or array.ndim != 1 or array.size == 0:
            summary[key] = values
        else:
            where = [round(f * (array.size - 1)) for f in RECORD_SAMPLES]
            stats = [array.size, np.sum(array), np.sum(array * array), array.min(), array.max()]
            summary[key] = np.concatenate([np.array(stats, dtype=float), array[where]])
    summary["attrs"] = json.dumps(attrs, sort_keys=True)
    return summary


# ----------------------------------------------------------------------------- write


class Writer:
    """Collects the entries of one checkout: CLI runs in a scratch folder, API calls."""

    def __init__(self, root: Path, scratch: Path) -> None:
        self.root = root
        self.scratch = scratch
        self.entries: Entries = {}

    def _clean(self, text: str) -> str:
        text = text.replace(str(self.scratch), "SCRATCH")
        return re.sub(r"clearjoint-control-[A-Za-z0-9_]+", "clearjoint-control-TMP", text)

    def add(self, name: str, data: Any, command: str) -> None:
        """Add the numbers of ``data`` under ``name``, scratch paths written as SCRATCH."""
        found: Entries = {}
        flatten(name, data, self._clean(command), found)
        for key, entry in found.items():
            if entry.get("kind") == "str":
                entry["values"] = [self._clean(v) for v in entry["values"]]
            self.entries[key] = entry

    def cli(self, name: str, args: Sequence[str], shown: str | None = None) -> str | None:
        """Run ``python -m clearjoint ARGS`` in the root; return stdout, or None if it failed.

        ``shown`` is the command as printed and recorded (e.g. with a glob for many files).
        """
        command = shown or "clearjoint " + " ".join(args)
        print(f"  {self._clean(command)}", flush=True)
        done = subprocess.run(
            [sys.executable, "-m", "clearjoint", *args],
            cwd=self.root,
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            why = f"exit {done.returncode}: {done.stderr.strip()[-400:]}"
            self.entries[name] = missing_entry(self._clean(command), self._clean(why))
            print(f"    failed: {self._clean(why)}", flush=True)
            return None
        return done.stdout

    def cli_json(self, name: str, args: Sequence[str], files: Iterable[Path] = ()) -> bool:
        """Run a command with ``--json``; add its JSON and every .nc / .csv it wrote."""
        out = self.cli(name, [*args, "--json"])
        if out is None:
            return False
        command = self._clean("clearjoint " + " ".join([*args, "--json"]))
        self.add(f"{name}/json", json.loads(out), command)
        for path in files:
            self.add_file(f"{name}/{path.suffix[1:]}", path, command)
        return True

    def add_file(self, name: str, path: Path, command: str) -> None:
        """Add the numbers of one .nc, .csv or .json file."""
        if not path.exists():
            self.entries[name] = missing_entry(command, f"{path.name} was not written")
        elif path.suffix == ".nc":
            self.add(name, read_netcdf(path), command)
        elif path.suffix == ".csv":
            self.add(name, read_csv(path), command)
        else:
            self.add(name, json.loads(path.read_text()), command)

    def api(self, name: str, call: str, make: Callable[[], Any]) -> None:
        """Add the result of a Python API call, or a missing entry if it raised."""
        try:
            result = make()
        except Exception as error:  # a renamed or removed name is a result too
            self.entries[name] = missing_entry(call, f"{type(error).__name__}: {error}")
            print(f"  {call}: missing ({type(error).__name__}: {error})", flush=True)
            return
        self.add(name, result, call)


def _reproduce_json(data: dict[str, Any]) -> dict[str, Any]:
    """Return results.json without the numbers that are timings."""
    data = dict(data)
    data.pop("timing", None)
    for row in data.get("model_comparison", []):
        row.pop("integration_s", None)
    data["findings"] = [
        row
        for row in data.get("findings", [])
        if "faster than integration" not in str(row.get("finding", ""))
    ]
    return data


def write_reproduction(w: Writer, quick: bool) -> Path | None:
    """Run the reproduction and add its numbers; return its records folder."""
    out = w.scratch / "reproduce"
    args = ["reproduce", "--out", str(out), "--jobs", "1"]
    if quick:
        campaign = w.scratch / "quick-campaign.toml"
        campaign.write_text(QUICK_CAMPAIGN)
        args += ["--campaign", str(campaign)]
    if w.cli("reproduce", args) is None:
        return None
    command = "clearjoint " + " ".join(args)
    results = json.loads((out / "results.json").read_text())
    w.add("reproduce/results.json", _reproduce_json(results), command)
    for name in ("results.csv", "fits.csv"):
        w.add_file(f"reproduce/{name}", out / name, command)
    records = out / "records"
    w.add_file("reproduce/records/manifest.csv", records / "manifest.csv", command)
    for path in sorted(records.glob("*.nc")):
        w.add(f"reproduce/records/{path.name}", record_summary(path), command)
    return records


def write_identification(w: Writer, records: Path | None) -> None:
    """Identify the rig's records and the BRFD records; add the results CSVs."""
    brfd = sorted((w.root / "tests" / "data" / "brfd").glob("*.json"))
    runs = [("identify/brfd", [str(p.relative_to(w.root)) for p in brfd], "tests/data/brfd")]
    if records is not None:
        rig = [str(p) for p in sorted(records.glob("*.nc"))]
        runs.insert(0, ("identify/rig", rig, str(records)))
    for name, files, folder in runs:
        target = w.scratch / f"{name.replace('/', '-')}.csv"
        args = ["identify", *files, "--out", str(target), "--quiet"]
        glob = "*.nc" if name == "identify/rig" else "*.json"
        shown = f"clearjoint identify {folder}/{glob} --out {target} --quiet"
        if w.cli(name, args, shown) is not None:
            w.add_file(name, target, shown)


def write_curves(w: Writer, quick: bool) -> None:
    """Add the periodic and harmonic curves and the joint's mode of examples/frf.toml."""
    study = "examples/frf.toml"
    points = ["--max-points", "40"] if quick else []
    shooting = w.scratch / "frf-shooting.nc"
    w.cli_json(
        "frf/shooting",
        ["frf", study, "--from", "10Hz", "--to", "360Hz", "--out", str(shooting), *points],
        [shooting],
    )
    force = w.scratch / "frf-force.nc"
    w.cli_json(
        "frf/force",
        [
            "frf",
            study,
            "--parameter",
            "force",
            "--from",
            "10N",
            "--to",
            "0.2kN",
            "--frequency",
            "300Hz",
            "--out",
            str(force),
            *(["--max-points", "30"] if quick else []),
        ],
        [force],
    )
    harmonic = w.scratch / "frf-harmonic.nc"
    w.cli_json(
        "frf/harmonic",
        [
            "frf",
            study,
            "--from",
            "200Hz",
            "--to",
            "330Hz",
            "--out",
            str(harmonic),
            "--method",
            "harmonic",
            "--harmonics",
            "7" if quick else "15",
            *points,
        ],
        [harmonic],
    )
    modes = w.scratch / "modes-joint.nc"
    w.cli_json(
        "modes/joint",
        [
            "modes",
            study,
            "--mode",
            "1",
            "--amplitude",
            "1um..1mm",
            "--points",
            "10" if quick else "40",
            "--out",
            str(modes),
        ],
        [modes],
    )


def _quick_mast(w: Writer) -> str:
    """Return the mast study to run: examples/mast.toml, or a shorter copy for --quick."""
    text = (w.root / "examples" / "mast.toml").read_text()
    text = re.sub(r"(?m)^periods = \d+", "periods = 1", text)
    text = re.sub(r'(?m)^duration = "[^"]*"', 'duration = "0.3s"', text)
    path = w.scratch / "mast-quick.toml"
    path.write_text(text)
    return str(path)


def write_structure(w: Writer, quick: bool) -> None:
    """Add the mast's linear modes, forced response, free decay and nonlinear mode."""
    study = _quick_mast(w) if quick else "examples/mast.toml"
    for what in ("modes", "respond", "decay"):
        path = w.scratch / f"structure-{what}.nc"
        w.cli_json(f"structure/{what}", ["structure", study, what, "--out", str(path)], [path])
    path = w.scratch / "modes-mast.nc"
    w.cli_json(
        "modes/mast",
        [
            "modes",
            "examples/mast.toml",
            "--mode",
            "1",
            "--amplitude",
            "1mm..7mm",
            "--points",
            "3",
            "--out",
            str(path),
        ],
        [path],
    )


def write_cli_small(w: Writer) -> None:
    """Add the stiffness, dissipation and simulate commands of the docs (--json)."""
    stiffness = "stiffness --mass 2kg --stiffness 8e7N/m --clearance 0.106mm"
    w.cli_json("cli/stiffness", [*stiffness.split(), "--amplitude", "1um,5um,20um"])
    # the command of docs/dissipation.md
    docs = (
        "dissipation --mass 2kg --stiffness 8e7N/m --tension-stiffness 5e7N/m "
        "--clearance 0.106mm --amplitude 5um,20um,40um --friction-coefficient 0.2 "
        "--lateral-load 300N --restitution 0.8 --pin-radius 5mm --pin-length 25mm "
        "--contact-friction-coefficient 0.15 --damping-ratio 0.01"
    )
    w.cli_json("cli/dissipation", docs.split())
    w.cli_json(
        "cli/dissipation_study",
        ["dissipation", "--study", "examples/study.toml", "--amplitude", "20um"],
    )
    path = w.scratch / "simulate.nc"
    w.cli_json("cli/simulate", ["simulate", "examples/study.toml", "--out", str(path)], [path])


def write_api(w: Writer) -> None:
    """Add the README's and the docs' Python examples, each missing if a name is gone."""
    import clearjoint

    def joint() -> Any:
        return clearjoint.Joint(
            mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7
        )

    amplitudes = np.array([1e-6, 5e-6, 20e-6, 100e-6])
    omega = 2 * np.pi * 400.0
    readme = "README: Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, "
    readme += "tension_stiffness=5e7); a = [1e-6, 5e-6, 20e-6, 100e-6]; "

    def stiffness(name: str) -> Callable[[], Any]:
        def make() -> Any:
            from clearjoint import stiffness as sk

            return getattr(sk, name)(joint(), amplitudes)

        return make

    for name in (
        "period",
        "natural_frequency",
        "dynamic_stiffness",
        "stiffness_coefficient",
        "describing_stiffness",
        "free_orbit",
    ):
        w.api(f"api/stiffness/{name}", readme + f"stiffness.{name}(joint, a)", stiffness(name))

    def linear() -> Any:
        from clearjoint import stiffness as sk

        return sk.equivalent_linear_response(joint(), 800.0, omega, 0.01)

    w.api(
        "api/stiffness/equivalent_linear_response",
        readme + "stiffness.equivalent_linear_response(joint, 800.0, 2 pi 400, 0.01)",
        linear,
    )

    def cycle() -> Any:
        from clearjoint.simulate import steady_state

        c = steady_state(
            joint(),
            1000.0,
            omega,
            **losses_for(
                steady_state,
                damping_ratio=0.01,
                restitution=0.8,
                friction=clearjoint.Friction(0.2, 300.0),
            ),
        )
        return {
            "amplitude": c.amplitude,
            "x_max": c.x_max,
            "x_min": c.x_min,
            "period": c.period,
            "stages": c.stages,
            "energy": c.energy,
            "time": c.time,
            "displacement": c.displacement,
            "velocity": c.velocity,
        }

    w.api(
        "api/simulate/steady_state",
        readme + "simulate.steady_state(joint, 1000.0, "
        "2 pi 400, damping_ratio=0.01, restitution=0.8, friction=Friction(0.2, 300.0))",
        cycle,
    )

    def energies() -> Any:
        from clearjoint import dissipation

        j = joint()
        pin = clearjoint.Pin.for_clearance(5e-3, j.clearance, 25e-3)
        result = dissipation.energies(
            j,
            np.array([5e-6, 20e-6, 40e-6]),
            **losses_for(
                dissipation.energies,
                friction=clearjoint.Friction(0.2, 300.0),
                pin=pin,
                contact_friction_coefficient=0.15,
                restitution=0.8,
                damping_ratio=0.01,
            ),
        )
        return {k: result[k] for k in result}

    w.api(
        "api/dissipation/energies",
        readme + "dissipation.energies(joint, [5, 20, 40] um, "
        "friction=Friction(0.2, 300.0), pin=Pin.for_clearance(5e-3, c, 25e-3), "
        "contact_friction_coefficient=0.15, restitution=0.8, damping_ratio=0.01)",
        energies,
    )

    def orbit() -> Any:
        from clearjoint.periodic import periodic_orbit

        o = periodic_orbit(joint(), 1000.0, omega, **losses_for(periodic_orbit, damping_ratio=0.01))
        return {
            "initial_state": o.initial_state,
            "monodromy": o.monodromy,
            "multipliers": o.multipliers,
            "stable": o.stable,
            "x_max": o.x_max,
            "x_min": o.x_min,
            "amplitude": o.amplitude,
        }

    w.api(
        "api/periodic/periodic_orbit",
        readme + "periodic.periodic_orbit(joint, 1000.0, 2 pi 400, damping_ratio=0.01)",
        orbit,
    )

    def mast_modes() -> Any:
        from clearjoint.structure import mast

        hinge = clearjoint.ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
        tower = mast(10, joints=hinge, rayleigh=(0.5, 2e-6))
        modes = {pattern: tower.modes(pattern) for pattern in ("closed", "open")}
        return {p: {"omega": m.omega, "shapes": m.shapes} for p, m in modes.items()}

    w.api(
        "api/structure/mast_modes",
        "docs/structure.md: mast(10, joints=ClearanceJoint("
        "50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.5, 2e-6)).modes('closed' / 'open')",
        mast_modes,
    )


def _default_root() -> Path:
    import clearjoint

    package = Path(clearjoint.__file__).resolve().parent
    root = package.parents[1]
    return root if (root / "examples").is_dir() else Path(__file__).resolve().parents[1]


def write(out: Path, *, quick: bool = False, root: Path | None = None) -> Entries:
    """Compute every entry with the clearjoint on the path and write them to ``out``."""
    import clearjoint

    root = (root or _default_root()).resolve()
    print(f"clearjoint from {clearjoint.__file__}", flush=True)
    print(f"inputs from {root}", flush=True)
    scratch = Path(tempfile.mkdtemp(prefix="numbers-"))
    try:
        w = Writer(root, scratch)
        records = write_reproduction(w, quick)
        write_identification(w, records)
        write_curves(w, quick)
        write_structure(w, quick)
        write_cli_small(w)
        write_api(w)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    meta = {
        "clearjoint": str(Path(clearjoint.__file__).resolve()),
        "version": str(getattr(clearjoint, "__version__", "unknown")),
        "quick": quick,
        "root": str(root),
    }
    out.write_text(json.dumps({"meta": meta, "entries": w.entries}, indent=0))
    missing = sum("missing" in e for e in w.entries.values())
    print(f"wrote {out}: {len(w.entries)} entries, {missing} missing", flush=True)
    return w.entries


# ----------------------------------------------------------------------------- compare


@dataclasses.dataclass(frozen=True)
class Comparison:
    """One entry's verdict: "equal", "differs" or "missing", with a one-line detail."""

    name: str
    verdict: str
    detail: str = ""


def _largest_difference(a: np.ndarray, b: np.ndarray, rtol: float, floor: float) -> str:
    """Return "" when a and b agree, else the largest relative difference and where."""
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    if np.any(nan_a != nan_b):
        i = int(np.flatnonzero(nan_a != nan_b)[0])
        return f"NaN on one side only at {_where(i, a, b)}"
    inf = np.isinf(a) | np.isinf(b)
    if np.any(inf & (a != b)):
        i = int(np.flatnonzero(inf & (a != b))[0])
        return f"infinite at {_where(i, a, b)}"
    finite = ~(nan_a | inf)
    if not np.any(finite):
        return ""
    fa, fb = np.where(finite, a, 0.0), np.where(finite, b, 0.0)
    scale = max(float(np.max(np.abs(fa))), float(np.max(np.abs(fb))))
    denominator = np.maximum(np.maximum(np.abs(fa), np.abs(fb)), floor * scale)
    difference = np.abs(fa - fb)
    with np.errstate(invalid="ignore", divide="ignore"):
        relative = np.where(difference == 0.0, 0.0, difference / denominator)
    i = int(np.argmax(relative))
    if relative.flat[i] <= rtol:
        return ""
    return f"largest relative difference {relative.flat[i]:.3g} at {_where(i, a, b)}"


def _where(i: int, a: np.ndarray, b: np.ndarray) -> str:
    return f"{_index(i, a.shape)}: {float(a.flat[i])!r} vs {float(b.flat[i])!r}"


def _index(i: int, shape: tuple[int, ...]) -> str:
    return str(tuple(int(k) for k in np.unravel_index(i, shape))) if shape else "()"


def compare_entry(
    name: str, a: Entry | None, b: Entry | None, *, rtol: float = 1e-9, floor: float = 1e-6
) -> Comparison:
    """Return whether two entries of the same name agree (see the module docstring)."""
    if a is None or b is None:
        return Comparison(name, "missing", f"not in the {'first' if a is None else 'second'} file")
    for side, entry in (("first", a), ("second", b)):
        if "missing" in entry:
            return Comparison(name, "missing", f"{side} file: {entry['missing']}")
    if a["kind"] != b["kind"]:
        return Comparison(name, "differs", f"kind {a['kind']} vs {b['kind']}")
    if list(a["shape"]) != list(b["shape"]):
        return Comparison(name, "differs", f"shape {a['shape']} vs {b['shape']}")
    if a["kind"] != "float":
        unequal = [
            i for i, (x, y) in enumerate(zip(a["values"], b["values"], strict=True)) if x != y
        ]
        if not unequal:
            return Comparison(name, "equal")
        i = unequal[0]
        return Comparison(
            name,
            "differs",
            f"{len(unequal)} unequal, first at "
            f"{_index(i, tuple(a['shape']))}: {a['values'][i]!r} vs "
            f"{b['values'][i]!r}",
        )
    shape = tuple(a["shape"])
    va = np.array([_float_or_nan(v) for v in a["values"]], dtype=float).reshape(shape)
    vb = np.array([_float_or_nan(v) for v in b["values"]], dtype=float).reshape(shape)
    detail = _largest_difference(va, vb, rtol, floor)
    return Comparison(name, "differs" if detail else "equal", detail)


def compare(a: Entries, b: Entries, *, rtol: float = 1e-9, floor: float = 1e-6) -> list[Comparison]:
    """Return one comparison per entry name found in either set of entries, in order."""
    names = list(a) + [n for n in b if n not in a]
    return [compare_entry(n, a.get(n), b.get(n), rtol=rtol, floor=floor) for n in names]


def compare_files(
    first: Path,
    second: Path,
    *,
    rtol: float = 1e-9,
    floor: float = 1e-6,
    only_problems: bool = False,
) -> int:
    """Print one line per entry of two written files; return 1 if any differs or is missing."""
    da, db = json.loads(first.read_text()), json.loads(second.read_text())
    for label, data in (("first ", da), ("second", db)):
        meta = data["meta"]
        print(f"{label}: {data['meta']['clearjoint']} (quick={meta['quick']})")
    if da["meta"]["quick"] != db["meta"]["quick"]:
        print("warning: one file was written with --quick and the other without")
    results = compare(da["entries"], db["entries"], rtol=rtol, floor=floor)
    for r in results:
        if r.verdict != "equal" or not only_problems:
            label = {"equal": "equal", "differs": "DIFFERS", "missing": "missing"}[r.verdict]
            print(f"{label:8s} {r.name}" + (f": {r.detail}" if r.detail else ""))
    counts = {v: sum(r.verdict == v for r in results) for v in ("equal", "differs", "missing")}
    print(
        f"{len(results)} entries: {counts['equal']} equal, {counts['differs']} differ, "
        f"{counts['missing']} missing (rtol {rtol:g}, floor {floor:g} of each array's scale)"
    )
    return 0 if counts["equal"] == len(results) else 1


# ----------------------------------------------------------------------------- checkouts


def checkouts(
    old: Path,
    new: Path,
    *,
    quick: bool,
    out: Path | None,
    rtol: float,
    floor: float,
    only_problems: bool,
) -> int:
    """Run ``write`` on two checkouts (each in its own process) and compare the files."""
    out = out or Path(tempfile.mkdtemp(prefix="numbers-"))
    out.mkdir(parents=True, exist_ok=True)
    files = []
    for label, checkout in (("OLD", old.resolve()), ("NEW", new.resolve())):
        target = out / f"{label}.json"
        env = dict(os.environ)
        src = str(checkout / "src")
        env["PYTHONPATH"] = os.pathsep.join([src, *filter(None, [env.get("PYTHONPATH")])])
        print(f"== {label}: PYTHONPATH={src}", flush=True)
        args = [
            sys.executable,
            str(Path(__file__).resolve()),
            "write",
            str(target),
            "--root",
            str(checkout),
            *(["--quick"] if quick else []),
        ]
        done = subprocess.run(args, env=env, check=False)
        if done.returncode != 0:
            print(f"write failed on {checkout} (exit {done.returncode})")
            return 1
        used = json.loads(target.read_text())["meta"]["clearjoint"]
        if not used.startswith(src + os.sep):
            print(f"{label} imported {used}, not the checkout's {src}: stopping")
            return 1
        files.append(target)
    print(f"== compare {files[0]} {files[1]}", flush=True)
    return compare_files(files[0], files[1], rtol=rtol, floor=floor, only_problems=only_problems)


def main(argv: Sequence[str] | None = None) -> int:
    """Parse the command line and run write, compare or checkouts; return the exit code."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else "")
    sub = parser.add_subparsers(dest="command", required=True)
    p_write = sub.add_parser("write", help="write this checkout's numbers to OUT.json")
    p_write.add_argument("out", type=Path)
    p_write.add_argument("--quick", action="store_true", help="a smaller run of each")
    p_write.add_argument("--root", type=Path, help="checkout whose examples/ and tests/data/")
    for name, helptext in (
        ("compare", "compare two written files"),
        ("checkouts", "write on two checkouts and compare"),
    ):
        p = sub.add_parser(name, help=helptext)
        p.add_argument("first", type=Path)
        p.add_argument("second", type=Path)
        p.add_argument("--rtol", type=float, default=1e-9)
        p.add_argument(
            "--floor",
            type=float,
            default=1e-6,
            help="absolute floor as a fraction of each array's largest value",
        )
        p.add_argument(
            "--only-problems",
            action="store_true",
            help="print only entries that differ or are missing",
        )
        if name == "checkouts":
            p.add_argument("--quick", action="store_true")
            p.add_argument("--out", type=Path, help="folder for OLD.json and NEW.json")
    args = parser.parse_args(argv)
    if args.command == "write":
        entries = write(args.out, quick=args.quick, root=args.root)
        return 0 if entries else 1
    options = {"rtol": args.rtol, "floor": args.floor, "only_problems": args.only_problems}
    if args.command == "compare":
        return compare_files(args.first, args.second, **options)
    return checkouts(args.first, args.second, quick=args.quick, out=args.out, **options)


if __name__ == "__main__":
    sys.exit(main())
