"""The signals the rest test works on (:mod:`.holds`): each joint's filtered velocity and
its rest threshold from the joint's noise, over the velocity filter's window and over a
longer one that finds motion too slow for the short window to tell from noise."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.memo import cached
from .onset import REST_SPEED
from .signal import NOISE_SIGMAS, odd, row_max, sg_coefficients, slope_gain, smooth, smooth_rows

__all__ = ["CLEARLY", "LONG_WINDOW", "Rest", "leading", "rest_at_end", "rest_signals"]

#: A joint is clearly moving at this many times its rest threshold (16 noise std).
CLEARLY = 3.0
#: Window of the slow-motion check inside long rests [s].
LONG_WINDOW = 0.3
#: Windows of the slow-motion check from which its filter runs through the FFT (from
#: about 500 Hz on; below, the direct sum is as fast).
FFT_WINDOW = 151


@dataclass(frozen=True)
class Rest:
    """The signals the rest test works on (arrays over the grid's N samples).

    Attributes:
        t: times [s]; h: the step [s]; window: the velocity filter [samples].
        v: filtered joint velocities, (N, n).
        thr: each joint's rest threshold [rad/s] at each sample, (N, n) (larger where
            a logging gap leaves fewer raw samples).
        ratio: each joint's speed over its threshold, ``|v| / thr``, (N, n).
        level: the largest of those, (N,): under 1 is rest.
        v_long, thr_long, ratio_long: the same over :data:`LONG_WINDOW` (None for
            clean data).
        t_last: the recording's end [s].
        q: joint positions, (N, n); noise: each joint's noise [rad], (n,);
        quantum: each joint's resolution [rad] (0: none), (n,).
        held_gain: the noise std per unit of noise of the hold test's positions
            (:meth:`held`).
        sparse: how much noisier a filtered value is than where the log has all its
            samples (above 1 across a logging gap), (N,).
        carried: the joint velocities and accelerations the file carries on these
            samples (a compiled trajectory, a logger that records them), or None.
    """

    t: np.ndarray
    h: float
    window: int
    v: np.ndarray
    thr: np.ndarray
    ratio: np.ndarray
    level: np.ndarray
    v_long: np.ndarray | None
    thr_long: np.ndarray | None
    ratio_long: np.ndarray | None
    t_last: float
    q: np.ndarray
    noise: np.ndarray
    quantum: np.ndarray
    held_gain: float
    sparse: np.ndarray
    carried: tuple[np.ndarray, np.ndarray] | None = None

    @cached_property
    def gapless(self) -> bool:
        """Whether the log has no gap: ``sparse`` is exactly 1 at every sample."""
        return bool(np.all(self.sparse == 1.0))

    def held(self, k0: int, k1: int) -> np.ndarray:
        """Joint positions filtered over ``window`` (raw for clean data) on samples
        ``k0``..``k1 - 1``, for the hold test, (k1 - k0, n): only the rests it tests
        are filtered, each value as the whole recording's filter gives it."""
        if self.window <= 3:
            return self.q[k0:k1]
        return smooth_rows(self.q, self.window, 0, self.h, k0, k1, order=3)



def rest_signals(t: np.ndarray, h: float, q: np.ndarray, noise: np.ndarray,
                 quantum: np.ndarray, density: np.ndarray, window: int, t_last: float,
                 carried: tuple[np.ndarray, np.ndarray] | None = None) -> Rest:
    """Joint velocities over ``window`` samples and per-joint rest thresholds from the
    joints' ``noise`` [rad] (0: a still or clean joint, threshold :data:`REST_SPEED`)."""
    v = smooth(q, window, 1, h, order=2)
    scale = 1.0 / np.sqrt(np.clip(density, 1e-3, 1.0))[:, None]
    thr = _thresholds(noise, slope_gain(window, h), scale)
    ratio = np.abs(v) / thr
    level = row_max(ratio)
    v_long = thr_long = ratio_long = None
    gain = 1.0
    if window > 3:
        gain = float(np.linalg.norm(sg_coefficients(window, 3, 0, 1.0)))
    if window > 3 and len(t) > odd(LONG_WINDOW / h):
        wl = odd(LONG_WINDOW / h)
        v_long = _long_slope(q, wl, h)
        thr_long = _thresholds(noise, slope_gain(wl, h), scale)
        ratio_long = np.abs(v_long) / thr_long
    return Rest(t, h, window, v, thr, ratio, level, v_long, thr_long, ratio_long, t_last, q,
                noise, quantum, gain, scale[:, 0], carried)


