"""The excitation frequency, the cycles, the steady-cycle rule and the cycle average.

MODEL.md section 3 ("per test record and per cycle"). The one rule for steady cycles,
used by every path of the identification (joint, damper, line) and quoted in its
error messages, is :data:`STEADY_RULE`: it is stated beside the record it judges
(:mod:`clearjoint.records.record`, which refuses a record too short for it) and applied
here by :func:`steady`; this module re-exports it and its constants.

The steady cycles are stacked on a common phase grid, shape (n_cycles, M): sample for
sample when the sampling rate is a multiple of the frequency (as in most test rigs),
else by linear interpolation. Their mean over the cycles is the latent periodic
signal the estimators fit: its noise is that of one cycle over sqrt(n_cycles), which is
what keeps displacement noise from biasing the regressors (errors in variables).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ClearjointError
from clearjoint.identify._stats import median
from clearjoint.records import CLOSURE as CLOSURE
from clearjoint.records import MIN_STEADY as MIN_STEADY
from clearjoint.records import PLATEAU as PLATEAU
from clearjoint.records import STEADY_RULE as STEADY_RULE
from clearjoint.records import Record
from clearjoint.records import steady_rule as steady_rule

FloatArray = NDArray[np.float64]


class IdentificationError(ClearjointError, ValueError):
    """A record could not be identified; the message says why in one line."""


def _smooth_length(n: int) -> int:
    """The smallest even 2^a 3^b 5^c >= n (a length the FFT factors into small primes)."""
    best = 2 * n
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            p = p35 * 2  # even: rfft of an even length
            while p < n:
                p *= 2
            best = min(best, p)
            p35 *= 3
        p5 *= 5
    return best


@functools.lru_cache(maxsize=8)
def _hanning(n: int) -> FloatArray:
    """``numpy.hanning(n)``, made once per length (a campaign's records share a few), read-only."""
    window = np.hanning(n)
    window.flags.writeable = False
    return window


def excitation_frequency(record: Record) -> float:
    """Return the excitation frequency in Hz: the displacement spectrum's peak, interpolated."""
    x = record.displacement - record.displacement.mean()
    n = x.size
    padded = _smooth_length(4 * n)  # a length the FFT factors fast
    # numpy's FFT (pocketfft): importing scipy.fft cost more than all the fits of a record
    spectrum = np.abs(np.fft.rfft(x * _hanning(n), n=padded))
    spectrum[0] = 0.0
    k = float(np.argmax(spectrum))
    i = int(k)
    if 0 < i < spectrum.size - 1:
        a, b, c = np.log(spectrum[i - 1 : i + 2] + 1e-300)
        if (a - 2 * b + c) != 0:
            k = i + 0.5 * (a - c) / (a - 2 * b + c)
    return float(k * record.sampling_rate / padded)


def cycle_bounds(record: Record, frequency: float) -> list[tuple[int, int]]:
    """Cycles from one minimum of the fundamental to the next, as sample index ranges."""
    t = record.time - record.time[0]
    w = 2.0 * math.pi * frequency
    basis = np.column_stack((np.cos(w * t), np.sin(w * t), np.ones_like(t)))
    gram = basis.T @ basis
    a, b, _ = np.linalg.solve(gram, basis.T @ record.displacement)
    phi = math.atan2(b, a)  # a cos + b sin = R cos(w t - phi): minimum where w t - phi = pi
    period = 1.0 / frequency
    first = ((phi + math.pi) / w) % period
    starts = np.arange(first, t[-1], period)
    index = np.searchsorted(t, starts)
    return [(int(i), int(j)) for i, j in itertools.pairwise(index) if j - i >= 16]


def steady(x: FloatArray, bounds: list[tuple[int, int]], tolerance: float) -> list[int]:
    """Indices (into ``bounds``) of the steady cycles, by :func:`steady_rule`."""
    if not bounds:
        return []
    starts = np.array([i for i, _ in bounds])
    stops = np.array([j for _, j in bounds])
    # bounds are contiguous ranges of x; reduceat over their starts (the last one ends at
    # its own stop, so the tail after it is cut off first)
    span = x[: stops[-1]]
    high = np.maximum.reduceat(span, starts)
    low = np.minimum.reduceat(span, starts)
    if np.any(starts[1:] != stops[:-1]):  # not contiguous: one cycle at a time
        high = np.array([x[i:j].max() for i, j in bounds])
        low = np.array([x[i:j].min() for i, j in bounds])
    amp = 0.5 * (high - low)
    mid = 0.5 * (high + low)
    top = amp >= PLATEAU * amp.max()
    reference = median(amp[top])
    centre = median(mid[top])
    closure = np.abs(x[starts] - x[stops - 1])
    keep = (
        (np.abs(amp - reference) <= tolerance * reference)
        & (np.abs(mid - centre) <= tolerance * reference)
        & (closure <= CLOSURE * reference)
    )
    return [int(k) for k in np.nonzero(keep)[0]]


@dataclass(frozen=True)
class Stack:
    """The steady cycles on a common phase grid.

    Attributes
    ----------
    starts : (n,) ndarray of int
        Sample index where each stacked cycle starts (for the record's own arrays).
    channels : dict of (n, M) ndarray
        Each channel, one row per steady cycle, M samples per period.
    step : float
        Time step of the phase grid, s.
    exact : bool
        True when the cycles were stacked sample for sample (no interpolation).
    """

    starts: NDArray[np.int64]
    channels: dict[str, FloatArray]
    step: float
    exact: bool

    @property
    def cycles(self) -> int:
        return int(self.starts.size)

    @property
    def samples(self) -> int:
        return int(next(iter(self.channels.values())).shape[1])


def stack(
    record: Record,
    frequency: float,
    bounds: list[tuple[int, int]],
    kept: list[int],
    channels: dict[str, FloatArray],
    shift: int = 0,
) -> Stack:
    """Stack the steady cycles ``kept`` (indices into ``bounds``) of every channel.

    Every cycle starts ``shift`` samples after (or, negative, before) its bound, so that
    rows stay contiguous in time (a cycle whose shifted span leaves the record is dropped).
    """
    rate = record.sampling_rate
    per = rate / frequency
    samples = round(per)
    n = record.time.size
    first = bounds[kept[0]][0] + shift
    # cycle k starts at first + (k - kept[0]) * per samples (k counts all cycles)
    offsets = np.array([(k - kept[0]) * per for k in kept])
    inside = (first + np.round(offsets) >= 0) & (first + np.round(offsets) + samples <= n)
    offsets = offsets[inside]
    drift = abs(per - samples) * (kept[-1] - kept[0] + 1)
    if drift < 0.05:
        starts = first + np.round(offsets).astype(np.int64)
        index = starts[:, None] + np.arange(samples)[None, :]
        out = {name: values[index] for name, values in channels.items()}
        return Stack(starts, out, 1.0 / rate, True)
    t0 = record.time[0] + first / rate
    grid = t0 + (offsets[:, None] + np.arange(samples)[None, :] * per / samples) / rate
    grid = np.clip(grid, record.time[0], record.time[-1])
    out = {
        name: np.interp(grid.ravel(), record.time, values).reshape(grid.shape)
        for name, values in channels.items()
    }
    starts = np.searchsorted(record.time, grid[:, 0]).astype(np.int64)
    return Stack(starts, out, per / samples / rate, False)
