"""The estimators' median: numpy.median's double, bit for bit, without importing numpy.ma."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from clearjoint.identify._stats import median

SHIPPED = Path(__file__).resolve().parent / "data" / "brfd"


def _bits(value: float) -> bytes:
    return np.float64(value).tobytes()


@pytest.mark.parametrize("n", [*range(1, 40), 1000, 1001])
def test_median_is_numpys_double_bit_for_bit(n: int) -> None:
    rng = np.random.default_rng(n)
    for scale in (1e-300, 1e-9, 1.0, 1e9, 1e300):
        values = rng.standard_normal(n) * scale
        assert _bits(median(values)) == _bits(float(np.median(values)))
        ties = np.round(values / scale, 1)  # repeated values and signed zeros
        assert _bits(median(ties)) == _bits(float(np.median(ties)))


def test_median_of_signed_zeros_nan_and_empty() -> None:
    assert _bits(median([-0.0])) == _bits(float(np.median([-0.0]))) == _bits(0.0)
    assert _bits(median([-0.0, -0.0])) == _bits(float(np.median([-0.0, -0.0])))
    assert np.isnan(median([1.0, np.nan, 2.0]))
    assert np.isnan(median([np.nan, 1.0, 2.0, 3.0]))
    with pytest.raises(ValueError, match="empty"):
        median([])


def test_identifying_a_brfd_record_imports_neither_numpy_ma_nor_the_weak_form() -> None:
    """Each identifying process (the command and its forked workers) used to import them."""
    record = SHIPPED / "2Hz30lbtension0.5amplitude.json"
    code = (
        "import sys\n"
        "from clearjoint.identify import identify\n"
        "from clearjoint.records import read_record\n"
        f"identify(read_record({str(record)!r}))\n"
        "unused = {'numpy.ma', 'numpy.polynomial', 'clearjoint.identify.weak'}\n"
        "print(sorted(unused & set(sys.modules)))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
