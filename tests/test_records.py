"""clearjoint.records: the record, its CSV and netCDF files, round trips, every bad-input case.

The BRFD JSON reader is tested in test_records_brfd.py, the registry of file endings in
test_records_formats.py.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from clearjoint.errors import OutputExistsError
from clearjoint.records import (
    CSV_MAGIC,
    Record,
    RecordError,
    RecordWarning,
    mass_advice,
    read_record,
    resample,
    sniff,
    write_record,
)
from clearjoint.units import registry


def record(**changes: object) -> Record:
    t = np.arange(2000) / 1000.0
    values: dict[str, object] = {
        "time": t,
        "force": 100.0 * np.sin(2 * np.pi * 10 * t),
        "displacement": 1e-5 * np.sin(2 * np.pi * 10 * t - 0.3),
        "acceleration": np.cos(t),
        "joint_id": "J1",
        "clearance": 0.106e-3,
        "force_amplitude": 100.0,
        "frequency_hz": 10.0,
        "mass": 1.5,
        "notes": 'a "quoted" note',
    }
    values.update(changes)
    return Record(**values)  # type: ignore[arg-type]


@pytest.mark.parametrize("suffix", [".csv", ".nc"])
def test_round_trip_keeps_data_and_metadata(tmp_path: Path, suffix: str) -> None:
    original = record()
    path = write_record(original, tmp_path / f"r{suffix}")
    back = read_record(path)
    for name in ("time", "force", "displacement", "acceleration"):
        np.testing.assert_array_equal(getattr(back, name), getattr(original, name))
    assert back.velocity is None
    for key in (
        "joint_id",
        "clearance",
        "force_amplitude",
        "frequency_hz",
        "mass",
        "notes",
        "control",
    ):
        assert getattr(back, key) == getattr(original, key)
    assert back.source == str(path)


def test_netcdf_variables_of_other_types_and_string_kinds_are_read(tmp_path: Path) -> None:
    # written by h5py by hand (not by xarray): float32, an integer variable (read by h5py's
    # usual interface), fixed-length and variable-length unit strings
    import h5py

    path = tmp_path / "lab.nc"
    t = np.arange(400) / 400.0
    force = (50 * np.sin(2 * np.pi * 10 * t)).astype(np.float32)
    steps = np.round(100 * np.sin(2 * np.pi * 10 * t - 0.3)).astype(np.int32)
    with h5py.File(path, "w") as handle:
        handle["time"] = t
        handle["time"].attrs["units"] = "s"
        handle["force"] = force
        handle["force"].attrs["units"] = np.bytes_(b"kN")
        handle["displacement"] = steps
        handle["displacement"].attrs["units"] = "um"
        handle.attrs["frequency_hz"] = 10.0
    back = read_record(path)
    np.testing.assert_array_equal(back.time, t)
    np.testing.assert_array_equal(back.force, force.astype(np.float64) * 1000.0)
    np.testing.assert_allclose(back.displacement, steps * 1e-6, rtol=1e-15)
    assert back.frequency_hz == 10.0
    with h5py.File(path, "a") as handle:
        del handle["force"].attrs["units"]
    with pytest.raises(RecordError, match="variable 'force' has no units attribute"):
        read_record(path)


def test_netcdf_attributes_read_as_h5pys_attribute_manager_gives_them(tmp_path: Path) -> None:
    # the low-level reading of the metadata against h5py's own AttributeManager, on every
    # kind an attribute may have: scalars and arrays of numbers, fixed- and variable-length
    # strings (one not UTF-8), an empty attribute and one of an array type (both left to
    # h5py: None)
    import h5py

    from clearjoint.records.netcdf import _h5_attribute

    path = tmp_path / "kinds.nc"
    with h5py.File(path, "w") as handle:
        attrs = handle.attrs
        attrs["scalar"] = 2.5
        attrs["one"] = np.array([1.5])
        attrs["ints"] = np.array([1, 2, 3], dtype=np.int16)
        attrs["text"] = "beam"
        attrs["fixed"] = np.bytes_(b"force")
        attrs.create("latin", data=b"caf\xe9", dtype=h5py.string_dtype())
        attrs.create("strings", data=["a", "bc"], dtype=h5py.string_dtype())
        attrs["empty"] = h5py.Empty("f8")
        attrs.create("arraytype", data=np.zeros((2, 3)), dtype=np.dtype("(3,)f8"))
    with h5py.File(path, "r") as handle:
        for name in handle.attrs:
            fast = _h5_attribute(h5py, handle.id, name.encode())
            if name in ("empty", "arraytype"):
                assert fast is None
                continue
            expected = handle.attrs[name]
            assert type(fast) is type(expected)
            np.testing.assert_array_equal(fast, expected, strict=True)


def test_netcdf_metadata_as_before(tmp_path: Path) -> None:
    # a record's metadata read by the low-level attributes, against xarray's reading
    import xarray as xr

    rec = Record(
        time=np.arange(600) / 600.0,
        force=np.sin(np.arange(600) / 10.0),
        displacement=np.cos(np.arange(600) / 10.0),
        frequency_hz=10.0,
        mass=1.25,
        clearance=1e-4,
        joint_id="pin 3",
        notes="caf\u00e9 [x]",
        control="displacement",
    )
    path = write_record(rec, tmp_path / "r.nc")
    back = read_record(path)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert back.frequency_hz == float(ds.attrs["frequency_hz"]) == 10.0
        assert back.mass == float(ds.attrs["mass_kg"]) == 1.25
        assert back.clearance == float(ds.attrs["clearance_m"])
        assert back.joint_id == ds.attrs["joint_id"] == "pin 3"
        assert back.notes == ds.attrs["notes"] == "caf\u00e9 [x]"
        assert back.control == ds.attrs["control"]


def test_csv_units_are_converted_to_si(tmp_path: Path) -> None:
    path = tmp_path / "lab.csv"
    t = np.arange(100) / 100.0
    lines = [
        CSV_MAGIC,
        '# frequency = "5 Hz"',
        '# clearance = "0.1 mm"',
        "time [ms],force [kN],displacement [mm]",
    ]
    lines += [f"{1000 * ti},{0.5},{0.01 * ti}" for ti in t]
    path.write_text("\n".join(lines) + "\n")
    r = read_record(path)
    np.testing.assert_allclose(r.time, t)
    np.testing.assert_allclose(r.force, 500.0)
    np.testing.assert_allclose(r.displacement, 1e-5 * t)
    assert r.clearance == pytest.approx(1e-4)
    assert r.units == {"time": "ms", "force": "kN", "displacement": "mm"}


def test_plain_csv_with_a_sidecar_toml(tmp_path: Path) -> None:
    path = tmp_path / "plain.csv"
    t = np.arange(100) / 100.0
    path.write_text(
        "time [s], force [N], displacement [um]\n" + "\n".join(f"{ti},{ti},{ti}" for ti in t) + "\n"
    )
    (tmp_path / "plain.toml").write_text('[record]\njoint_id = "side"\nmass = "2 kg"\n')
    r = read_record(path)
    assert r.joint_id == "side"
    assert r.mass == 2.0
    np.testing.assert_allclose(r.displacement, 1e-6 * t)


def test_mass_advice_in_a_sidecar_with_a_record_table_and_in_netcdf(tmp_path: Path) -> None:
    path = tmp_path / "plain.csv"
    t = np.arange(100) / 100.0
    path.write_text("time [s],force [N],displacement [m]\n" + "".join(f"{v},1,1\n" for v in t))
    sidecar = tmp_path / "plain.toml"
    sidecar.write_text('[record]\njoint_id = "side"\n')
    advice = mass_advice(str(path))
    line = "add the line 'mass = \"1.5 kg\"' (your moving mass)"
    assert advice == f"{line} to the [record] table of {sidecar}"
    sidecar.write_text(sidecar.read_text() + 'mass = "1.5 kg"\n')  # [record] is its last table
    assert read_record(path).mass == 1.5
    nc = write_record(record(mass=None), tmp_path / "r.nc")
    expected = f"set the global attribute mass_kg (your moving mass), in kg, in {nc}"
    assert mass_advice(str(nc)) == expected
    # a record not from a file: every way, each where it works
    assert "sidecar NAME.toml" in mass_advice("")


def write_csv(tmp_path: Path, body: str, name: str = "bad.csv") -> Path:
    path = tmp_path / name
    path.write_text(body)
    return path


def csv_body(times: list[float], values: str = "1,1") -> str:
    return "time [s],force [N],displacement [m]\n" + "".join(f"{t},{values}\n" for t in times)


UNIFORM = [i / 100 for i in range(50)]


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (csv_body([*UNIFORM[:10], 0.05, *UNIFORM[11:]]), "not strictly increasing"),
        (csv_body(UNIFORM, "nan,1"), "NaN or infinite"),
        (
            csv_body([0.0, 0.01, 0.03] + [0.03 + i / 100 for i in range(1, 40)]),
            "not uniformly sampled",
        ),
        (csv_body(UNIFORM[:5]), "only 5 samples"),
        ("time [s],force [lbf],displacement [m/s]\n" + "0,1,1\n" * 20, "not a unit of m"),
        ("time [s],force [N],displacement [furlongz]\n" + "0,1,1\n" * 20, "unknown unit"),
        ("time [s],force [N]\n" + "".join(f"{t},1\n" for t in UNIFORM), "no displacement"),
        ("time,force [N],displacement [m]\n0,1,1\n", "has no unit"),
        (CSV_MAGIC + '\n# frequency = "2 Hz"\n' + csv_body(UNIFORM), "spans 0.98 cycles"),
        (CSV_MAGIC + '\n# colour = "red"\n' + csv_body(UNIFORM), "unknown metadata"),
        (csv_body(UNIFORM, "1,abc"), "not numeric"),
    ],
)
def test_bad_records_name_the_file_and_the_problem(tmp_path: Path, body: str, words: str) -> None:
    path = write_csv(tmp_path, body)
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_a_record_of_two_cycles_is_refused_with_the_steady_cycle_rule(tmp_path: Path) -> None:
    """The same sentence as the identification's refusals (clearjoint.identify.steady_rule)."""
    from clearjoint.identify.cycles import STEADY_RULE

    path = write_csv(tmp_path, CSV_MAGIC + '\n# frequency = "2 Hz"\n' + csv_body(UNIFORM))
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert str(info.value).endswith(STEADY_RULE)
    assert "at least 3 steady cycles" in str(info.value)


