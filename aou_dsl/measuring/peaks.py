"""The peak acceleration of an approach or a retreat, read phase by phase.

An episode speeds up from rest and slows down to rest; the peak of each phase is read as
follows (docs/measure.md explains the choices). Every reading is a quadratic in time
fitted by least squares to the samples at their own times: a log's jittered clock and
its gaps are no curvature (a straight line drawn across a gap would be).

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
3. **The phase's profile.** Not every phase holds a level: a joint at its acceleration
   limit gives a peak at the phase's start that falls off after it (or one that builds
   up to its end), a minimum-jerk law a bell. The acceleration is also read over every
   run of samples of one length inside the phase and up to the top speed beside it
   (where a bang-bang law switches), as the level of a quadratic over the run. The runs
   are first long enough that their noise is :data:`DETECTION` of the level (at most
   half the phase): their largest reading is a peak when it exceeds the level by more
   than the largest of that many readings of a level would (:data:`SIGNIFICANT` stds
   more than ``sqrt(2 ln M)`` for ``M`` runs, stds of the hand's own noise) and, in a
   recording of an arm, by more than :data:`TRANSIENT_EXCESS` of the step of the
   acceleration at the phase's ends (what an arm's tracking transients add: a start
   from rest steps by the level, a switch from speeding up to slowing down by twice
   that). Otherwise the phase holds its level, and the level is its peak. A peak is
   then read finely: at the motion's start or stop, where the acceleration trends to
   it, by the cubic through the run that found it, at the shortest span an arm's
   transients allow (the end itself for a computed trajectory), when that cubic's
   noise is within :data:`RESOLUTION` of the peak; elsewhere as the largest reading,
   within that run, of the shortest runs whose noise is :data:`RESOLUTION` of the
   peak. A recording's runs never last less than its arm's transients.
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

from ..core.memo import cached
from .signal import median0, row_sum

__all__ = ["PhasePeak", "curvatures", "episode_peak", "path_travel", "phase_peak"]

#: Largest mean squared residual of the joints from their fitted path, in noise variances.
PATH_FIT = 1.5
#: Noise that moves a phase's level by less than this fraction of it is left as it is.
NEGLIGIBLE = 1e-3
#: A peak is read over runs whose noise std is at most this fraction of it.
RESOLUTION = 0.015
#: The profile's peak is found over runs whose noise std is at most this fraction of the
#: level (then read over runs of :data:`RESOLUTION`).
DETECTION = 0.005
#: The largest reading of the profile is a peak when it exceeds the level by this many
#: stds of its noise, plus what the largest of that many readings of a level exceeds it
#: by (``sqrt(2 ln M)`` stds for ``M`` independent runs in the phase)...
SIGNIFICANT = 3.5
#: ... and, in a recording of an arm, by this fraction of the level (of the step at
#: the phase's ends): an arm's tracking transients after a step of its acceleration add
#: up to about that to a reading as short as they are.
TRANSIENT_EXCESS = 0.03


@dataclass(frozen=True)
class PhasePeak:
    """A phase's peak acceleration [m/s^2], its std from the noise, and the time [s] and
    span [s] of the samples it was read from."""

    value: float
    sd: float
    at: float
    span: float


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
        # The normal equations: z lies in [-0.5, 0.5], so they lose at most about 1e-8 of
        # a joint's angle, far under its noise; LAPACK's least squares (an SVD) costs a
        # hundred times more on the thousands of samples of an approach at 1 kHz.
        try:
            coef = np.linalg.solve(powers.T @ powers, powers.T @ qm)
        except np.linalg.LinAlgError:  # fewer distinct travels than the terms (rounding)
            continue
        miss = qm - powers @ coef
        if float(np.mean(miss * miss * w)) > PATH_FIT:
            continue
        slopes = np.column_stack([(degree - i) * z ** (degree - i - 1) for i in range(degree)])
        g = slopes @ coef[:-1] / extent  # d(joint)/ds along the path, (K, n)
        weight = row_sum(g * g * w)
        if np.any(weight <= 0):
            continue
        return s + row_sum(miss * g * w) / weight, float(np.sqrt(1.0 / median0(weight)))
    return None


@cached(maxsize=512)
def _uniform_weights(w: int, h: float) -> np.ndarray:
    """The second-derivative weights of a least-squares quadratic through ``w`` samples
    ``h`` [s] apart (any ``w`` >= 3, odd or even). The step is a mean of a phase's own,
    rarely the same twice: the part that does not depend on it is kept per ``w``."""
    twice, norm = _centred_squares(w)
    return twice / (norm * h * h)


@cached(maxsize=512)
def _centred_squares(w: int) -> tuple[np.ndarray, float]:
    """Twice the squared offsets from the centre of ``w`` samples, less their mean, and
    the sum of the squares of the latter (read-only: cached)."""
    k = np.arange(w) - 0.5 * (w - 1)
    d = k * k - float(np.mean(k * k))
    twice = 2.0 * d
    twice.flags.writeable = False
    return twice, float(d @ d)


@cached(maxsize=512)
def _uniform_gain(w: int, h: float) -> float:
    """The norm of :func:`_uniform_weights`: the reading's std per unit of white noise."""
    return float(np.linalg.norm(_uniform_weights(w, h)))


