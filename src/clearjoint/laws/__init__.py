"""Each law of the joint written once, for numba kernels and numpy code alike.

:mod:`clearjoint.laws.clearance` is the clearance joint's piecewise-linear law of
MODEL.md section 0 and 5.2: its force, tangent stiffness, potential energy, contact
state and the (stiffness, offset) of each state. Every solver takes the law from there.
"""

from __future__ import annotations

from typing import Protocol

__all__ = ["Law", "Spring"]


class Law(Protocol):
    """What the law's array helpers read of a law: a :class:`~clearjoint.ClearanceJoint`.

    Kept here, apart from the compiled :mod:`clearjoint.laws.clearance`, so that code
    without numba (``clearjoint.stiffness``) can name it.
    """

    @property
    def gap_stiffness(self) -> float: ...
    @property
    def compression_stiffness(self) -> float: ...
    @property
    def tension_stiffness(self) -> float: ...
    @property
    def compression_gap(self) -> float: ...
    @property
    def tension_gap(self) -> float: ...


class Spring(Law, Protocol):
    """A law with the mass it carries: a :class:`~clearjoint.Joint`, or its validated values."""

    @property
    def mass(self) -> float: ...