def test_resampling_is_offered_and_works(tmp_path: Path) -> None:
    times = [0.0, 0.011] + [0.011 + i / 100 for i in range(1, 60)]
    path = write_csv(tmp_path, csv_body(times))
    with pytest.raises(RecordError, match="resample=True"):
        read_record(path)
    r = read_record(path, resample=True)
    assert np.ptp(np.diff(r.time)) < 1e-12


def test_resample_interpolates_linearly() -> None:
    t = np.array([0.0, 0.1, 0.25, 0.3, 0.4])
    grid, out = resample(t, {"x": 2 * t}, rate=20.0)
    np.testing.assert_allclose(out["x"], 2 * grid)
    np.testing.assert_allclose(np.diff(grid), 0.05)


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("fake.nc", b"time [s],force [N]\n", "named as netCDF but its content is CSV"),
        ("fake.json", b"time [s]\n", "named as JSON but its content is CSV"),
        ("fake.csv", b"\x89HDF\r\n\x1a\n" + b"\x00" * 32, "named as CSV but its content is NETCDF"),
        ("empty.csv", b"", "empty file"),
        ("blob.dat", b"\x00\x01\x02garbage", "binary file of unknown format"),
        ("other.json", b'{"a": 1}', "not a BRFD record"),
        ("broken.json", b'{"data": [1, 2', "not a JSON file"),
        ("broken.nc", b"\x89HDF\r\n\x1a\n" + b"\x00" * 64, "not a readable netCDF/HDF5 file"),
    ],
)
def test_files_that_are_not_what_they_claim(
    tmp_path: Path, name: str, content: bytes, words: str
) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(RecordError, match=words):
        read_record(path)


