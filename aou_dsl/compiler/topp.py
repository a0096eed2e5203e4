"""TOPP-RA, as the timing stage uses it: imported lazily (without matplotlib), its
constraints built once per set of limits, its grid fine enough for the declared limits.

:func:`parametrize` returns TOPP-RA's time-optimal law (piecewise constant ``s''``) over
a joint path with the path coordinate appended as a *virtual joint* (see
:mod:`.timing`), or the reason it failed.
"""

from __future__ import annotations

import copy
import importlib
import logging
import sys
import types
from typing import Any

import numpy as np

from ..core.memo import cached
from .timelaw import TimeLaw

__all__ = ["grid", "import_toppra", "parametrize"]


class _LazyModule(types.ModuleType):
    """Stands in for a module until one of its attributes is used, then imports it."""

    def __getattr__(self, attr: str):
        module = importlib.import_module(self.__name__)  # safe: its own name, toppra
        return getattr(module, attr)


@cached(maxsize=1)
def import_toppra():
    """toppra, imported without matplotlib.

    toppra's algorithm module imports ``matplotlib.pyplot`` at its top, for plotting
    helpers aou never calls; that import costs every compile a fraction of a second. While
    toppra is imported, lazy stand-ins take matplotlib's place in ``sys.modules``; they
    are removed right after, so a later ``import matplotlib`` (``aouc plot``) is the real
    one, and toppra's own reference imports it only if it is ever used.
    """
    stubs: dict[str, types.ModuleType] = {}
    if "matplotlib" not in sys.modules:
        stubs["matplotlib"] = _LazyModule("matplotlib")
        stubs["matplotlib.pyplot"] = _LazyModule("matplotlib.pyplot")
        setattr(stubs["matplotlib"], "pyplot", stubs["matplotlib.pyplot"])  # noqa: B010
        sys.modules.update(stubs)
    try:
        import toppra
        import toppra.algorithm  # noqa: F401
        import toppra.constraint  # noqa: F401
    finally:
        for name, stub in stubs.items():
            if sys.modules.get(name) is stub:
                del sys.modules[name]
    logging.getLogger("toppra").setLevel(logging.ERROR)
    # Every TOPP-RA instance asks which solvers are installed, by searching the import
    # path for two optional packages (a millisecond): the answer cannot change while the
    # process runs, so it is asked once.
    wrappers = toppra.solverwrapper
    available = wrappers.available_solvers(output_msg=False)
    wrappers.available_solvers = lambda output_msg=True: available
    return toppra


@cached(maxsize=256)
def _constraints(jv: tuple[float, ...], ja: tuple[float, ...], a: float, vmax: float):
    """TOPP-RA's joint velocity and acceleration constraints, the virtual joint last.
    They do not depend on the path, so they are made once per set of limits; and since
    every new motion has its own virtual limits, those are copies of the joints' own
    (:func:`_joint_constraints`) with the limits set: toppra's constructors describe the
    limits as text with numpy's printer, about half a millisecond a pair, for a
    ``repr`` aou never shows. The copies hold the same limits, so the same law comes
    out; their text is written with Python's float format."""
    vlim = np.column_stack([-np.append(jv, vmax), np.append(jv, vmax)])
    alim = np.column_stack([-np.append(ja, a), np.append(ja, a)])
    if np.isnan(vlim).any() or np.isnan(alim).any() or np.any(vlim[:, 0] >= vlim[:, 1]):
        constraint = import_toppra().constraint  # refused by toppra's own checks
        return (constraint.JointVelocityConstraint(vlim),
                constraint.JointAccelerationConstraint(alim))
    velocity, acceleration = (copy.copy(c) for c in _joint_constraints(jv, ja))
    velocity.vlim, acceleration.alim = vlim, alim
    velocity._format_string = _described("Velocity", vlim)
    acceleration._format_string = _described("Acceleration", alim)
    return velocity, acceleration


@cached(maxsize=64)
def _joint_constraints(jv: tuple[float, ...], ja: tuple[float, ...]):
    """toppra's own constraints of the joints' limits, with a virtual joint limited to
    1 (:func:`_constraints` copies them with its limits)."""
    constraint = import_toppra().constraint
    return (constraint.JointVelocityConstraint(
                np.column_stack([-np.append(jv, 1.0), np.append(jv, 1.0)])),
            constraint.JointAccelerationConstraint(
                np.column_stack([-np.append(ja, 1.0), np.append(ja, 1.0)])))


def _described(what: str, lim: np.ndarray) -> str:
    """A constraint's limits as toppra's ``repr`` shows them, one joint a line."""
    return f"    {what} limit: \n" + "".join(
        f"      J{i}: [{lo!r} {hi!r}]\n" for i, (lo, hi) in enumerate(lim.tolist(), 1))