def _runs_of(v: np.ndarray, w: int) -> np.ndarray:
    """Every run of ``w`` consecutive samples of the 1-D ``v``, (len(v) - w + 1, w): a
    read-only view (NumPy's sliding window view, without its checks)."""
    step = v.strides[0]
    if not v.flags.c_contiguous:
        return np.lib.stride_tricks.as_strided(v, (len(v) - w + 1, w), (step, step),
                                               writeable=False)
    # The same view made on the samples' own memory, without the general function's
    # array interface (a few microseconds a call, on a few thousand calls a build).
    out = np.ndarray((len(v) - w + 1, w), v.dtype, v, 0, (step, step))
    out.flags.writeable = False
    return out


def curvatures(t: np.ndarray, x: np.ndarray, w: int, noisy: bool = False
               ) -> tuple[np.ndarray, np.ndarray]:
    """Over every run of ``w`` (>= 3) consecutive samples of ``x`` at times ``t``: the
    second derivative of the least-squares quadratic in time, and its std per unit of
    white noise on ``x``. Run ``k`` covers samples ``k``..``k + w - 1``. With ``noisy``
    (a recording's samples), an even clock's runs are summed by NumPy's correlation,
    several times faster over long runs and different only in rounding (1e-14 of the
    reading, far under the noise); without, in one fixed order (a computed trajectory's
    equal readings are told apart by their rounding, which must not move)."""
    xw = _runs_of(x, w)
    steps = t[1:] - t[:-1]
    if len(steps):
        mean = float(np.add.reduce(steps)) / len(steps)  # steps.mean(), its sum and division
        if float(steps.max() - steps.min()) <= 1e-9 * mean:  # one clock
            weights = _uniform_weights(w, mean)
            reads = np.correlate(x, weights, "valid") if noisy else xw @ weights
            return reads, np.full(len(xw), _uniform_gain(w, mean))
    tw = _runs_of(t, w)
    centre = tw.mean(axis=1, keepdims=True)
    half = np.maximum(0.5 * (tw[:, -1] - tw[:, 0]), 1e-300)[:, None]
    z = (tw - centre) / half  # in [-1, 1]: well conditioned at any clock
    z2 = z * z
    m = np.empty((len(tw), 3, 3))
    m[:, 0, 0] = w
    m[:, 0, 1] = m[:, 1, 0] = z.sum(axis=1)
    m[:, 0, 2] = m[:, 2, 0] = m[:, 1, 1] = z2.sum(axis=1)
    m[:, 1, 2] = m[:, 2, 1] = (z2 * z).sum(axis=1)
    m[:, 2, 2] = (z2 * z2).sum(axis=1)
    xm = xw - xw.mean(axis=1, keepdims=True)  # the constant term takes the offset
    rhs = np.stack([xm.sum(axis=1), (xm * z).sum(axis=1), (xm * z2).sum(axis=1)], axis=1)
    inv = np.linalg.inv(m)
    scale = 2.0 / half[:, 0] ** 2
    return (np.einsum("kj,kj->k", inv[:, 2], rhs) * scale,
            np.sqrt(np.maximum(inv[:, 2, 2], 0.0)) * scale)