def test_missing_file_and_folder(tmp_path: Path) -> None:
    with pytest.raises(RecordError, match="no such file"):
        read_record(tmp_path / "none.csv")
    with pytest.raises(RecordError, match="is a folder"):
        sniff(tmp_path)


def test_never_overwrites_unless_asked(tmp_path: Path) -> None:
    path = write_record(record(), tmp_path / "r.csv")
    before = path.read_bytes()
    with pytest.raises(OutputExistsError, match="will not overwrite"):
        write_record(record(force_amplitude=5.0), path)
    assert path.read_bytes() == before
    write_record(record(force_amplitude=5.0), path, force=True)
    assert read_record(path).force_amplitude == 5.0
    with pytest.raises(RecordError, match=r"\.csv or \.nc"):
        write_record(record(), tmp_path / "r.xlsx")


def test_record_checks_its_own_fields() -> None:
    with pytest.raises(RecordError, match="force has 3 samples but time has 2000"):
        record(force=[1.0, 2.0, 3.0])
    with pytest.raises(RecordError, match="control must be"):
        record(control="temperature")
    with pytest.raises(RecordError, match="clearance must be finite and >= 0"):
        record(clearance=-1.0)


def test_fast_unit_factors_agree_with_pint() -> None:
    from clearjoint.records import FAST_FACTORS, SI
    from clearjoint.units import registry

    for (channel, unit), factor in FAST_FACTORS.items():
        exact = registry().Quantity(1.0, unit).to(SI[channel]).magnitude
        assert factor == pytest.approx(exact, rel=1e-12), (channel, unit)


