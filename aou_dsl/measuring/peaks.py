"""The peak acceleration of an approach or a retreat, read phase by phase.

An episode speeds up from rest and slows down to rest; the peak of each phase is read as
follows (docs/measure.md explains the choices):

1. **The hand's travel, with the joints' noise across their path removed.** The hand's
   position along its direction of travel, ``s = u . p``, takes noise from every joint,
   but the joints move along one path: each joint a smooth function of ``s``. That path
   is fitted over the phase and half a phase on either side (each joint a cubic of
   ``s``, a quintic when the cubic misses), and each sample is moved onto it, the joints
   weighted by their noise. What is left of the noise is its part along the path: on
   the arms aou knows, about half of the hand's. A path that does not match the joints
   within their noise (mean squared residual over :data:`PATH_FIT` noise variances)
   leaves the hand's own travel.
2. **The level of the phase.** A quadratic fitted over the whole phase: its second
   derivative is a mean of the acceleration with positive weights, equal to it where the
   acceleration holds a level, and the least noisy reading of one. It is one reading at
   one place: no maximum over noisy values, which the noise would bias up.
3. **A curved phase.** A bell-shaped acceleration peaks above any mean of it. A quartic
   fitted over the phase, centred where the phase's acceleration is concentrated (the
   centroid of its square), reads a curved peak without that bias. Where the two
   readings differ by more than :data:`CURVED_SIGMAS` stds of their difference and by
   :data:`CURVED` of the level, the phase is curved and the quartic's reading is its
   peak. A quartic resolves finer detail than a quadratic over the same span, so it is
   used over :data:`QUARTIC_SPAN` times the arm's transients at least: an arm's
   tracking transients after a switch are no peak.
4. **The episode's peak** is the larger of its two phases'. When they differ by no more
   than their noise, the larger of two noisy readings is biased up (by half a std for
   equal ones); the estimate is then their weighted mean, plus half the part of their
   difference the noise does not explain.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .signal import filter_at, odd, sg_coefficients

__all__ = ["PhasePeak", "episode_peak", "path_travel", "phase_peak"]

#: Largest mean squared residual of the joints from their fitted path, in noise variances.
PATH_FIT = 1.5
#: Noise that moves a phase's level by less than this fraction of it is left as it is.
NEGLIGIBLE = 1e-3
#: A quartic's reading replaces the quadratic's when they differ by this many stds of
#: their difference...
CURVED_SIGMAS = 4.0
#: ... and by this fraction of the level.
CURVED = 0.03
#: The quartic is used over this many times the arm's transients at least.
QUARTIC_SPAN = 1.7


@dataclass(frozen=True)
class PhasePeak:
    """A phase's peak acceleration [m/s^2], its std from the noise, the sample (of the
    piece) and the window [samples] it was read at."""

    value: float
    sd: float
    at: int
    window: int


def path_travel(s: np.ndarray, q: np.ndarray, noise: np.ndarray
                ) -> tuple[np.ndarray, float] | None:
    """The travel ``s`` (K,) [m] with the joints' noise across their path removed, and
    the noise std left in it [m]; None when no fitted path matches the joints ``q``
    (K, n) within their ``noise`` (n,) (0 for a joint without noise, not used)."""
    moving = noise > 0
    extent = float(np.ptp(s)) if len(s) else 0.0
    if len(s) < 12 or not moving.any() or extent <= 0:
        return None
    qm, w = q[:, moving], 1.0 / noise[moving] ** 2
    z = (s - s.mean()) / extent
    for degree in (3, 5):
        powers = np.vander(z, degree + 1)
        coef = np.linalg.lstsq(powers, qm, rcond=None)[0]
        miss = qm - powers @ coef
        if float(np.mean(miss * miss * w)) > PATH_FIT:
            continue
        slopes = np.column_stack([(degree - i) * z ** (degree - i - 1) for i in range(degree)])
        g = slopes @ coef[:-1] / extent  # d(joint)/ds along the path, (K, n)
        weight = (g * g * w).sum(axis=1)
        if np.any(weight <= 0):
            continue
        return s + (miss * g * w).sum(axis=1) / weight, float(np.sqrt(1.0 / np.median(weight)))
    return None


def _centroid(x: np.ndarray, a: int, b: int, window: int, h: float) -> tuple[int, float]:
    """Where the acceleration of phase ``a``..``b`` is concentrated (the centroid of its
    square, from a quadratic over ``window`` samples), and its sign."""
    n, half = len(x), window // 2
    k0, k1 = max(a, half), min(b, n - 1 - half)
    if k1 < k0:
        k0 = k1 = min(max((a + b) // 2, half), n - 1 - half)
    acc = filter_at(x, window, 2, h, k0, k1, order=2)
    sign = 1.0 if acc.sum() >= 0 else -1.0
    weight = np.clip(acc * sign, 0.0, None) ** 2
    if weight.sum() <= 0:
        return (k0 + k1) // 2, sign
    return int(round(k0 + float(np.arange(len(acc)) @ weight) / float(weight.sum()))), sign


def _weights(n: int, centre: int, window: int, order: int, h: float) -> np.ndarray:
    """A fit's second-derivative weights at ``centre``, over ``n`` samples."""
    out = np.zeros(n)
    half = window // 2
    out[centre - half:centre + half + 1] = sg_coefficients(window, order, 2, h)
    return out


