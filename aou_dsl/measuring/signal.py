"""Signal processing for measuring recordings: continuous joints unwrapped, the noise of
each joint, one uniform clock, and the filters whose windows the noise sets.

A recording is not a compiled trajectory: its clock jitters and drops samples, its
moving joints carry encoder noise while joints that never move are constant to the last
bit, and its positions may be rounded (an encoder's resolution, a fixed number of
decimals). Every threshold of the measurement is derived here from what the data show,
joint by joint (docs/measure.md explains the choices).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.memo import table
from .savgol import savgol, savgol_1d, savgol_rows, savgol_weights

__all__ = [
    "centred_mean",
    "Grid",
    "JointNoise",
    "curvature_gain",
    "filter_at",
    "filters_at",
    "sg_coefficients",
    "joint_noise",
    "line_fit",
    "median0",
    "odd",
    "row_max",
    "row_sum",
    "runs",
    "short_window",
    "slope_gain",
    "smooth",
    "smooth_rows",
    "to_grid",
    "unwrap",
]

#: Slowest joint speed the rest test is meant to resolve [rad/s]; the velocity filter is
#: made just long enough for that, within :data:`MAX_SHORT_WINDOW`.
SPEED_RESOLUTION = 5e-3
#: Longest velocity filter [s]: it still passes the fastest shiver the compiler accepts
#: (about 7 Hz at 1 deg: the filter keeps more than 80 % of that speed).
MAX_SHORT_WINDOW = 0.06
#: A filtered velocity is motion when it exceeds this many times its noise std.
NOISE_SIGMAS = 5.5


def odd(n: float, least: int = 3) -> int:
    """The odd integer nearest ``n``, at least ``least``."""
    k = max(least, int(round(n)))
    return k if k % 2 else k + 1


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    if not mask.any():
        return []
    if mask.all():  # one run: the whole of it (a hold held throughout)
        return [(0, len(mask) - 1)]
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts = np.flatnonzero(d == 1)
    ends = np.flatnonzero(d == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def unwrap(q: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Columns that jump by about a full turn between two samples (a continuous joint
    reported in [-pi, pi)) made continuous; and which columns were. No joint turns by
    pi within one sample, so a jump of more than pi is a wrap."""
    jumps = np.abs(np.diff(q, axis=0)) > math.pi
    cols = [int(j) for j in np.flatnonzero(jumps.any(axis=0))]
    if not cols:
        return q, []
    q = q.copy()
    q[:, cols] = np.unwrap(q[:, cols], axis=0)
    return q, cols


@dataclass(frozen=True)
class JointNoise:
    """Per joint: white noise std [rad or m], resolution (0 when the values are not on a
    grid), and whether the column changes at all."""

    sigma: np.ndarray
    quantum: np.ndarray
    moving: np.ndarray

    @property
    def effective(self) -> np.ndarray:
        """The noise a filter sees: the larger of the white noise and the rounding error
        of the resolution (uniform, std quantum / sqrt(12)); 0 for a still column."""
        return np.where(self.moving, np.maximum(self.sigma, self.quantum / math.sqrt(12.0)),
                        0.0)