def test_metadata_takes_units_or_a_unit_named_key_never_a_bare_number(tmp_path: Path) -> None:
    times = [i / 100 for i in range(50)]
    good = write_csv(tmp_path, CSV_MAGIC + "\n# frequency_hz = 10\n# clearance = \"0.1mm\"\n"
                     + csv_body(times), "good.csv")  # fmt: skip
    record = read_record(good)
    assert (record.frequency_hz, record.clearance) == pytest.approx((10.0, 1e-4))
    bad = write_csv(tmp_path, CSV_MAGIC + "\n# clearance = 0.1\n" + csv_body(times))
    with pytest.raises(RecordError, match=r"clearance = 0\.1: give a unit"):
        read_record(bad)


# ---- issue 16: lab CSV files as labs write them (each file written here by hand) ------------

RATE = 12000.0  # Hz, the issue's recorder
N_LAB = 1200  # 0.1 s: five cycles at 50 Hz


def lab_signals(i: int) -> tuple[float, float, float]:
    """Exact time (s), force (kN) and displacement (mm) of sample i."""
    t = i / RATE
    return t, 1.5 * math.sin(2 * math.pi * 50 * t), 0.02 * math.cos(2 * math.pi * 50 * t)


def check_lab_record(r: Record) -> None:
    """The record holds the exact signals in SI, on the uniform 12 kHz clock.

    The clock is fitted to stamps rounded to 1 us: it is found within 1 % of that.
    """
    i = np.arange(N_LAB)
    np.testing.assert_allclose(r.time, i / RATE, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r.force, 1500 * np.sin(2 * np.pi * 50 * i / RATE), atol=1e-3)
    np.testing.assert_allclose(r.displacement, 2e-5 * np.cos(2 * np.pi * 50 * i / RATE), atol=1e-9)


