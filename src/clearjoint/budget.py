"""How long a request will take, roughly: a runaway one is refused before it starts.

An estimate is a count (amplitudes of a mode, points of a curve) times a cost per unit
measured on this project's machine (2 cores, warm compiled-code cache), rounded down, so
the estimate is rather short than long. A request whose estimate exceeds :data:`LIMIT_S`
is refused with the estimate and the option that allows it; the command line's
``--allow-long`` skips the check. No physics here.
"""

from __future__ import annotations

from clearjoint.errors import ParameterError

__all__ = [
    "LIMIT_S",
    "OUTPUT_BYTES_PER_SAMPLE",
    "OUTPUT_LIMIT_BYTES",
    "SECONDS_PER",
    "STRUCTURE_PERIOD_S_PER_DOF2",
    "STRUCTURE_TANGENT_S_PER_DOF3",
    "TABLE_BYTES_PER_POINT",
    "check_budget",
    "check_output",
    "check_table",
    "estimate_s",
    "for_people",
    "structure_period_s",
    "structure_tangent_s",
]

#: Estimated seconds above which a request is refused unless allowed: one hour.
LIMIT_S = 3600.0

#: Seconds one unit of work costs, by kind, measured with the commands named (rounded down).
SECONDS_PER = {
    # clearjoint modes examples/frf.toml --amplitude 1um..1mm --points 80: ~0.05 s a point
    "joint mode amplitude": 0.02,
    # clearjoint modes examples/mast.toml --amplitude 2mm..7mm --points 30: 3-7 s a point
    "structure mode amplitude": 2.0,
    # clearjoint frf examples/frf.toml --from 10Hz --to 360Hz: 323 points in ~4 s
    "joint curve point": 0.01,
    # a structure's curve by harmonic balance: several times a joint's point
    "structure curve point": 0.1,
    # clearjoint simulate examples/study.toml as a transient of 2000 periods: 0.63 s
    "joint forcing period": 1e-4,
}

#: Seconds one period of a structure's exact motion costs, per DOF squared (the march's
#: matrices): examples/chain.toml (5 DOF) 0.003 s a period, examples/mast.toml (40 DOF)
#: 0.28 s a period (clearjoint.structure.time_response, machine loaded), rounded down.
STRUCTURE_PERIOD_S_PER_DOF2 = 1e-4


def structure_period_s(n_dof: int) -> float:
    """Estimated seconds of one period of the exact motion of an ``n_dof``-DOF structure."""
    return STRUCTURE_PERIOD_S_PER_DOF2 * float(n_dof) ** 2


#: Seconds a recorded period of a stepped sine costs on top of its motion, per DOF cubed:
#: its largest Lyapunov exponent carries the (2N, 2N) tangent flow along the motion.
#: CPU seconds of a recorded period less a settling one, near and at twice closed mode 1
#: (benchmarks/bench_budget.py, one BLAS thread, machine loaded, three runs):
#: examples/chain.toml (5 DOF) 0.002-0.004 s, examples/mast.toml (40 DOF) 1.3-3.1 s; the
#: settling periods there took 0.0006-0.0011 s and up to 0.13 s, which
#: :data:`STRUCTURE_PERIOD_S_PER_DOF2` covers. A period's cost follows the gap-edge events
#: it meets: the mast with 5 bays (20 DOF) at the same force met few and cost 5-30 times
#: less than this estimate.
STRUCTURE_TANGENT_S_PER_DOF3 = 3e-5


def structure_tangent_s(n_dof: int) -> float:
    """Estimated extra seconds of one recorded stepped-sine period of an ``n_dof``-DOF structure."""
    return STRUCTURE_TANGENT_S_PER_DOF3 * float(n_dof) ** 3


def estimate_s(count: float, kind: str) -> float:
    """Estimated seconds for ``count`` units of ``kind`` (a key of :data:`SECONDS_PER`)."""
    return float(count) * SECONDS_PER[kind]


def for_people(seconds: float) -> str:
    """A time span as a person reads it: 40 s, 12 min, 3.5 h, 23 days."""
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    if seconds < 7200.0:
        return f"{seconds / 60.0:.0f} min"
    if seconds < 3.0 * 86400.0:
        return f"{seconds / 3600.0:.1f} h"
    return f"{seconds / 86400.0:.0f} days"