def _thresholds(noise: np.ndarray, gain: float, scale: np.ndarray) -> np.ndarray:
    """Each joint's rest threshold at each sample, (N, n): ``NOISE_SIGMAS`` stds of its
    filtered velocity (``gain`` per unit of noise, ``scale`` (N, 1) more across a logging
    gap), at least :data:`REST_SPEED`. Where every sample was logged (no gap) it is one
    row, read-only, the same for every sample."""
    row = NOISE_SIGMAS * noise[None, :] * gain
    if bool(np.all(scale == 1.0)):
        return np.broadcast_to(np.maximum(row, REST_SPEED), (len(scale), len(noise)))
    return np.maximum(row * scale, REST_SPEED)


def _long_slope(q: np.ndarray, window: int, h: float) -> np.ndarray:
    """The slope of the straight line fitted to ``window`` (odd) samples around each row
    of ``q`` (N, n), ``h`` [s] apart; near the ends, that of the line through the first
    or last window (the first-order Savitzky-Golay derivative, as :func:`.signal.smooth`
    gives it). Through the FFT: at 1 kHz the 0.3 s window has 301 weights, which the
    direct sum applies one pass over the samples each. The two differ by rounding
    (about 1e-14 rad/s here, against thresholds of 1e-3 rad/s and more)."""
    n, half = len(q), window // 2
    if n < 2 * window or window < FFT_WINDOW:
        return smooth(q, window, 1, h, order=1)
    size = 1 << int(math.ceil(math.log2(n + window)))
    x = q - q.mean(axis=0)  # no offset: the rounding is relative to what moves
    full = np.fft.irfft(np.fft.rfft(x, size, axis=0) * _kernel(window, h, size)[:, None],
                        size, axis=0)
    inner = full[window - 1:n]  # centred on rows half .. n - half - 1
    return np.concatenate([np.repeat(inner[:1], half, axis=0), inner,
                           np.repeat(inner[-1:], half, axis=0)])


@cached(maxsize=16)
def _kernel(window: int, h: float, size: int) -> np.ndarray:
    """The slope's weights, reversed, through the FFT of ``size`` (read-only: cached;
    the same for every recording, and every re-noised copy, on one clock)."""
    out = np.fft.rfft(sg_coefficients(window, 1, 1, h)[::-1], size)
    out.flags.writeable = False
    return out


def leading(v: np.ndarray, j: np.ndarray, shift: int) -> np.ndarray:
    """``v[np.arange(len(j)) + shift, j]``: each row's (from row ``shift`` on) joint ``j``,
    taken from the samples in the order they lie (by rows or by columns): the same
    values, without a look-up over both axes at once."""
    n, cols = v.shape
    rows = np.arange(shift, shift + len(j))
    if v.flags.c_contiguous:
        return v.ravel().take(rows * cols + j)
    if v.flags.f_contiguous:
        return v.ravel("F").take(j * n + rows)
    return v[rows, j]


def rest_at_end(r: Rest, last: bool) -> bool:
    """Whether the arm is at rest at the recording's first sample (its last with
    ``last``). A motion that starts from rest right at the first sample (under a jerk
    limit it barely moves at first) looks moving to a velocity filter there; its velocity,
    a cubic fitted over the first samples and followed back to the edge, is near zero
    beside the speed it has reached. A log that starts mid-motion starts at speed."""
    n = len(r.t)
    k = n - 1 if last else 0
    if r.level[k] < 1.0:
        return True
    m = min(n, max(2 * r.window + 1, odd(0.05 / r.h), 7))
    idx = np.arange(n - m, n) if last else np.arange(m)
    j = int(np.argmax(np.abs(r.q[idx[-1]] - r.q[idx[0]])))
    tt = r.t[idx] - r.t[k]
    c = np.polyfit(tt, r.q[idx, j], 3)
    far = float(tt[0] if last else tt[-1])
    v_edge = float(c[2])
    v_far = float(3 * c[0] * far ** 2 + 2 * c[1] * far + c[2])
    return abs(v_edge) <= max(0.1 * abs(v_far), CLEARLY * float(r.thr[k, j]))