def test_lab_csv_semicolon_decimal_comma_key_value_preamble_units_row(tmp_path: Path) -> None:
    lines = ["Device;Rig A", "Operator: J. Smith", "Sample rate = 12000 Hz", "",
             "Time;Force;Displacement", "s;kN;mm"]  # fmt: skip
    for i in range(N_LAB):
        t, f, x = lab_signals(i)
        lines.append(f"{t:.6f};{f:.6f};{x:.7f}".replace(".", ","))  # rounded to 1 us
    path = tmp_path / "lab.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    r = read_record(path)
    check_lab_record(r)
    assert r.units == {"time": "s", "force": "kN", "displacement": "mm"}
    assert "Operator: J. Smith" in r.notes


def test_lab_csv_tab_comment_preamble_units_in_parentheses(tmp_path: Path) -> None:
    lines = ["# exported by DAQ 4.2", "// channel 3 unused", "% gain 10",
             "time (ms)\tforce (N)\tdisplacement (um)"]  # fmt: skip
    for i in range(N_LAB):
        t, f, x = lab_signals(i)
        lines.append(f"{t * 1e3:.3f}\t{f * 1e3:.4f}\t{x * 1e3:.4f}")  # ms to 1 us
    path = tmp_path / "lab.txt"
    path.write_text("\r\n".join(lines) + "\r\n", encoding="latin-1")
    check_lab_record(read_record(path))


def test_lab_csv_comma_with_a_bom_and_the_issue_rounding(tmp_path: Path) -> None:
    """The issue's file: 12 kHz, times rounded to 1 us, refused before as uneven."""
    body = "time [s],force [kN],displacement [mm]\n" + "".join(
        "{:.6f},{:.6f},{:.7f}\n".format(*lab_signals(i)) for i in range(N_LAB)
    )
    path = tmp_path / "lab.csv"
    path.write_bytes(b"\xef\xbb\xbf" + body.encode())
    check_lab_record(read_record(path))


def test_lab_csv_tab_decimal_comma_trailing_delimiter(tmp_path: Path) -> None:
    lines = ["time [s]\tforce [kN]\tdisplacement [mm]\t"]
    for i in range(N_LAB):
        t, f, x = lab_signals(i)
        lines.append(f"{t:.6f}\t{f:.6f}\t{x:.7f}\t".replace(".", ","))
    path = tmp_path / "lab.csv"
    path.write_text("\n".join(lines) + "\n")
    check_lab_record(read_record(path))


def test_uneven_beyond_the_clock_resolution_is_still_refused(tmp_path: Path) -> None:
    jitter = [0.0, 4e-6, -3e-6, 5e-6]  # up to 5 us on a clock written to 1 us
    body = "time [s],force [kN],displacement [mm]\n" + "".join(
        "{:.6f},{:.6f},{:.7f}\n".format(lab_signals(i)[0] + jitter[i % 4], *lab_signals(i)[1:])
        for i in range(N_LAB)
    )
    path = write_csv(tmp_path, body)
    with pytest.raises(RecordError, match="beyond their resolution 1e-06 s"):
        read_record(path)


@pytest.mark.parametrize("stamp", ["{:.6e}", "{:.9e}", "{:g}"])
def test_lab_csv_time_stamps_in_scientific_notation(tmp_path: Path, stamp: str) -> None:
    """%.6e stamps are rounded to 1e-11 s near 0 but 1e-7 s near 0.1 s: still a uniform clock."""
    body = "time [s],force [kN],displacement [mm]\n" + "".join(
        (stamp + ",{:.6f},{:.7f}\n").format(*lab_signals(i)) for i in range(N_LAB)
    )
    check_lab_record(read_record(write_csv(tmp_path, body)))


