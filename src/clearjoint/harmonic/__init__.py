"""Harmonic balance (AFT) with continuation, Hill stability and nonlinear modes (MODEL.md 5.3-5.4).

``frequency_response`` gives the same :class:`~clearjoint.periodic.FrequencyResponse`
as the exact shooting of :mod:`clearjoint.periodic`, approximately but for any
structure; ``nonlinear_modes`` gives each mode's frequency and damping against
amplitude (EPMC).
"""

from clearjoint.harmonic.modes import NonlinearMode, nonlinear_modes
from clearjoint.harmonic.response import frequency_response
from clearjoint.harmonic.system import HarmonicError

__all__ = ["HarmonicError", "NonlinearMode", "frequency_response", "nonlinear_modes"]