def _run(t: np.ndarray, a: int, b: int, level: float, noise: float, shortest: float,
         resolution: float) -> int:
    """The profile's run [samples] within phase ``a``..``b``: the shortest of at least 3
    samples, lasting at least ``shortest`` [s], whose reading has a noise std (``noise``
    on the travel) within ``resolution`` of ``level``; the whole phase when none is."""
    length = b - a + 1
    step = float(t[b] - t[a]) / max(length - 1, 1)
    w = min(max(3, int(math.ceil(shortest / step - 1e-9)) + 1), length)
    bound = resolution * level
    while w < length:
        # The gain of a run on an even clock of the phase's mean step: first from its
        # closed form, ``2 / (h^2 sqrt(w (w^2 - 1) (w^2 - 4) / 180))``, which settles
        # every run clearly too short; the weights' own norm decides the close ones.
        close = 2.0 / (step * step * math.sqrt(w * (w * w - 1.0) * (w * w - 4.0) / 180.0))
        if noise * close <= bound + 1e-9 * (abs(bound) + noise * close):
            gain = _uniform_gain(w, step)
            if noise * gain <= bound:
                break
        w = min(w + max(1, w // 8), length)
    return w


Travel = Callable[[int, int], "tuple[np.ndarray, float] | None"]


def phase_peak(t: np.ndarray, x: np.ndarray, a: int, b: int, sigma: float,
               transient: float, travel: Travel | None = None, step: float = 1.0,
               around: tuple[int, int] | None = None) -> PhasePeak | None:
    """The peak acceleration of phase ``a``..``b`` (samples of ``x``, the hand's travel
    [m] over its piece, at times ``t`` [s]); ``sigma`` the travel's noise std [m];
    ``transient`` [s] how long the arm's tracking transients last (0 for a computed
    trajectory, which has none); ``travel(j0, j1)`` the travel over samples
    ``j0``..``j1`` with the joints' noise across their path removed, and its noise
    (:func:`path_travel`); ``step`` the largest step of the acceleration at the phase's
    ends, in levels (1 from rest, up to 2 where one motion reverses into the next): an
    arm's transients grow with it; ``around`` the samples its peak is looked for in
    (``a``..``b`` and up to the top speed beside it)."""
    n, length = len(x), b - a + 1
    if length < 3:
        return None
    acc, gain = curvatures(t[a:b + 1], x[a:b + 1], length)
    level, g2 = float(acc[0]), float(gain[0])
    reach = length // 2 + 1
    j0, j1 = max(0, a - reach), min(n - 1, b + reach)
    # Noise that moves the level by less than NEGLIGIBLE of it is not worth the path.
    better = (travel(j0, j1) if travel is not None and sigma * g2 > NEGLIGIBLE * abs(level)
              else None)
    # The path's noise is what a fit of it says is left; but the fitted path bends with
    # the noise across it over a short stretch, so a peak must stand out of the hand's.
    raw = sigma
    if better is not None and better[1] < sigma:
        x = x.copy()
        x[j0:j1 + 1], sigma = better
        level = float(curvatures(t[a:b + 1], x[a:b + 1], length)[0][0])
    sign = 1.0 if level >= 0 else -1.0
    level *= sign
    out = PhasePeak(level, sigma * g2, 0.5 * float(t[a] + t[b]), float(t[b] - t[a]))
    w = _run(t, a, b, level, sigma, transient, RESOLUTION)
    if w >= length:
        return out
    # The peak is found over longer runs (less noisy: a smaller excess stands out of
    # the noise) and then read over the shortest run the noise allows, where it was found.
    lo, hi = around if around is not None else (a, b)
    lo, hi = min(lo, a), max(hi, b)
    if lo < a or hi > b:  # up to the top speed: a bang-bang law's switch steps by 2 levels
        step = max(step, 2.0)
    ws = max(w, min(_run(t, a, b, level, sigma, transient, DETECTION), (length + 1) // 2))
    noisy = transient > 0  # a recording: its noise is far above the sums' rounding
    reads, gains = curvatures(t[lo:hi + 1], x[lo:hi + 1], ws, noisy)
    best = int(np.argmax(reads * sign))
    found, sd = float(reads[best]) * sign, sigma * float(gains[best])
    runs = max(1.0, (hi - lo + 1) / ws)
    allowed = max((SIGNIFICANT + math.sqrt(2.0 * math.log(runs))) * raw * float(gains[best]),
                  TRANSIENT_EXCESS * step * level if transient > 0 else 0.0)
    if found - level <= allowed:
        return out
    k0, k1 = lo + best, lo + best + ws - 1
    start, end = best == 0 and lo == a, best == len(reads) - 1 and hi == b
    if (start or end) and ws >= 6:
        # At the motion's start or stop the acceleration trends to its peak: a cubic over
        # the run follows the trend to the shortest span an arm's transients allow there
        # (when the noise lets it: its reading is noisier than the run's).
        at = t[k0] + 0.5 * transient if start else t[k1] - 0.5 * transient
        edge, edge_gain = _cubic_curvature(t[k0:k1 + 1], x[k0:k1 + 1], float(at))
        if edge * sign > found and sigma * edge_gain <= RESOLUTION * edge * sign:
            return PhasePeak(edge * sign, sigma * edge_gain, float(at), transient)
    fine = _run(t, a, b, found, sigma, transient, RESOLUTION)
    if fine < ws:
        acc_f, gain_f = curvatures(t[k0:k1 + 1], x[k0:k1 + 1], fine, noisy)
        k = int(np.argmax(acc_f * sign))
        if float(acc_f[k]) * sign > found:
            k0, k1 = k0 + k, k0 + k + fine - 1
            found, sd = float(acc_f[k]) * sign, sigma * float(gain_f[k])
    return PhasePeak(found, sd, 0.5 * float(t[k0] + t[k1]), float(t[k1] - t[k0]))


def _cubic_curvature(t: np.ndarray, x: np.ndarray, at: float) -> tuple[float, float]:
    """The second derivative at time ``at`` of the least-squares cubic in time through
    ``x``, and its std per unit of white noise on ``x``."""
    centre, half = 0.5 * float(t[0] + t[-1]), max(0.5 * float(t[-1] - t[0]), 1e-300)
    z = (t - centre) / half
    v = np.vander(z, 4, increasing=True)
    inv = np.linalg.inv(v.T @ v)
    za = (at - centre) / half
    g = np.array([0.0, 0.0, 2.0, 6.0 * za]) / half ** 2
    return float(g @ inv @ (v.T @ x)), float(np.sqrt(max(float(g @ inv @ g), 0.0)))


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
        return PhasePeak(value, p.sd, p.at, p.span)
    wp, wr = 1.0 / max(p.sd, 1e-300) ** 2, 1.0 / max(r.sd, 1e-300) ** 2
    return PhasePeak((wp * p.value + wr * r.value) / (wp + wr), 1.0 / math.sqrt(wp + wr),
                     p.at, p.span)