def test_uneven_scientific_stamps_are_still_refused(tmp_path: Path) -> None:
    jitter = [0.0, 3e-6, -2e-6, 1e-6]  # 3 us on stamps written to 1e-7 s or finer
    body = "time [s],force [kN],displacement [mm]\n" + "".join(
        "{:.6e},{:.6f},{:.7f}\n".format(lab_signals(i)[0] + jitter[i % 4], *lab_signals(i)[1:])
        for i in range(N_LAB)
    )
    with pytest.raises(RecordError, match="not uniformly sampled"):
        read_record(write_csv(tmp_path, body))


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("Device;Rig A\nthis line is free text\n", "no column names above the numbers (line 2"),
        ("time;force;displacement\n", "has no unit"),
        ("time [s];force [N];displacement [m];velocity [m/s]\n", "names 4 columns"),
        ("time [s];force [(];displacement [m]\n", "unknown unit '('"),  # pint asserted here
        ("time;force;displacement\ns;N\n", "line 2 has units for 2 columns"),
    ],
)
def test_lab_csv_problems_are_named(tmp_path: Path, text: str, words: str) -> None:
    path = write_csv(tmp_path, text + "".join(f"{i / 100};1;2\n" for i in range(50)))
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert words in str(info.value)
    assert str(path) in str(info.value)


# ---- issue 28: any preamble above the column names is kept as the record's notes --------


def lab_rows(delimiter: str = ",") -> list[str]:
    """The 12 kHz lab signals, in s, kN and mm, rounded to 1 us as a DAQ writes them."""
    return [delimiter.join(f.format(v) for f, v in zip(("{:.6f}", "{:.6f}", "{:.7f}"),
            lab_signals(i), strict=True)) for i in range(N_LAB)]  # fmt: skip


def test_lab_csv_with_a_free_text_title_line_as_acquisition_programs_write(
    tmp_path: Path,
) -> None:
    """The issue's file: a title line of free text above the header was refused."""
    lines = ["Clearance joint J1 - sine dwell 50 Hz", "time [s],force [kN],displacement [mm]"]
    path = write_csv(tmp_path, "\n".join(lines + lab_rows()) + "\n")
    r = read_record(path)
    check_lab_record(r)
    assert r.notes == "Clearance joint J1 - sine dwell 50 Hz"


def test_lab_csv_preamble_of_several_kinds_of_lines_kept_in_order(tmp_path: Path) -> None:
    lines = [
        "LabVIEW Measurement",  # free text
        "Operator;J. Smith;;",  # key and value in two cells, empty cells after
        "Rig A, bay 3; second shift",  # free text with punctuation
        "",
        "# comment line",
        "Time;Force;Displacement",
        "s;kN;mm",
    ]
    rows = [row.replace(",", ";").replace(".", ",") for row in lab_rows()]
    r = read_record(write_csv(tmp_path, "\n".join(lines + rows) + "\n"))
    check_lab_record(r)
    assert r.notes == (
        "LabVIEW Measurement; Operator;J. Smith; Rig A, bay 3; second shift; comment line"
    )


def test_lab_csv_preamble_that_looks_numeric_is_not_the_data(tmp_path: Path) -> None:
    """Numbers above the header (a date, a gain, a calibration table of five rows in the
    columns of the data) are preamble: the data is the block the column names head."""
    calibration = [f"{k},{2 * k}.5,{k * k}" for k in range(1, 6)]  # 5 rows of 3 numbers
    lines = ["20261128", "12000", *calibration, "", "time [s],force [kN],displacement [mm]"]
    r = read_record(write_csv(tmp_path, "\n".join(lines + lab_rows()) + "\n"))
    check_lab_record(r)  # the calibration rows are not in the signals
    assert r.notes == "20261128; 12000; " + "; ".join(calibration)


