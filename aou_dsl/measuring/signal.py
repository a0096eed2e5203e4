"""Signal processing for measuring recordings: a uniform clock, the noise, derivatives,
and where motion comes to rest."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["derivatives", "noise", "refine", "refine_noisy", "runs", "uniform"]


def uniform(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resample onto a uniform clock at the median step (exact if already uniform).

    A trajectory whose last step alone is shorter (it ends between two ticks of its
    clock) keeps its samples; the last one is dropped and its time kept by the caller.
    """
    steps = np.diff(t)
    dt = float(np.median(steps))
    if np.allclose(steps[:-1], dt, rtol=1e-6, atol=1e-9):
        if abs(steps[-1] - dt) < 1e-9:
            return t - t[0], q
        return t[:-1] - t[0], q[:-1]
    from scipy.interpolate import CubicSpline

    n = int(math.floor((t[-1] - t[0]) / dt + 1e-9)) + 1
    tu = t[0] + np.arange(n) * dt
    return tu - t[0], CubicSpline(t, q, axis=0)(tu)


def noise(q: np.ndarray) -> float:
    """Joint noise [rad] from the median absolute third difference (robust to motion)."""
    if len(q) < 8:
        return 0.0
    d3 = np.diff(q, n=3, axis=0)
    # For white noise of std s, the third difference has std s * sqrt(20).
    return float(np.median(np.abs(d3)) / 0.6745 / math.sqrt(20.0))


def derivatives(x: np.ndarray, dt: float, window: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, first and second derivative along axis 0: central differences when
    ``window`` <= 2, else a cubic Savitzky-Golay filter of ``window`` samples (odd)."""
    if window <= 2:
        v = np.gradient(x, dt, axis=0)
        return x, v, np.gradient(v, dt, axis=0)
    from scipy.signal import savgol_filter

    w = min(window, len(x) if len(x) % 2 else len(x) - 1)
    return (savgol_filter(x, w, 3, axis=0), savgol_filter(x, w, 3, deriv=1, delta=dt, axis=0),
            savgol_filter(x, w, 3, deriv=2, delta=dt, axis=0))


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    if not mask.any():
        return []
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts = np.flatnonzero(d == 1)
    ends = np.flatnonzero(d == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def refine(t: np.ndarray, speed: np.ndarray, i: int, direction: int, thr: float) -> float:
    """Clean data: the time where the speed reaches zero next to the rest sample ``i``.

    Motion comes to rest (and leaves it) with a nearly constant acceleration, so the speed
    is linear in time there: a line through the few moving samples beside the rest run
    (``direction`` -1: before it, +1: after it), while the speed keeps growing away from
    the rest, is extrapolated to zero. This undoes the one-sample smear of central
    differences.
    """
    idx: list[int] = []
    j = i + direction
    while 0 <= j < len(t) and len(idx) < 6:
        if idx and speed[j] < speed[idx[-1]]:
            break  # no longer moving away from rest
        idx.append(j)
        j += direction
    if len(idx) < 3:
        return float(t[i])
    slope, icpt = np.polyfit(t[idx], speed[idx], 1)
    if slope == 0:
        return float(t[i])
    lo, hi = sorted((float(t[idx[-1]]), float(t[i])))
    return float(np.clip(-icpt / slope, lo, hi))


def refine_noisy(t: np.ndarray, qd: np.ndarray, i: int, direction: int, half: int) -> float:
    """Noisy data: where the motion next to rest sample ``i`` starts or stops.

    The joint moving fastest 0.3 s away is followed back toward the rest: its *signed*
    filtered velocity is linear in time near a constant-deceleration stop and its noise
    averages out, unlike the speed (a maximum of absolute values, biased upward). The
    samples within half a filter window of the rest are skipped (the filter rounds the
    corner there); a line through the next 0.2 s is extrapolated to zero.
    """
    dt = t[1] - t[0]
    far = i + direction * int(round(0.3 / dt))
    if not 0 <= far < len(t):
        return float(t[i])
    j = int(np.argmax(np.abs(qd[far])))
    idx = np.arange(i + direction * half, i + direction * (half + int(round(0.2 / dt))),
                    direction)
    idx = idx[(idx >= 0) & (idx < len(t))]
    if len(idx) < 5:
        return float(t[i])
    slope, icpt = np.polyfit(t[idx], qd[idx, j], 1)
    if slope == 0:
        return float(t[i])
    t0 = -icpt / slope
    lo, hi = sorted((float(t[i]), float(t[idx[0]])))
    # The stop lies between the rest sample and the first sample used, give or take the
    # filter's reach.
    return float(np.clip(t0, lo - half * dt, hi + half * dt))
