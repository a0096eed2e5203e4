"""TOPP-RA as the compiler runs it (its lean solver, its constraints copied from each
joint set's own with the virtual joint's limits set) gives toppra's own law to the bit,
and limits toppra refuses are refused as toppra refuses them."""

from __future__ import annotations

import numpy as np
import pytest

from aou_dsl.compiler.topp import _constraints, _lean_toppra, grid, import_toppra
from aou_dsl.robot.load import load_arm


def _path(rng: np.random.Generator, n: int):
    s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.02, 0.1, 6))])
    q = np.cumsum(rng.normal(0.0, 0.05, (len(s), n)), axis=0)
    return s, q


@pytest.mark.parametrize("seed", range(6))
def test_the_compilers_topp_ra_is_toppras_own(seed):
    toppra = import_toppra()
    arm = load_arm("panda")
    rng = np.random.default_rng(seed)
    s, q = _path(rng, arm.n)
    jv, ja = tuple(arm.plan_vmax * rng.uniform(0.3, 1.0)), tuple(arm.plan_amax)
    for a, vmax in ((rng.uniform(0.05, 3.0), rng.uniform(0.05, 1.0)), (0.4, 0.2)):
        path = toppra.SplineInterpolator(s, np.column_stack([q, s]))
        g = grid(s, 80, a, vmax)
        vlim = np.column_stack([-np.append(jv, vmax), np.append(jv, vmax)])
        alim = np.column_stack([-np.append(ja, a), np.append(ja, a)])
        stock = toppra.algorithm.TOPPRA(
            [toppra.constraint.JointVelocityConstraint(vlim),
             toppra.constraint.JointAccelerationConstraint(alim)],
            path, gridpoints=g, solver_wrapper="seidel")
        ours = _lean_toppra()(list(_constraints(jv, ja, a, vmax)), path, gridpoints=g,
                              solver_wrapper="seidel")
        want = stock.compute_parameterization(0.0, 0.0, return_data=True)[1]
        got = ours.compute_parameterization(0.0, 0.0, return_data=True)[1]
        assert want is not None and np.array_equal(got, want)
        vel, acc = _constraints(jv, ja, a, vmax)
        assert np.array_equal(vel.vlim, vlim) and np.array_equal(acc.alim, alim)
        assert f"J{arm.n + 1}: [{-vmax!r} {vmax!r}]" in repr(vel)


@pytest.mark.parametrize("vmax", [0.0, -1.0, float("nan")])
def test_limits_toppra_refuses_are_refused(vmax):
    jv, ja = (2.0,) * 7, (10.0,) * 7
    with pytest.raises(ValueError):
        _constraints(jv, ja, 1.0, vmax)
