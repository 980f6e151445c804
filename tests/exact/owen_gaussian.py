"""The variance of a (0,m,2)-net in base 2 under nested uniform scrambling on a truncated
Gaussian, in 40-digit arithmetic (mpmath).

For f(x) = g_1(x_1) g_2(x_2), g_l(x) = exp(-(x - c_l)^2 / (2 s^2)) on [0, 1)^2, the variance is
(1/N) sum_{k != 0} Gamma_k delta_1(k_1) delta_2(k_2) (Owen 1997), with delta_l(a) the energy of
g_l at dyadic level a: delta(0) = (int g)^2 and, for a >= 1, 2^(a-1) sum_j (m_2j - m_2j+1)^2 over
the masses m_i of g on the 2^a cells of level a, here from erf at 40 digits. A (0,m,2)-net's
gains follow from its cells' occupancies alone: Gamma_k = 0 for k_1 + k_2 <= m, 2 for
k_1 + k_2 = m + 1 with both k_l >= 1, and 1 otherwise. The levels beyond those computed enter
through T(b) = sum_{a >= b} delta(a) = int g^2 - sum_{a < b} delta(a), whose subtraction
keeps its digits at this precision.

`tests/suite/owen_gains.rs` compares `predict -s sobol|pmj02 -n 2^m -f gaussian:sigma=0.2,c=0.2;0.7`
with the values printed here: `python3 tests/exact/owen_gaussian.py 20` (mpmath, 2^22 error
functions: about a minute with gmpy2) prints 6.9921935244021339169e-18.
"""
import sys

import mpmath as mp

mp.mp.dps = 40
SIGMA = mp.mpf("0.2")
CENTRE = [mp.mpf("0.2"), mp.mpf("0.7")]


def axis(c, top):
    """delta(a) for a = 0..top, and T(b) for b <= top + 1."""
    k = SIGMA * mp.sqrt(2)
    n = 2**top
    erf = [mp.erf((mp.mpf(i) / n - c) / k) for i in range(n + 1)]
    row = [(erf[i + 1] - erf[i]) * SIGMA * mp.sqrt(mp.pi / 2) for i in range(n)]
    delta = {}
    a = top
    while len(row) > 1:
        half = len(row) // 2
        delta[a] = half * mp.fsum((row[2 * j] - row[2 * j + 1]) ** 2 for j in range(half))
        row = [row[2 * j] + row[2 * j + 1] for j in range(half)]
        a -= 1
    delta[0] = row[0] ** 2
    # int_0^1 g^2, g^2 a Gaussian of deviation s / sqrt(2).
    energy = SIGMA / mp.sqrt(2) * mp.sqrt(mp.pi / 2) * (mp.erf((1 - c) / SIGMA) + mp.erf(c / SIGMA))
    return delta, lambda b: energy - mp.fsum(delta[x] for x in range(b))


def variance(m):
    top = m + 1
    (d1, t1), (d2, t2) = axis(CENTRE[0], top), axis(CENTRE[1], top)
    total = mp.mpf(0)
    for k1 in range(top + 1):
        for k2 in range(top + 1):
            if k1 + k2 == 0 or k1 + k2 > m + 1:
                continue
            gain = 0 if k1 + k2 <= m else (2 if k1 > 0 and k2 > 0 else 1)
            total += gain * d1[k1] * d2[k2]
    # Every level with k1 + k2 >= m + 2 has gain 1.
    for k1 in range(top + 1):
        total += d1[k1] * t2(max(0, m + 2 - k1))
    total += t1(top + 1) * t2(0)
    return total / 2**m


if __name__ == "__main__":
    for m in map(int, sys.argv[1:]):
        print(m, mp.nstr(variance(m), 20))