@pytest.mark.parametrize(
    ("preamble", "words"),
    [
        ([], "no column names above the numbers; name them like 'time [s]'"),
        (["Sine dwell, J1, 50 Hz"], "no column names above the numbers (line 1: 'Sine dwell"),
        (["Title", "a,b,c"], "(line 2: 'a,b,c')"),
    ],
)
def test_lab_csv_without_column_names_is_one_clear_line(
    tmp_path: Path, preamble: list[str], words: str
) -> None:
    path = write_csv(tmp_path, "\n".join(preamble + lab_rows()) + "\n")
    with pytest.raises(RecordError) as info:
        read_record(path)
    message = str(info.value)
    assert words in message
    assert str(path) in message
    assert "\n" not in message


def test_lab_csv_in_utf16_as_excel_saves_unicode_text(tmp_path: Path) -> None:
    """Excel's "Unicode text" is UTF-16 with a BOM, tab-separated: text, not a binary file."""
    lines = ["time (s)\tforce (kN)\tdisplacement (mm)"]
    lines += ["{:.6f}\t{:.6f}\t{:.7f}".format(*lab_signals(i)) for i in range(N_LAB)]
    path = tmp_path / "lab.txt"
    path.write_bytes("\r\n".join(lines).encode("utf-16"))  # BOM first, then UTF-16-LE
    check_lab_record(read_record(path))


def test_lab_csv_a_blank_spreadsheet_row_of_delimiters(tmp_path: Path) -> None:
    """';;' between the names and the numbers is a blank row, not a units row of blanks."""
    lines = ["Time [s];Force [kN];Displacement [mm]", ";;"]
    lines += [
        "{:.6f};{:.6f};{:.7f}".format(*lab_signals(i)).replace(".", ",") for i in range(N_LAB)
    ]
    path = tmp_path / "lab.csv"
    path.write_text("\n".join(lines) + "\n")
    check_lab_record(read_record(path))


def test_a_toml_file_given_as_a_record_says_so(tmp_path: Path) -> None:
    path = tmp_path / "test-1.toml"
    path.write_text('clearance = "0.1mm"\n')
    with pytest.raises(RecordError, match="a TOML file is not a record"):
        read_record(path)


def test_record_metadata_text_keeps_the_unit_message() -> None:
    t = np.arange(100) / 100.0
    with pytest.raises(RecordError, match=r"clearance 0\.1: give a unit, e\.g\. 0\.1mm"):
        Record(time=t, force=t, displacement=t, clearance="0.1")


def test_lab_csv_in_latin1_with_a_micro_sign(tmp_path: Path) -> None:
    """Windows DAQ software writes 'µm' as the single byte 0xB5: Latin-1, not UTF-8."""
    lines = ["time [s];force [kN];displacement [\u00b5m]"]
    for i in range(N_LAB):
        t, f, x = lab_signals(i)
        lines.append(f"{t:.6f};{f:.6f};{x * 1e3:.4f}".replace(".", ","))
    path = tmp_path / "lab.csv"
    path.write_bytes("\n".join(lines).encode("latin-1"))
    assert b"\xb5m" in path.read_bytes()
    r = read_record(path)
    check_lab_record(r)
    assert r.units["displacement"] == "\u00b5m"


def test_channels_given_as_pint_quantities_are_converted_not_stripped() -> None:
    # np.asarray(Quantity) keeps the magnitude and drops the unit: ms would be read as s
    ureg = registry()
    i = np.arange(100.0)
    r = Record(
        time=ureg.Quantity(i, "ms"),
        force=ureg.Quantity(np.ones(100), "kN"),
        displacement=ureg.Quantity(np.full(100, 20.0), "um"),
    )
    assert (r.time[-1], r.force[0], r.displacement[0]) == pytest.approx((0.099, 1000.0, 2e-5))
    with pytest.raises(RecordError, match="is not a length"):
        Record(time=i / 100, force=i, displacement=ureg.Quantity(i, "N"))


# ---- accelerometers speak g; a column a record has no channel for is left out -------------

G_N = 9.80665  # standard gravity, m/s^2 (CGPM 1901), written here, not read from the package


