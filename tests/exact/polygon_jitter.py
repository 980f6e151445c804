"""The unshifted jitter variance of a triangle's indicator in exact rational arithmetic.

Jitter with M x M strata has variance (1/N^2) sum_c V_c, N = M^2, and on an indicator a cell's
inner variance is p(1 - p) for the fraction p of it the triangle covers, 0 on the cells its
boundary does not touch. Each touched cell is clipped by the triangle in fractions.Fraction, so
the sum is exact for the triangle's vertices as doubles (0.1, 0.2; 0.8, 0.1; 0.4, 0.9) and the
strata's edges i/M. `tests/suite/unshifted.rs` compares `predict -s jitter` with the values printed
here: `python3 tests/exact/polygon_jitter.py 10000` prints 3.9432749433e-13 (15 s).
"""
import math
import sys
from fractions import Fraction

VERTICES = [(Fraction(x), Fraction(y)) for x, y in [(0.1, 0.2), (0.8, 0.1), (0.4, 0.9)]]


def clip(polygon, axis, bound, keep_below):
    """The part of a convex polygon on one side of the line x[axis] = bound."""
    out = []
    for i, a in enumerate(polygon):
        b = polygon[(i + 1) % len(polygon)]
        a_in = a[axis] <= bound if keep_below else a[axis] >= bound
        b_in = b[axis] <= bound if keep_below else b[axis] >= bound
        if a_in:
            out.append(a)
        if a_in != b_in:
            t = (bound - a[axis]) / (b[axis] - a[axis])
            out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
    return out


def area(polygon):
    twice = sum(a[0] * b[1] - b[0] * a[1]
                for a, b in zip(polygon, polygon[1:] + polygon[:1]))
    return abs(twice) / 2


def touched_cells(m):
    """Every cell an edge passes through, with a cell of margin: the rest are 0 or 1."""
    cells = set()
    for k, a in enumerate(VERTICES):
        b = VERTICES[(k + 1) % len(VERTICES)]
        lo_x, hi_x = min(a[0], b[0]), max(a[0], b[0])
        for i in range(max(0, math.floor(lo_x * m) - 1), min(m - 1, math.floor(hi_x * m) + 1) + 1):
            x0, x1 = Fraction(i, m), Fraction(i + 1, m)
            if hi_x < x0 or lo_x > x1:
                continue
            y_at = lambda x: a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
            ys = (y_at(max(x0, lo_x)), y_at(min(x1, hi_x)))
            for j in range(max(0, math.floor(min(ys) * m) - 1), min(m - 1, math.floor(max(ys) * m) + 1) + 1):
                cells.add((i, j))
    return cells


def variance(m):
    total = Fraction(0)
    for i, j in touched_cells(m):
        part = VERTICES
        for axis, bound, below in [(0, Fraction(i, m), False), (0, Fraction(i + 1, m), True),
                                   (1, Fraction(j, m), False), (1, Fraction(j + 1, m), True)]:
            if len(part) >= 3:
                part = clip(part, axis, bound, below)
        p = area(part) * m * m if len(part) >= 3 else 0
        total += p - p * p
    n = m * m
    return total / (n * n)


if __name__ == "__main__":
    print("%.10e" % float(variance(int(sys.argv[1]))))
