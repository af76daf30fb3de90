"""How long a request will take, roughly: a runaway one is refused before it starts.

An estimate is a count (amplitudes of a mode, points of a curve) times a cost per unit
measured on this project's machine (2 cores, warm compiled-code cache), rounded down, so
the estimate is rather short than long. A request whose estimate exceeds :data:`LIMIT_S`
is refused with the estimate and the option that allows it; the command line's
``--allow-long`` skips the check. No physics here.
"""

from __future__ import annotations

from clearjoint.errors import ParameterError

__all__ = ["LIMIT_S", "SECONDS_PER", "check_budget", "estimate_s", "for_people"]

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
}


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


def check_budget(count: int, kind: str, *, option: str, allow: str = "--allow-long") -> None:
    """Refuse ``count`` units of ``kind`` (given by ``option``) if they would take too long.

    Raises
    ------
    ParameterError
        The estimate exceeds :data:`LIMIT_S`; the message gives the estimate, the limit,
        and ``allow``, the option that runs it anyway.
    """
    seconds = estimate_s(count, kind)
    if seconds > LIMIT_S:
        each = SECONDS_PER[kind]
        raise ParameterError(
            f"{option} {count}: about {for_people(seconds)} of computing "
            f"({each:g} s per {kind}), above the limit of {for_people(LIMIT_S)}; "
            f"ask for fewer, or pass {allow} to run it anyway"
        )
