"""How stiff is my joint at this amplitude? And what amplitude will this force give?"""

import math

import numpy as np

from clearjoint import Joint
from clearjoint import stiffness as sk

joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
amplitudes = np.array([1e-6, 5e-6, 20e-6, 100e-6])  # penetration beyond the gap edge, m
print("k_d (N/m):", sk.dynamic_stiffness(joint, amplitudes))
print("c_d:      ", sk.stiffness_coefficient(joint, amplitudes))
print("f_n (Hz): ", sk.natural_frequency(joint, amplitudes) / (2 * math.pi))

# eq 7: every steady amplitude under 800 N at 400 Hz, with 1 % damping
for branch in sk.equivalent_linear_response(joint, 800.0, 2 * math.pi * 400.0, 0.01):
    print(branch)