def lab_with_acceleration(unit: str, extra: str = "", extra_value: str = "") -> str:
    """Time (s), force (kN), displacement (mm), acceleration in ``unit`` (g) and an extra column.

    The acceleration is exact: x = X cos(w t) gives a = -w^2 x, written in g.
    """
    w = 2 * math.pi * 50
    head = f"time [s],force [kN],displacement [mm],acceleration [{unit}]{extra}\n"
    rows = []
    for i in range(N_LAB):
        t, f, x = lab_signals(i)
        a_in_g = -(w**2) * x * 1e-3 / G_N
        rows.append(f"{t:.6f},{f:.6f},{x:.7f},{a_in_g:.9e}{extra_value}\n")
    return head + "".join(rows)


@pytest.mark.parametrize("unit", ["g", "gn", "g0"])
def test_acceleration_in_g_is_standard_gravity(tmp_path: Path, unit: str) -> None:
    r = read_record(write_csv(tmp_path, lab_with_acceleration(unit), "acc.csv"))
    check_lab_record(r)
    w = 2 * math.pi * 50
    assert r.acceleration is not None
    exact = -(w**2) * 2e-5 * np.cos(w * np.arange(N_LAB) / RATE)  # m/s^2, as lab_signals
    np.testing.assert_allclose(r.acceleration, exact, rtol=1e-8, atol=1e-9)
    assert r.units["acceleration"] == unit


@pytest.mark.parametrize(
    ("header", "words"),
    [
        ("time [s],force [g],displacement [m]\n", "force is in 'g', which is not a unit of N"),
        ("time [s],force [N],displacement [g]\n", "displacement is in 'g', which is not a unit"),
    ],
)
def test_g_is_standard_gravity_for_acceleration_only(
    tmp_path: Path, header: str, words: str
) -> None:
    path = write_csv(tmp_path, header + "".join(f"{t},1,1\n" for t in UNIFORM))
    with pytest.raises(RecordError, match=re.escape(words)):
        read_record(path)


@pytest.mark.parametrize(
    ("extra", "value", "shown"),
    [
        (",temperature [C]", ",21.5", "'temperature [C]'"),
        (",Temperature (°C),strain [ue]", ",21.5,3", "'Temperature (°C)', 'strain [ue]'"),
    ],
)
def test_a_lab_csv_with_extra_columns_reads_the_known_ones_and_warns_once(
    tmp_path: Path, extra: str, value: str, shown: str
) -> None:
    path = write_csv(tmp_path, lab_with_acceleration("g", extra, value), "extra.csv")
    with pytest.warns(RecordWarning) as caught:
        r = read_record(path)
    check_lab_record(r)
    assert r.acceleration is not None
    assert set(r.units) == {"time", "force", "displacement", "acceleration"}
    assert len(caught) == 1
    message = str(caught[0].message)
    assert f"ignored column(s) {shown}" in message
    assert str(path) in message
    assert "\n" not in message


def test_an_unknown_column_in_place_of_a_needed_one_is_named(tmp_path: Path) -> None:
    body = "time [s],force [N],displacment [mm]\n" + "".join(f"{t},1,1\n" for t in UNIFORM)
    path = write_csv(tmp_path, body)
    with pytest.raises(
        RecordError,
        match=r"no displacement column, and no channel for "
        r"'displacment \[mm\]'.*rename the column that holds displacement",
    ):
        read_record(path)


@pytest.mark.filterwarnings("default::clearjoint.records.RecordWarning")
def test_cli_warns_in_one_line_for_an_extra_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from clearjoint.cli import main

    path = write_csv(tmp_path, lab_with_acceleration("g", ",temperature [C]", ",21.5"), "x.csv")
    main(["identify", str(path), "--out", str(tmp_path / "out.csv")])
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "ignored column" in line]
    assert lines == [
        f"clearjoint identify: warning: {path}: ignored column(s) 'temperature [C]': a record "
        "has no such channel (it reads time, force, displacement, velocity, acceleration)"
    ]
