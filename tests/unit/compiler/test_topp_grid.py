"""TOPP-RA's grid (:func:`aou_dsl.compiler.topp.grid`) from its definition: the uniform
points, the waypoints and the speed cap's points, sorted, where a point closer than a
nanometre to the point kept before it (or to the end) is dropped. When no point is that
close the sorted points come back as they are, at once; when some are, they go."""

from __future__ import annotations

import numpy as np

from aou_dsl.compiler.topp import grid


def _points(s_way, gridpoints, a, vmax) -> np.ndarray:
    """Every candidate point, sorted, before any is dropped."""
    length = float(s_way[-1])
    reach = vmax * vmax / (2.0 * a)
    extra = np.linspace(0.0, reach, 5)[1:] if 0.0 < reach < length / 2.0 else np.empty(0)
    return np.unique(np.concatenate([np.linspace(s_way[0], length, gridpoints), s_way,
                                     extra, length - extra]))


def _holds_the_definition(g: np.ndarray, points: np.ndarray, tol: float) -> None:
    assert g.dtype == np.float64
    assert g[0] == points[0] and g[-1] == points[-1]  # both ends always kept
    assert np.isin(g, points).all()  # nothing made up
    assert (np.diff(g) > tol).all()  # nothing close left
    # every point dropped was within the tolerance of the one kept before it, or the end
    for x in np.setdiff1d(points, g):
        before = g[np.searchsorted(g, x) - 1]
        assert x - before <= tol or g[-1] - x <= tol


def test_the_grid_keeps_every_point_when_none_is_close_and_drops_the_close_ones():
    rng = np.random.default_rng(2)
    cases = [(np.linspace(0.0, 0.2, 41), 80, 0.05, 0.3),
             (np.linspace(0.0, 0.06, 13), 80, 0.12, 0.05),
             (np.array([0.0, 0.1, 0.1 + 4e-10, 0.2]), 5, 1.0, 1.0),  # a close pair
             (np.array([0.0, 0.1, 0.2 - 3e-10, 0.2]), 5, 1.0, 1.0)]  # close to the end
    for _ in range(30):
        s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.001, 0.01, 30))])
        s[rng.integers(1, 30)] += 1e-10 * rng.choice([-1.0, 1.0])
        cases.append((s, 80, float(rng.uniform(0.01, 1.0)), float(rng.uniform(0.01, 1.0))))
    dropped = 0
    for case in cases:
        points, tol = _points(*case), 1e-9 * max(float(case[0][-1]), 1.0)
        g = grid(*case)
        _holds_the_definition(g, points, tol)
        close = bool((np.diff(points) <= tol).any())
        assert (len(g) < len(points)) == close  # all kept exactly when none is close
        dropped += close
    assert dropped >= 2  # the close cases were made


def test_a_path_of_no_length_is_its_one_point_twice():
    assert grid(np.array([0.0, 0.0]), 3, 1.0, 1.0).tolist() == [0.0, 0.0]
