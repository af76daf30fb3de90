"""The sweep tasks built on clearjoint.periodic and clearjoint.harmonic, by independent routes.

- ``frequency_response`` on a joint without clearance is the forced linear oscillator:
  its peak is F0 / (2 zeta k sqrt(1 - zeta^2)) at w_n sqrt(1 - 2 zeta^2) (textbook).
- ``nonlinear_mode`` of a lossless joint: its frequency at the orbit's x_max is the exact
  free frequency 1 / T(A) of MODEL.md section 1, A = x_max - g_c (eq 4: T = 2 pi / w1 +
  2 c / (A w1) for k0 = 0, symmetric), written out here, within the harmonic truncation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from clearjoint.sweep import SERIAL, Sweep, run_sweep
from helpers import LINEAR_STUDY

LOSSLESS_GAP = """
[joint]
mass = "2kg"
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
[excitation]
force_amplitude = "500N"
frequency = "400Hz"
"""


def _sweep(tmp_path: Path, study: str, sweep: str) -> Path:
    (tmp_path / "study.toml").write_text(study, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(sweep, encoding="utf-8")
    return path


def test_frequency_response_peak_is_the_linear_resonance(tmp_path: Path) -> None:
    path = _sweep(
        tmp_path,
        LINEAR_STUDY,
        """
base = "study.toml"
[task]
name = "frequency_response"
frequency_start = "600Hz"
frequency_stop = "1400Hz"
outputs = ["peak_amplitude_m", "peak_frequency_hz", "folds", "unstable_points"]
[axes.excitation]
force_amplitude = ["100N", "300N"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, zeta = 2.0, 8e7, 0.05
    f0 = results["excitation.force_amplitude"].values
    peak = f0 / (2 * zeta * k * math.sqrt(1 - zeta**2))
    hz = math.sqrt(k / m) * math.sqrt(1 - 2 * zeta**2) / (2 * math.pi)
    # the curve is sampled: its largest point sits within the step of the true peak
    np.testing.assert_allclose(results.peak_amplitude_m, peak, rtol=1e-3)
    np.testing.assert_allclose(results.peak_frequency_hz, hz, rtol=1e-2)
    assert (results.folds == 0).all()
    assert (results.unstable_points == 0).all()


def test_nonlinear_mode_frequency_is_the_exact_free_frequency(tmp_path: Path) -> None:
    path = _sweep(
        tmp_path,
        LOSSLESS_GAP,
        """
base = "study.toml"
[task]
name = "nonlinear_mode"
harmonics = 31
outputs = ["frequency_hz", "damping_ratio", "x_max_m"]
[axes.task]
amplitude = ["80um", "200um"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, c = 2.0, 8e7, 0.1e-3
    w1 = math.sqrt(k / m)
    a = results.x_max_m.values - c / 2  # penetration beyond the centred gap's edge
    assert (a > 0).all()
    exact_hz = 1.0 / (2 * math.pi / w1 + 2 * c / (a * w1))
    np.testing.assert_allclose(results.frequency_hz, exact_hz, rtol=1e-4)
    np.testing.assert_allclose(results.damping_ratio, 0.0, atol=1e-9)  # no losses