@cached(maxsize=1)
def _lean_toppra():
    """toppra's ``TOPPRA`` whose two per-stage steps (the backward pass's controllable
    set, the forward pass's greedy step) skip their per-call allocations and checks, and
    whose two passes keep their running values in Python floats instead of reading and
    writing array elements one at a time: the same solver calls with the same arguments
    in the same order (the seidel solver warm-starts from its previous call), the same
    arithmetic, so the same law to the last bit, and the same refusals; about a third
    faster on aou's paths. ``tests/integration/test_speed_props.py`` compares the two."""
    stock: Any = import_toppra().algorithm.TOPPRA  # an untyped library's class
    ra: types.ModuleType = sys.modules[stock.__mro__[1].__module__]  # its passes' constants
    nan = float("nan")

    class LeanTOPPRA(stock):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            # The linear objectives: the controllable set's upper and lower ends, and
            # per stage the forward step's (``-2 delta_i u - x``).
            sw = self.solver_wrapper
            self._upper = np.zeros(sw.get_no_vars())
            self._upper[0], self._upper[1] = 1e-9, -1
            self._lower = -self._upper
            self._forward = np.zeros((sw.get_no_stages(), sw.get_no_vars()))
            self._forward[:, 1] = -1
            self._forward[:, 0] = -2 * sw.get_deltas()
            self._solve = sw.solve_stagewise_optim

        def _one_step(self, i, K_next):
            lo, hi = K_next[0], K_next[1]
            if lo != lo or hi != hi or i < 0 or i > self._N:  # a NaN bound
                return np.array([nan, nan])
            x_upper = self._solve(i, None, self._upper, nan, nan, lo, hi)[1]
            x_lower = self._solve(i, None, self._lower, nan, nan, lo, hi)[1]
            return np.array([x_lower, x_upper])

        def _forward_step(self, i, x, K_next):
            if i < 0 or i > self._N or x is None or x != x:
                return np.array([nan, nan])
            return self._solve(i, None, self._forward[i], x, x, K_next[0], K_next[1])

        def compute_controllable_sets(self, sdmin, sdmax):
            # toppra's backward pass, its set kept in floats while it runs (not read
            # and written an element at a time in an array): the same calls, the same
            # numbers. Stops at a NaN set as toppra does, the rows after it left 0.
            assert sdmin <= sdmax and 0 <= sdmin
            n = self._N
            K = np.zeros((n + 1, 2))
            K[n] = [sdmin ** 2, sdmax ** 2]
            lo, hi = K[n, 0], K[n, 1]
            solve, upper, lower = self._solve, self._upper, self._lower
            self.solver_wrapper.setup_solver()
            rows = []
            for i in range(n - 1, -1, -1):
                if lo != lo or hi != hi:
                    lo = hi = nan
                else:
                    x_upper = solve(i, None, upper, nan, nan, lo, hi)[1]
                    lo, hi = solve(i, None, lower, nan, nan, lo, hi)[1], x_upper
                if lo < 0:
                    lo = 0.0
                rows.append((lo, hi))
                if lo != lo or hi != hi:
                    K[i:n] = rows[::-1]
                    return K
            self.solver_wrapper.close_solver()
            K[:n] = rows[::-1]
            return K

        def compute_parameterization(self, sd_start, sd_end, return_data=False):
            # toppra's, with the forward pass's velocities and accelerations kept in
            # floats while it runs: the same steps, the same numbers.
            if sd_end < 0 or sd_start < 0:
                return super().compute_parameterization(sd_start, sd_end, return_data)
            K = self.compute_controllable_sets(sd_end, sd_end)
            codes = ra.ParameterizationReturnCode
            if np.isnan(K).any():  # not controllable: toppra's failure, as it gives it
                self._problem_data.return_code = codes.FailUncontrollable
                return (None, None, None, K) if return_data else (None, None, None)
            self._problem_data.K = K
            x_start = sd_start ** 2
            if x_start + ra.SMALL < K[0, 0] or K[0, 1] + ra.SMALL < x_start:
                self._problem_data.return_code = codes.FailUncontrollable
                return (None, None, None, K) if return_data else (None, None, None)
            sw = self.solver_wrapper
            n, deltas, forward = sw.get_no_stages(), sw.get_deltas().tolist(), self._forward
            extra = sw.get_no_vars() - 2
            v_vec = np.zeros((n, extra))
            k_lo, k_hi = K[:, 0].tolist(), K[:, 1].tolist()
            xs, us = [x_start] + [0.0] * n, [0.0] * n
            tries = 0
            sw.setup_solver()
            i = 0
            while i < self._N:
                x = xs[i]
                res = (np.array([nan, nan]) if x is None or x != x else
                       self._solve(i, None, forward[i], x, x, k_lo[i + 1], k_hi[i + 1]))
                if res[0] != res[0]:
                    if tries < ra.MAX_TRIES:
                        xs[i] = max(x - ra.TINY, 0.999 * x)
                        tries += 1
                    else:
                        xs[i + 1:] = [nan] * (n - i)
                        break
                else:
                    tries = 0
                    us[i] = u = float(res[0])
                    x_next = x + 2 * deltas[i] * u
                    x_next = max(x_next - ra.TINY, 0.9999 * x_next)
                    xs[i + 1] = min(k_hi[i + 1], max(k_lo[i + 1], x_next))
                    if extra:
                        v_vec[i] = res[2:]
                    i += 1
            sw.close_solver()
            sd_vec = np.sqrt(np.array(xs, dtype=float))
            sdd_vec = np.array(us, dtype=float)
            self._problem_data.sd_vec = sd_vec
            self._problem_data.sdd_vec = sdd_vec
            self._problem_data.return_code = (codes.ErrUnknown if np.isnan(sd_vec).any()
                                              else codes.Ok)
            if return_data:
                return sdd_vec, sd_vec, v_vec, K
            return sdd_vec, sd_vec, v_vec

    return LeanTOPPRA