#: Bytes a steady state's output costs per sample, in memory and on disk together:
#: ``clearjoint simulate`` on examples/study.toml made steady, with [output] periods =
#: 20000 (5.1 million samples), took 540 MB resident against 260 MB with 2 periods and
#: wrote 246 MB (rounded up from 55 + 48).
OUTPUT_BYTES_PER_SAMPLE = 110

#: A steady state's output estimated above this many bytes is refused unless allowed.
OUTPUT_LIMIT_BYTES = 4 * 2**30


def check_output(periods: int, samples_per_period: int, *, allow: str = "--allow-long") -> None:
    """Refuse a steady state's ``[output] periods`` whose samples would not fit in memory.

    Its cost is not time (the orbit is computed once and repeated) but the repeated series,
    held in memory and written to --out.

    Raises
    ------
    ParameterError
        The estimate exceeds :data:`OUTPUT_LIMIT_BYTES`; the message gives the estimate,
        the limit and ``allow``.
    """
    _check_bytes(
        float(periods) * float(samples_per_period) * OUTPUT_BYTES_PER_SAMPLE,
        f"[output] periods {periods} x samples_per_period {samples_per_period}",
        f"series in memory and on disk ({OUTPUT_BYTES_PER_SAMPLE} bytes a sample)",
        f"ask for fewer periods, or pass {allow} to write it anyway",
    )


def _check_bytes(size: float, asked: str, what: str, instead: str) -> None:
    """Refuse a request whose ``size`` bytes exceed :data:`OUTPUT_LIMIT_BYTES`, in one line."""
    if size > OUTPUT_LIMIT_BYTES:
        raise ParameterError(
            f"{asked}: about {size / 2**30:.0f} GiB of {what}, above the limit of "
            f"{OUTPUT_LIMIT_BYTES / 2**30:.0f} GiB; {instead}"
        )


#: Bytes a point of a joint's amplitude table costs in memory, its arrays and the printed
#: table or JSON together: ``clearjoint stiffness`` with --amplitude 1um..1mm --points
#: 1000000 took 366 MB resident (584 MB with --json) and ``clearjoint dissipation --study
#: examples/study.toml`` 642 MB, against 164 and 233 MB with 100000 points (rounded up).
TABLE_BYTES_PER_POINT = 500


def check_table(points: int, *, option: str = "--points", allow: str = "--allow-long") -> None:
    """Refuse an amplitude range of ``points`` whose table would not fit in memory.

    ``clearjoint stiffness`` and ``dissipation`` compute a row a point in microseconds: the
    limit is the memory (:data:`TABLE_BYTES_PER_POINT`), as for :func:`check_output`.

    Raises
    ------
    ParameterError
        The estimate exceeds :data:`OUTPUT_LIMIT_BYTES`; the message gives the estimate,
        the limit and ``allow``.
    """
    _check_bytes(
        float(points) * TABLE_BYTES_PER_POINT,
        f"{option} {points}",
        f"table in memory ({TABLE_BYTES_PER_POINT} bytes a point)",
        f"ask for fewer, or pass {allow} to run it anyway",
    )


def check_budget(
    count: float,
    kind: str,
    *,
    option: str,
    allow: str = "--allow-long",
    each: float | None = None,
    given: str | None = None,
    extra: tuple[float, float, str] | None = None,
) -> None:
    """Refuse ``count`` units of ``kind`` (given by ``option``) if they would take too long.

    ``each`` is the seconds a unit costs when it is not :data:`SECONDS_PER` [``kind``] (a
    structure's period, :func:`structure_period_s`); ``given`` says how the request was
    written when not as ``option count`` (a product of several options, a study value);
    ``extra`` = (count, seconds each, what) is a further cost of some of the units (a
    stepped sine's recorded periods carry a tangent flow, :func:`structure_tangent_s`).

    Raises
    ------
    ParameterError
        The estimate exceeds :data:`LIMIT_S`; the message gives the estimate, the limit,
        and ``allow``, the option that runs it anyway.
    """
    each = SECONDS_PER[kind] if each is None else each
    seconds = float(count) * each
    more = ""
    if extra is not None:
        seconds += float(extra[0]) * extra[1]
        more = f" plus {extra[2]} of {extra[0]:.0f} periods ({extra[1]:.3g} s each)"
    if seconds > LIMIT_S:
        asked = f"{option} {count}" if given is None else given
        raise ParameterError(
            f"{asked}: about {for_people(seconds)} of computing "
            f"({each:g} s per {kind}){more}, above the limit of {for_people(LIMIT_S)}; "
            f"ask for fewer, or pass {allow} to run it anyway"
        )
