"""The exact, event-driven flow every exact solver is built on (MODEL.md sec. 2, 5.1-5.2).

- :mod:`clearjoint.exact.kernel`: the single joint's motion, state by state in closed
  form, compiled (its parameter vector, events, certified marching, energy ledger);
- :mod:`clearjoint.exact.single`: that kernel set up for a Joint, run, and turned into the
  fields of a Motion or the SteadyState of an orbit;
- :mod:`clearjoint.exact.shooting`: the exact stroboscopic map over p forcing periods, its
  monodromy (with saltation at every event) and Newton and arclength steps on it;
- :mod:`clearjoint.exact.march`: a structure's exact motion, event by event, compiled.

The public solvers sit on top: :mod:`clearjoint.simulate` (time response, steady state,
frequency sweep), :mod:`clearjoint.periodic` (exact orbits and curves by shooting) and
:mod:`clearjoint.structure` (a structure's exact motion and free decay).
"""
