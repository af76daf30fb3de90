"""The exceptions clearjoint raises for bad input.

Every error a user can cause is a subclass of :class:`ClearjointError`, and
also of the built-in ``ValueError`` or ``TypeError`` so that generic handlers
still work. Messages name the bad value and what would be valid.
"""

from __future__ import annotations


class ClearjointError(Exception):
    """Base class of every error clearjoint raises on purpose."""


class ParameterError(ClearjointError, ValueError):
    """A physical parameter is out of its valid range (negative, NaN, infinite...)."""


class ParameterTypeError(ClearjointError, TypeError):
    """A parameter has the wrong type (a string where a number is needed...)."""


class OutputExistsError(ClearjointError, FileExistsError):
    """An output file exists and overwriting it was not asked for."""


class SimulationError(ClearjointError, RuntimeError):
    """The simulation could not do what was asked (no steady state, too many events...)."""
