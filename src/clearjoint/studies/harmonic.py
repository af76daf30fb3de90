"""What harmonic balance can carry of a study, refused with the reason and what to do instead.

Harmonic balance (MODEL.md 5.3-5.4) holds a joint's stiffness law, viscous damping and
sliding friction everywhere; it cannot hold an impact (restitution e < 1, MODEL.md eq
16-18) nor friction that acts only in the free play. A study that asks for either is
refused here, before the solver runs, in the words of the study file.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from clearjoint.errors import ParameterError
from clearjoint.structure.model import Structure
from clearjoint.structure.study import StructureStudy
from clearjoint.studies.joint_study import Study

__all__ = [
    "checked_samples",
    "no_orbit",
    "refuse_harmonic_losses",
    "refuse_harmonic_structure",
]

#: What to do instead of harmonic balance, by the command that asked for it.
_EXACT_ROUTE = {
    "frf": "drop --method harmonic (exact shooting carries it)",
    "modes": "follow the forced response instead with clearjoint frf STUDY (exact shooting)",
}


def refuse_harmonic_losses(study: Study, command: str) -> None:
    """Raise ParameterError for a joint study's losses that harmonic balance cannot carry.

    Parameters
    ----------
    study : Study
    command : {"frf", "modes"}
        What asked, for the way round the refusal.

    Raises
    ------
    ParameterError
        Restitution below 1 (an impact), or sliding friction only in the free play.
    """
    exact = _EXACT_ROUTE[command]
    if study.restitution != 1.0:
        raise ParameterError(
            f"{study.source}: [losses] restitution = {study.restitution:g} is an impact, which "
            f"harmonic balance cannot carry; {exact}, or set restitution = 1"
        )
    friction = study.friction
    if friction is None or friction.force <= 0.0:
        return
    if friction.region != "everywhere":
        raise ParameterError(
            f"{study.source}: [losses] friction_region = {friction.region!r} is not carried by "
            f'harmonic balance; {exact}, or set friction_region = "everywhere"'
        )


def refuse_harmonic_structure(study: StructureStudy, command: str) -> None:
    """Raise ParameterError for a structure study's joints harmonic balance cannot carry.

    Raises
    ------
    ParameterError
        A joint with restitution below 1 (an impact).
    """
    s = study.structure
    restitution = (
        [law.restitution for law in s.joint_laws] if isinstance(s, Structure) else s.restitution()
    )
    if any(e != 1.0 for e in restitution):
        value = next(e for e in restitution if e != 1.0)
        raise ParameterError(
            f"{study.source}: [joint] restitution = {value:g} is an impact, which harmonic "
            f"balance ({command}) cannot carry; set restitution = 1, or use clearjoint "
            f"structure {study.source} respond for the exact motion with impacts"
        )


def checked_samples(
    samples: int | None, harmonics: int, names: Mapping[str, str] | None = None
) -> int | None:
    """Return the time samples per period, checked against aliasing; None for the default.

    At least 2 (2H + 1) samples per period, or the joint law's higher harmonics alias
    onto the kept ones (MODEL.md 5.3, AFT).

    Raises
    ------
    ParameterError
        Too few samples for ``harmonics``.
    """
    if samples is None:
        return None
    name = {"samples": "samples", "harmonics": "harmonics", **(names or {})}
    least = 2 * (2 * harmonics + 1)
    if harmonics >= 1 and samples < least:
        raise ParameterError(
            f"{name['samples']} {samples} is too few for {name['harmonics']} {harmonics}: give "
            f"at least 2 (2H + 1) = {least} (fewer alias the joint law's higher harmonics onto "
            f"the kept ones), or leave {name['samples']} out for the default"
        )
    return int(samples)


def no_orbit(exc: Any, source: str, force: float) -> ParameterError:
    """Return the error for a start with no harmonic-balance orbit, with what to do."""
    hz = exc.omega / (2.0 * math.pi)
    reached = (
        f"; following the force up from a small one reached only {exc.reached * force:.3g} N"
        if exc.reached > 0.0
        else ""
    )
    return ParameterError(
        f"{source}: no harmonic-balance orbit at {hz:.6g} Hz and {force:.3g} N{reached}: at this "
        "force the joints may rattle with no periodic orbit (docs/harmonic.md); lower "
        "[excitation] force_amplitude, or start elsewhere (--from), or take the exact motion: "
        f"clearjoint structure {source} respond"
    )