Travel = Callable[[int, int], "tuple[np.ndarray, float] | None"]


def phase_peak(x: np.ndarray, a: int, b: int, h: float, sigma: float, sparse: np.ndarray,
               shortest: float, travel: Travel | None = None) -> PhasePeak | None:
    """The peak acceleration of phase ``a``..``b`` (samples of ``x``, the hand's travel
    [m] over its piece); ``sigma`` the travel's noise std [m]; ``sparse`` (per sample)
    how much noisier a value is across a logging gap; ``shortest`` [s] the arm's
    transients; ``travel(j0, j1)`` the travel over samples ``j0``..``j1`` with the
    joints' noise across their path removed, and its noise (:func:`path_travel`)."""
    n, length = len(x), b - a + 1
    w1 = min(odd(shortest / h, least=5), length if length % 2 else length - 1,
             n if n % 2 else n - 1)
    if w1 < 3:
        return None
    ctr, sign = _centroid(x, a, b, w1, h)
    mid = (a + b) // 2
    w2 = max(3, min(2 * min(mid - a, b - mid) + 1, 2 * min(mid, n - 1 - mid) + 1))
    f2 = _weights(n, mid, w2, 2, h)
    level = float(f2 @ x) * sign
    reach = length // 2 + 1
    j0, j1 = max(0, a - reach), min(n - 1, b + reach)
    # Noise that moves the level by less than NEGLIGIBLE of it is not worth the path.
    noisy = sigma * float(np.linalg.norm(f2)) > NEGLIGIBLE * abs(level)
    better = travel(j0, j1) if travel is not None and noisy else None
    if better is not None and better[1] < sigma:
        x = x.copy()
        x[j0:j1 + 1], sigma = better
        level = float(f2 @ x) * sign
    sigma *= float(sparse[ctr])
    out = PhasePeak(abs(level), sigma * float(np.linalg.norm(f2)), mid, w2)
    w4 = max(w1, min(2 * min(ctr - a, b - ctr) + 1, 2 * min(ctr, n - 1 - ctr) + 1))
    c4 = ctr
    if w4 * h < QUARTIC_SPAN * shortest:
        w4, c4 = w2, mid
    if w4 * h < QUARTIC_SPAN * shortest or w4 < 7:
        return out
    f4 = _weights(n, c4, w4, 4, h)
    curved = float(f4 @ x) * sign
    if abs(curved - level) > max(CURVED_SIGMAS * sigma * float(np.linalg.norm(f4 - f2)),
                                 CURVED * abs(level)):
        return PhasePeak(abs(curved), sigma * float(np.linalg.norm(f4)), c4, w4)
    return out


def episode_peak(phases: list[PhasePeak]) -> PhasePeak:
    """An episode's peak from its phases' (see the module's docstring): the larger, or,
    for two that differ by no more than their noise explains, their weighted mean plus
    half the difference beyond the noise."""
    if len(phases) != 2:
        return max(phases, key=lambda p: p.value)
    p, r = sorted(phases, key=lambda f: f.value, reverse=True)
    beyond = (p.value - r.value) ** 2 - (p.sd ** 2 + r.sd ** 2)
    if beyond > 0:
        value = min(p.value, 0.5 * (p.value + r.value) + 0.5 * math.sqrt(beyond))
        return PhasePeak(value, p.sd, p.at, p.window)
    wp, wr = 1.0 / max(p.sd, 1e-300) ** 2, 1.0 / max(r.sd, 1e-300) ** 2
    return PhasePeak((wp * p.value + wr * r.value) / (wp + wr), 1.0 / math.sqrt(wp + wr),
                     p.at, p.window)
