"""TOPP-RA's grid drops a point closer than a nanometre to the last one kept (or to the
end); when no point is that close it returns the sorted points as they are, at once:
the same grid as the point-by-point walk, written out here."""

from __future__ import annotations

import numpy as np

from aou_dsl.compiler.topp import grid


def _walked(s_way, gridpoints, a, vmax) -> np.ndarray:
    length = float(s_way[-1])
    pts = [np.linspace(s_way[0], length, gridpoints), s_way]
    reach = vmax * vmax / (2.0 * a)
    if 0.0 < reach < length / 2.0:
        inner = np.linspace(0.0, reach, 5)[1:]
        pts += [inner, length - inner]
    g = np.unique(np.concatenate(pts))
    tol = 1e-9 * max(length, 1.0)
    out = [g[0]]
    for x in g[1:-1]:
        if x - out[-1] > tol and g[-1] - x > tol:
            out.append(x)
    out.append(g[-1])
    return np.array(out)


def test_the_grid_is_the_walked_grid_with_and_without_close_points():
    rng = np.random.default_rng(2)
    cases = [(np.linspace(0.0, 0.2, 41), 80, 0.05, 0.3),
             (np.linspace(0.0, 0.06, 13), 80, 0.12, 0.05),
             (np.array([0.0, 0.1, 0.1 + 4e-10, 0.2]), 5, 1.0, 1.0),  # a close pair
             (np.array([0.0, 0.1, 0.2 - 3e-10, 0.2]), 5, 1.0, 1.0),  # close to the end
             (np.array([0.0, 0.0]), 3, 1.0, 1.0)]  # no length
    for _ in range(30):
        s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.001, 0.01, 30))])
        s[rng.integers(1, 30)] += 1e-10 * rng.choice([-1.0, 1.0])
        cases.append((s, 80, float(rng.uniform(0.01, 1.0)), float(rng.uniform(0.01, 1.0))))
    for case in cases:
        got, want = grid(*case), _walked(*case)
        assert got.dtype == want.dtype and np.array_equal(got, want)
