"""Test records: time, force and displacement with their metadata, in real file formats.

A :class:`Record` is validated when it is made (strictly increasing, uniformly
sampled, finite, long enough for three cycles); everything inside is SI with the
frequencies in Hz, as in files. Formats, recognised by their content:

* CSV (:mod:`~clearjoint.records.lab_csv`): a ``# clearjoint record 1`` header block
  of ``key = value`` lines (TOML), then a column line ``time [s],force [N],displacement
  [mm],...`` whose units are converted to SI; or a plain CSV with a sidecar
  ``<name>.toml`` beside it.
* netCDF / HDF5 (:mod:`~clearjoint.records.netcdf`), written through xarray (h5netcdf
  engine) and read back with h5py: variables ``time``, ``force``, ``displacement`` (and
  ``velocity``, ``acceleration``) with ``units`` attributes, metadata as global
  attributes.
* The BRFD JSON files of the friction-damper-with-backlash data set (inches, kips; see
  data/brfd/README.md), through :func:`read_brfd` (:mod:`~clearjoint.records.brfd`).

The modules: :mod:`~clearjoint.records.record` (the record, its channels and units, the
steady-cycle rule :data:`STEADY_RULE`), one module per format, and
:mod:`~clearjoint.records.formats` (the one registry of file endings, :data:`FORMATS`,
and reading and writing through it). The layouts are documented in docs/records.md.
Nothing is overwritten unless asked.
"""

from clearjoint.records.brfd import BRFD_CITATION, read_brfd
from clearjoint.records.formats import (
    FORMATS,
    RecordFormat,
    import_readers,
    is_record_file,
    mass_advice,
    read_record,
    record_format,
    record_suffixes,
    sniff,
    write_record,
)
from clearjoint.records.lab_csv import CSV_MAGIC, regular_time
from clearjoint.records.netcdf import record_dataset
from clearjoint.records.record import (
    CHANNELS,
    CLOSURE,
    FAST_FACTORS,
    GRAVITY_UNITS,
    MIN_CYCLES,
    MIN_SAMPLES,
    MIN_STEADY,
    PLATEAU,
    SI,
    STANDARD_GRAVITY,
    STEADY_RULE,
    UNIFORM_TOLERANCE,
    Record,
    RecordError,
    RecordWarning,
    resample,
    steady_rule,
)

__all__ = [
    "BRFD_CITATION",
    "CHANNELS",
    "CLOSURE",
    "CSV_MAGIC",
    "FAST_FACTORS",
    "FORMATS",
    "GRAVITY_UNITS",
    "MIN_CYCLES",
    "MIN_SAMPLES",
    "MIN_STEADY",
    "PLATEAU",
    "SI",
    "STANDARD_GRAVITY",
    "STEADY_RULE",
    "UNIFORM_TOLERANCE",
    "Record",
    "RecordError",
    "RecordFormat",
    "RecordWarning",
    "import_readers",
    "is_record_file",
    "mass_advice",
    "read_brfd",
    "read_record",
    "record_dataset",
    "record_format",
    "record_suffixes",
    "regular_time",
    "resample",
    "sniff",
    "steady_rule",
    "write_record",
]
