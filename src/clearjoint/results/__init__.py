"""The results every solver hands back: one class per concept, whichever solver made it.

A result carries its arrays, a short ``repr`` (a summary, never the arrays),
``.plot(ax=None)`` returning the Axes, ``.to_xarray()`` with each variable's unit
in its attrs, and ``.to_pandas()``. Here are those shared by more than one solver
(or read by one solver from another): the exact motion of a joint
(:class:`Motion`, :class:`SteadyState`, :class:`FrequencySweep`, with
:class:`EnergyLedger` and :class:`Stage`), the exact periodic orbit
(:class:`PeriodicOrbit`) and the frequency-response curve with its events
(:class:`FrequencyResponse`, :class:`ResponseEvent`), the same whether shooting or
harmonic balance made it. Results only one solver makes stay beside it
(``NonlinearMode`` in ``clearjoint.harmonic.modes``, ``StructureMotion`` in
``clearjoint.structure.motion``, ...). No module here imports a solver.
"""

from clearjoint.results.motion import EnergyLedger, FrequencySweep, Motion, Stage, SteadyState
from clearjoint.results.orbit import PeriodicOrbit
from clearjoint.results.response import FrequencyResponse, ResponseEvent

__all__ = [
    "EnergyLedger",
    "FrequencyResponse",
    "FrequencySweep",
    "Motion",
    "PeriodicOrbit",
    "ResponseEvent",
    "Stage",
    "SteadyState",
]
