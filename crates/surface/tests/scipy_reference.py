#!/usr/bin/env python3
"""Independent reference for kinpost's B-spline surfaces (crates/surface).

Evaluates the tensor-product cubic spline interpolant of a grid of points
with scipy, one direction at a time, exactly as Li's B-spline paper constructs it
it: data at uniform parameters u_i = i/(m-1), v_j = j/(n-1) (or averaged
chord-length parameters), cubic, knots at the data parameters with the end
ones four-fold, natural end conditions (or not-a-knot, or clamped tangents
from the parabola through the three end points).

scipy's make_interp_spline(k=3, bc_type="natural") builds exactly that
spline: for derivative end conditions it takes the knots
t = [x0]*4 + x[1:-1] + [x_last]*4 (scipy's _augknt), the same open knot vector
as the specification. For "not-a-knot" scipy drops x[1] and x[-2] from the
knots instead; that is the same function (the not-a-knot interpolant is
unique and C3 at those parameters), so values and derivatives agree although
the control nets differ.

The surface S(u, v) = sum_ij L_i(u) M_j(v) P_ij is evaluated, with its
partial derivatives d^a/du^a d^b/dv^b, as: for every grid row i, the spline
through P_i. along v, differentiated b times at v; then the spline along u
through those m values, differentiated a times at u. Both interpolation
operators are linear, so this equals the tensor product.

Usage: scipy_reference.py POINTS.csv ENDS PARAMS < uv-list
  ENDS: natural | not-a-knot | clamped-tangent
  PARAMS: uniform | chord-length
  stdin: lines "u v"; stdout: lines "u v x y z nx ny nz K H k1 k2" (repr).
"""

import csv
import sys

import numpy as np
from scipy.interpolate import make_interp_spline


def read_grid(path):
    rows = {}
    with open(path, newline="") as f:
        for rec in csv.DictReader(f):
            rows[(int(rec["row"]), int(rec["col"]))] = [float(rec[c]) for c in "xyz"]
    m = 1 + max(r for r, _ in rows)
    n = 1 + max(c for _, c in rows)
    grid = np.empty((m, n, 3))
    for (r, c), p in rows.items():
        grid[r, c] = p
    return grid


def params(grid, kind, axis):
    """Parameters along `axis` (0: rows, u; 1: columns, v)."""
    count = grid.shape[axis]
    if kind == "uniform":
        return np.arange(count) / (count - 1)
    lines = np.moveaxis(grid, axis, 0)  # (count, lines, 3)
    chords = np.linalg.norm(np.diff(lines, axis=0), axis=2)  # (count-1, lines)
    cum = np.vstack([np.zeros(chords.shape[1]), np.cumsum(chords, axis=0)])
    t = (cum / cum[-1]).mean(axis=1)
    t[0], t[-1] = 0.0, 1.0
    return t


def bessel_tangents(x, y):
    """Derivatives at both ends of the parabolas through the end points."""

    def d(t0, t1, t2, q0, q1, q2):
        w0 = (2 * t0 - t1 - t2) / ((t0 - t1) * (t0 - t2))
        w1 = (t0 - t2) / ((t1 - t0) * (t1 - t2))
        w2 = (t0 - t1) / ((t2 - t0) * (t2 - t1))
        return w0 * q0 + w1 * q1 + w2 * q2

    if len(x) == 2:
        s = (y[1] - y[0]) / (x[1] - x[0])
        return s, s
    return (
        d(x[0], x[1], x[2], y[0], y[1], y[2]),
        d(x[-1], x[-2], x[-3], y[-1], y[-2], y[-3]),
    )


def spline(x, y, ends):
    if ends == "natural":
        return make_interp_spline(x, y, k=3, bc_type="natural")
    if ends == "not-a-knot":
        return make_interp_spline(x, y, k=3, bc_type="not-a-knot")
    if ends == "clamped-tangent":
        d0, d1 = bessel_tangents(x, y)
        return make_interp_spline(x, y, k=3, bc_type=([(1, d0)], [(1, d1)]))
    raise SystemExit(f"unknown ends {ends}")


def partial(grid, pu, pv, ends, u, v, a, b):
    q = np.array([spline(pv, grid[i], ends)(v, nu=b) for i in range(grid.shape[0])])
    return spline(pu, q, ends)(u, nu=a)


def main():
    path, ends, kind = sys.argv[1:4]
    grid = read_grid(path)
    pu, pv = params(grid, kind, 0), params(grid, kind, 1)
    out = []
    for line in sys.stdin:
        if not line.strip():
            continue
        u, v = (float(t) for t in line.split())
        s = partial(grid, pu, pv, ends, u, v, 0, 0)
        su = partial(grid, pu, pv, ends, u, v, 1, 0)
        sv = partial(grid, pu, pv, ends, u, v, 0, 1)
        suu = partial(grid, pu, pv, ends, u, v, 2, 0)
        suv = partial(grid, pu, pv, ends, u, v, 1, 1)
        svv = partial(grid, pu, pv, ends, u, v, 0, 2)
        cross = np.cross(su, sv)
        n = cross / np.linalg.norm(cross)
        e, f, g = su @ su, su @ sv, sv @ sv
        l_, m_, n_ = suu @ n, suv @ n, svv @ n
        k = (l_ * n_ - m_ * m_) / (e * g - f * f)  # Li (B-spline grinding) eq. 16
        h = (e * n_ - 2 * f * m_ + g * l_) / (2 * (e * g - f * f))
        r = np.sqrt(max(h * h - k, 0.0))
        vals = [u, v, *s, *n, k, h, h + r, h - r]
        out.append(" ".join(repr(float(x)) for x in vals))
    print("\n".join(out))


if __name__ == "__main__":
    main()