def grid(s_way: np.ndarray, gridpoints: int, a: float, vmax: float) -> np.ndarray:
    """TOPP-RA's grid over the path coordinate, shape (G,), increasing.

    A uniform grid plus every waypoint: the spline's second derivative is piecewise
    linear, so its extremes sit at the waypoints (knots), which the grid must include.
    TOPP-RA's ``s''`` is constant on each interval, so when the speed cap is reached
    after ``v^2 / 2a`` (often shorter than one uniform step), the grid also holds that
    point and a few before it, from both ends: the accelerating phase then runs at
    exactly ``a`` instead of being averaged over a whole interval.
    """
    length = float(s_way[-1])
    pts = [np.linspace(s_way[0], length, gridpoints), s_way]
    reach = vmax * vmax / (2.0 * a)
    if 0.0 < reach < length / 2.0:
        inner = np.linspace(0.0, reach, 5)[1:]
        pts += [inner, length - inner]
    g = np.unique(np.concatenate(pts))
    # Points closer than a nanometre (or nanoradian) would make degenerate intervals.
    tol = 1e-9 * max(length, 1.0)
    if len(g) >= 2 and np.all(np.diff(g[:-1]) > tol) and g[-1] - g[-2] > tol:
        return g  # none is: the loop below would keep every point
    out = [g[0]]
    for x in g[1:-1]:
        if x - out[-1] > tol and g[-1] - x > tol:
            out.append(x)
    out.append(g[-1])
    return np.array(out)


def parametrize(s_way: np.ndarray, q_way: np.ndarray, a: float, vmax: float,
                gridpoints: int, jv: np.ndarray, ja: np.ndarray):
    """TOPP-RA's rest-to-rest law over the joint path through ``q_way`` (shape (K, n)).

    Args:
        jv, ja: joint velocity and acceleration limits, shape (n,).
        a, vmax: the virtual joint's limits (path acceleration and speed).

    Returns:
        ``(law, spline, None)`` on success, where ``spline`` is the path (joints and the
        virtual coordinate last); ``(None, None, reason)`` when TOPP-RA fails.
    """
    toppra = import_toppra()
    algo = toppra.algorithm
    aug = np.column_stack([q_way, s_way])
    path = toppra.SplineInterpolator(s_way, aug)
    g = grid(s_way, gridpoints, a, vmax)
    inst = _lean_toppra()(list(_constraints(tuple(jv), tuple(ja), a, vmax)),
                          path, gridpoints=g, solver_wrapper="seidel")
    try:
        _, sd, _, _ = inst.compute_parameterization(0.0, 0.0, return_data=True)
    except Exception as exc:  # toppra raises bare exceptions on degenerate input
        return None, None, f"TOPP-RA failed: {exc}"
    if inst.problem_data.return_code != algo.ParameterizationReturnCode.Ok or sd is None:
        return None, None, f"TOPP-RA: {inst.problem_data.return_code}"
    sd = np.asarray(sd, dtype=float)
    sd[0] = sd[-1] = 0.0
    try:
        law = TimeLaw.from_speeds(g, sd)
    except ValueError:  # the path speed is zero inside the path: no motion can follow it
        return None, None, "TOPP-RA: the path speed drops to zero inside the path"
    return law, path.cspl, None