def _residuals(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Each sample minus the cubic through its two neighbours on either side (Lagrange
    interpolation at its own time, so any clock works), scaled to the noise's std: for
    white noise of std s the result has std s. Smooth motion leaves almost nothing."""
    idx = np.arange(2, len(t) - 2)
    nb = np.stack([idx - 2, idx - 1, idx + 1, idx + 2])  # (4, K)
    x = t[idx]
    tn = t[nb]
    w = np.ones_like(tn)
    others = np.ones(4, bool)[:, None]
    for m in range(4):  # each neighbour's weight takes the factors of the others in turn
        others[m] = False
        w *= np.divide(x - tn[m], tn - tn[m], out=np.ones_like(tn), where=others)
        others[m] = True
    fit = np.einsum("ak,akj->kj", w, q[nb])
    return (q[idx] - fit) / np.sqrt(1.0 + (w * w).sum(axis=0))[:, None]


def _quantum(col: np.ndarray) -> float:
    """The column's resolution when all its steps are whole multiples of the smallest
    one (positions rounded to an encoder count or to decimals), else 0."""
    d = np.abs(np.diff(col))
    d = d[d > 0]
    if len(d) < 10:
        return 0.0
    step = float(d.min())
    if step <= 1e-12 * max(1.0, float(np.abs(col).max())):
        return 0.0
    return step if _whole(d, step).mean() >= 0.95 else 0.0


def _whole(d: np.ndarray, step: float) -> np.ndarray:
    """Whether each of the steps ``d`` (> 0) is a whole multiple of ``step``."""
    ratio = d / step
    return (np.abs(ratio - np.round(ratio)) < 0.02) & (np.round(ratio) >= 1)


def joint_noise(t: np.ndarray, q: np.ndarray) -> JointNoise:
    """Noise of each joint from its own samples (median absolute residual, robust to
    the motion); the resolution of rounded columns; still columns have neither.

    A build asks it twice of the same samples (its limit check, then its measurement):
    the last few answers are kept by the samples' bytes, and given back as copies."""
    from ..robot.rows import content_key

    key = content_key(t, q)
    kept = _NOISE.get(key)
    if kept is None:
        kept = _joint_noise(np.asarray(t), np.asarray(q))
        _NOISE.put(key, kept)
    return JointNoise(kept.sigma.copy(), kept.quantum.copy(), kept.moving.copy())


#: The last answers of :func:`joint_noise`, by the samples' bytes (a motion's are a
#: few hundred kilobytes).
_NOISE = table("aou_dsl.measuring.signal.joint_noise", 4)


def _joint_noise(t: np.ndarray, q: np.ndarray) -> JointNoise:
    n = q.shape[1]
    moving = np.ptp(q, axis=0) > 0 if len(q) else np.zeros(n, bool)
    sigma = np.zeros(n)
    if len(t) >= 8:
        r = _residuals(t, q)
        sigma = 1.4826 * np.median(np.abs(r), axis=0)
    quantum = np.array([_quantum(q[:, j]) if moving[j] else 0.0 for j in range(n)])
    return JointNoise(np.where(moving, sigma, 0.0), _shared(q, moving, quantum), moving)


def _shared(q: np.ndarray, moving: np.ndarray, quantum: np.ndarray) -> np.ndarray:
    """``quantum`` with a joint that steps too few times to show its own resolution
    given the finest one the other joints show, when every step it takes is a whole
    multiple of it (one encoder resolution for the arm: a joint that barely moves
    still logs its few steps of it, which would otherwise read as motion out of no
    noise)."""
    found = quantum[quantum > 0]
    if not len(found):
        return quantum
    step = float(found.min())
    out = quantum.copy()
    for j in np.flatnonzero(moving & (quantum == 0)):
        d = np.abs(np.diff(q[:, j]))
        d = d[d > 0]
        if 0 < len(d) < 10 and bool(np.all(_whole(d, step))):
            out[j] = step
    return out


@dataclass(frozen=True)
class Grid:
    """Samples on one uniform clock.

    Attributes:
        t: times from the first sample [s], (N,).
        q: joint positions, (N, n).
        h: the step [s].
        density: distinct raw samples per grid step around each grid point (1 for a
            uniform recording; under 1 across a logging gap), (N,).
        t_last: the recording's last time [s] (may lie after ``t[-1]``).
        resampled: whether the recording's own clock was not uniform.
    """

    t: np.ndarray
    q: np.ndarray
    h: float
    density: np.ndarray
    t_last: float
    resampled: bool


def to_grid(t: np.ndarray, q: np.ndarray, window: float) -> Grid:
    """The recording on a uniform clock at its median step.

    A uniform clock is kept as is (a shorter last step is allowed: compiled trajectories
    end between two ticks; that sample is dropped and its time kept as ``t_last``).
    Otherwise the joints are interpolated linearly: a spline through noisy samples
    taken 0.04 ms apart overshoots, a straight line cannot. ``window`` [s] is the span
    over which the raw sample density is counted.
    """
    t = t - t[0]
    steps = np.diff(t)
    h = float(median0(steps))  # np.median's number (a checked clock: finite)
    t_last = float(t[-1])
    if _uniform(steps[:-1], h):
        ones = np.ones(len(t))
        if abs(steps[-1] - h) < 1e-9 or len(t) < 4:
            return Grid(t, q, h, ones, t_last, False)
        return Grid(t[:-1], q[:-1], h, ones[:-1], t_last, False)
    n = int(math.floor(t_last / h + 1e-9)) + 1
    tg = np.arange(n) * h
    qg = np.empty((n, q.shape[1]))
    for j in range(q.shape[1]):
        qg[:, j] = np.interp(tg, t, q[:, j])
    # The raw samples the interpolation actually uses around each grid point (bunched
    # samples share one grid step, a gap leaves many steps on two samples).
    used = np.searchsorted(t, tg, "right")
    fresh = np.concatenate([[1], (np.diff(used) > 0).astype(int)])
    total = np.concatenate([[0], np.cumsum(fresh)])
    half = max(int(round(window / h)), 3) // 2
    lo = np.clip(np.arange(n) - half, 0, n)
    hi = np.clip(np.arange(n) + half + 1, 0, n)
    density = (total[hi] - total[lo]) / (hi - lo)
    return Grid(tg, qg, h, np.maximum(density, 1.0 / (2 * half + 1)), t_last, True)


def _uniform(steps: np.ndarray, h: float) -> bool:
    """``np.allclose(steps, h, rtol=1e-6, atol=1e-9)`` of finite ``steps``: whether each
    differs from ``h`` by at most ``1e-9 + 1e-6 * |h|`` (the same bound, in the same
    arithmetic; a step equal to ``h`` is within it), so whether the largest does."""
    return float(np.abs(steps - h).max()) <= 1e-9 + 1e-6 * abs(h)


def smooth(x: np.ndarray, window: int, deriv: int, h: float, order: int = 3,
           exact: bool = True) -> np.ndarray:
    """A Savitzky-Golay filter along axis 0: the value (``deriv`` 0) or a derivative of
    the local polynomial of degree ``order`` through ``window`` samples. Window 3 is the
    central difference. Near the ends the polynomial is fitted to the first or last
    window. Not ``exact``: a 1-D ``x`` is summed in NumPy's own order, the same to
    rounding and faster (:func:`.savgol.savgol_1d`; for a recording, whose noise is
    far above the rounding)."""
    n = len(x)
    w = min(window, n if n % 2 else n - 1)
    if w < 3:
        return np.gradient(x, h, axis=0) if deriv == 1 else (
            x if deriv == 0 else np.zeros_like(x))
    if not exact:
        return savgol_1d(x, w, min(order, w - 1), deriv, h)
    return savgol(x, w, min(order, w - 1), deriv, h)


def smooth_rows(x: np.ndarray, window: int, deriv: int, h: float, start: int, stop: int,
                order: int = 3) -> np.ndarray:
    """``smooth(x, window, deriv, h, order)[start:stop]``, the same numbers, computing
    only those rows (a long recording's filter asked for a few stretches of it)."""
    n = len(x)
    w = min(window, n if n % 2 else n - 1)
    if w < 3:
        return smooth(x, window, deriv, h, order)[start:stop]
    return savgol_rows(x, w, min(order, w - 1), deriv, h, start, stop)


def sg_coefficients(window: int, order: int, deriv: int, h: float) -> np.ndarray:
    """The Savitzky-Golay filter's weights for the centre sample (cached by
    :func:`~.savgol.savgol_weights`, read-only)."""
    return savgol_weights(window, min(order, window - 1), deriv, h)


def filter_at(x: np.ndarray, window: int, deriv: int, h: float, at: np.ndarray,
              order: int = 3) -> np.ndarray:
    """:func:`smooth` of ``x`` evaluated only at the samples ``at``, each of which must
    have ``window // 2`` samples on either side: each is the weights' dot product with
    its own window of samples, whatever the other samples hold."""
    return filters_at(x, window, (deriv,), h, at, order)[0]


def filters_at(x: np.ndarray, window: int, derivs: tuple[int, ...], h: float,
               at: np.ndarray, order: int = 3) -> list[np.ndarray]:
    """:func:`filter_at` for each of ``derivs``, from one copy of the windows."""
    half = window // 2
    cs = [sg_coefficients(window, order, d, h) for d in derivs]
    at = np.asarray(at)
    if x.ndim == 2 and len(at):
        # Each window a stretch of the rows laid out by rows (a view of rows laid out
        # so, else a copy), as the gathered windows lie: the same product, without the
        # gather's indices and its moved axes. The few samples' windows overlap: the rows
        # they span are laid out once, each window a stretch of them.
        ks = at.tolist()
        lo = min(ks) - half
        block = np.ascontiguousarray(x[lo:max(ks) + half + 1])
        wins = [block[k - half - lo:k + half + 1 - lo].T for k in ks]
        return [np.array([w @ c for w in wins]) for c in cs]  # stacked: the same rows
    windows = np.moveaxis(x[at[:, None] + np.arange(-half, half + 1)], 1, -1)
    return [windows @ c for c in cs]


def slope_gain(window: int, h: float) -> float:
    """Std of the filtered first derivative per unit of white noise (window samples)."""
    m = window // 2
    s2 = m * (m + 1) * (2 * m + 1) / 3.0  # sum of k^2 over -m..m
    return 1.0 / (h * math.sqrt(s2))


def curvature_gain(window: int, h: float) -> float:
    """Std of the filtered second derivative per unit of white noise (window samples)."""
    m = window // 2
    n = 2 * m + 1
    s2 = m * (m + 1) * (2 * m + 1) / 3.0
    s4 = m * (m + 1) * (2 * m + 1) * (3 * m * m + 3 * m - 1) / 15.0
    return 2.0 / (h * h * math.sqrt(max(s4 - s2 * s2 / n, 1e-300)))


def short_window(sigma: float, h: float) -> int:
    """The velocity filter's window [samples]: the shortest whose noise leaves joint
    speeds of :data:`SPEED_RESOLUTION` visible, within :data:`MAX_SHORT_WINDOW`."""
    longest = odd(MAX_SHORT_WINDOW / h)
    w = 3
    while w < longest and NOISE_SIGMAS * sigma * slope_gain(w, h) > SPEED_RESOLUTION:
        w += 2
    return w


def centred_mean(x: np.ndarray, half: int) -> np.ndarray:
    """The mean of ``x`` (N,) over the ``2 * half + 1`` samples centred on each, over
    fewer (still centred) within ``half`` of either end: a running sum's differences."""
    n = len(x)
    c = np.concatenate([[0.0], np.cumsum(x)])
    at = np.arange(n)
    r = np.minimum(np.minimum(at, n - 1 - at), half)
    return (c[at + r + 1] - c[at - r]) / (2 * r + 1)


def row_max(a: np.ndarray) -> np.ndarray:
    """The largest of each row of the 2-D ``a`` (a NaN where a row holds one), as
    ``a.max(axis=1)`` gives it: column by column, which on a few joints' columns is
    several times faster than NumPy's reduction along the short rows."""
    out = a[:, 0].copy()
    for j in range(1, a.shape[1]):
        np.maximum(out, a[:, j], out=out)
    return out


def row_sum(a: np.ndarray) -> np.ndarray:
    """The sum of each row of the 2-D ``a``, the same bits as ``a.sum(axis=1)`` (and the
    squares' in ``np.linalg.norm(a, axis=1)``): NumPy adds a row of fewer than eight
    values from left to right, as this does column by column, several times faster on a
    few joints' or coordinates' columns. A row of eight or more it adds pairwise, so
    that is left to it."""
    if a.shape[1] >= 8 or a.shape[1] == 0:
        return a.sum(axis=1)
    out = 0.0 + a[:, 0]  # NumPy's sum starts at +0.0: a row of zeros sums to +0.0
    for j in range(1, a.shape[1]):
        out += a[:, j]
    return out


def median0(a: np.ndarray) -> Any:
    """``np.median(a, axis=0)`` of finite values, the same numbers (a zero as +0.0, as
    its mean of the middle ones gives it): from one partition about the middle, without
    NumPy's look for NaNs (a finite recording has none) and its general axes, which on
    the few hundred samples of a hold cost more than the partition."""
    n = len(a)
    if n == 0:
        return np.median(a, axis=0)
    h = n // 2
    if n % 2:
        return 0.0 + np.partition(a, (h, n - 1), axis=0)[h]
    part = np.partition(a, (h - 1, h), axis=0)
    return (0.0 + part[h - 1] + part[h]) / 2.0


def line_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The slope and intercept of the least-squares line through ``(x, y)``: the
    numbers ``np.polyfit(x, y, 1)`` gives (the same scaled design, the same solver,
    without its checks and its general degree, which cost more than the solve on the
    few tens of samples of a ramp; its warning on a rank-deficient fit too)."""
    x, y = x + 0.0, y + 0.0  # as polyfit takes them (no negative zeros)
    lhs = np.empty((len(x), 2))
    lhs[:, 0], lhs[:, 1] = x, 1.0
    scale = np.sqrt((lhs * lhs).sum(axis=0))
    lhs /= scale
    c, _, rank, _ = np.linalg.lstsq(lhs, y, len(x) * _EPS)
    if rank != 2:
        warnings.warn("Polyfit may be poorly conditioned", np.exceptions.RankWarning,
                      stacklevel=2)
    return float(c[0] / scale[0]), float(c[1] / scale[1])


_EPS = float(np.finfo(np.float64).eps)
