#!/usr/bin/env python3
"""The randomly shifted Korobov lattice's variance on a contained anisotropic Gaussian, summed
over the dual lattice with numpy, independently of specvar: Var = sum over k != 0 with
k_0 + a k_1 = 0 (mod N) of |f^(k)|^2, f^(k) = 2 pi s1 s2 exp(-2 pi^2 k' S k) for the lobe of
widths s1 (at angle theta) and s2 centred in the square (its images across the faces are below
e^-50 of its peak). Prints the variance for the cases of tests/suite/dual_lattice.rs.

    python3 -m venv /tmp/v && /tmp/v/bin/pip install numpy && /tmp/v/bin/python tests/exact/korobov_agaussian.py
"""
import math

import numpy as np


def dual_variance(n, a, s1, s2, theta, reach=400):
    t = math.radians(theta)
    u, v = np.array([math.cos(t), math.sin(t)]), np.array([-math.sin(t), math.cos(t)])
    cov = s1 ** 2 * np.outer(u, u) + s2 ** 2 * np.outer(v, v)
    integral = 2 * math.pi * s1 * s2
    k1 = np.arange(-reach, reach + 1)
    r = (-a * k1) % n
    total = 0.0
    for shift in range(-(reach // n) - 2, reach // n + 3):
        k0 = r + shift * n
        keep = (np.abs(k0) <= reach) & ((k0 != 0) | (k1 != 0))
        k = np.stack([k0[keep], k1[keep]], axis=1).astype(float)
        q = np.einsum("ij,jk,ik->i", k, cov, k)
        total += np.sum(np.sort(integral ** 2 * np.exp(-4 * math.pi ** 2 * q)))
    return total


for n, a in [(1024, 271)]:
    print(n, a, repr(dual_variance(n, a, 0.05, 0.02, 30.0)))
