"""Exact, event-driven time-domain simulation of the forced clearance joint.

``steady_state``, ``time_response`` and ``frequency_sweep`` advance the motion
state by state in closed form (see :mod:`clearjoint.exact`); ``reference_time_response``
solves the same equations with scipy's solve_ivp and event location, as a
cross-check. MODEL.md sec. 1-2. The results they return (``Motion``, ``SteadyState``,
``FrequencySweep``, ...) live in :mod:`clearjoint.results` and are re-exported here.
"""

from clearjoint.results import EnergyLedger, FrequencySweep, Motion, Stage, SteadyState
from clearjoint.simulate.core import SimulationError, frequency_sweep, steady_state, time_response

__all__ = [
    "EnergyLedger",
    "FrequencySweep",
    "Motion",
    "SimulationError",
    "Stage",
    "SteadyState",
    "frequency_sweep",
    "steady_state",
    "time_response",
]
