"""Each law of the joint written once, for numba kernels and numpy code alike.

:mod:`clearjoint.laws.clearance` is the clearance joint's piecewise-linear law of
MODEL.md section 0 and 5.2: its force, tangent stiffness, potential energy, contact
state and the (stiffness, offset) of each state. Every solver takes the law from there.
"""
