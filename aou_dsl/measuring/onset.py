"""Where an oscillation beside a hold leaves (or reaches) the held position.

An oscillation (a shiver) starts and ends with an envelope that fades in and out: near
its start it grows as a power of the time since it started (the cube for an envelope
that rises as sin^2, the square or the cube for most smooth starts from rest). Its first
part hides under the noise, and its velocity has no straight ramp to follow back to
zero, so the rest test sees it tens of milliseconds late. The hold's edge is found
instead by fitting the deviation of the leading joint from the held position, from
inside the hold to :data:`ONSET_TOP` of the oscillation's first lobe, with ``c * (t - t0)^p``
after ``t0`` and 0 before it: ``t0`` on a grid a quarter step (at most 1 ms) fine, ``p`` from
:data:`POWERS`, ``c`` by least squares. Under noise the data hardly tell a higher power
with an earlier start from a lower one with a later start, so the powers are those of
smooth starts from rest: from finite acceleration (2) to a little past finite jerk (3).
The fit reaches well up the first lobe, where the oscillation's growth has begun to
slow, so that enough samples stand above the noise; the free power absorbs that. A
motion that does not swing to both sides of the hold (an approach, a tilt, the ringing
of an arm that stops) is left to its velocity ramp, and a fit that misses the data by
more than the noise leaves the edge where it was. An oscillation that fades in over a
cycle may hide its whole first swing under the noise, so that the first lobe standing out
is its second: a power of time alone misses the hidden swing, and the power times the
oscillation (at the frequency its first two clear lobes give) is fitted instead.

A file that carries its joints' velocities and accelerations (a compiled trajectory)
says exactly where any motion leaves rest: :func:`carried_edge`.
"""

from __future__ import annotations

import math

import numpy as np

from .signal import median0

__all__ = ["REST_SPEED", "carried_edge", "held_at", "soft_edge", "soft_pause"]

#: Joint speed under which clean data are at rest [rad/s].
REST_SPEED = 1e-4

#: The powers of time a soft start is fitted with.
POWERS = (2.0, 2.5, 3.0, 3.5)
#: The fit covers the motion until its deviation reaches this fraction of its first lobe.
ONSET_TOP = 0.8
#: Longest stretch of a hold [s] and of the motion [s] the fit looks at.
HOLD_SPAN = 0.4
MOTION_SPAN = 1.5
#: A fit whose residual is more than this many times the noise's, and more than this
#: fraction of the first lobe (a power of time is not the lobe's exact shape), leaves the
#: edge alone.
FIT_SIGMAS = 1.5
FIT_SHAPE = 0.05
#: An oscillation swings to either side of the held position, twice at least, by this
#: fraction of its first lobe.
SWING = 0.3
#: Its first lobe is this fraction of its largest at least (a fade-in over one cycle
#: makes it about 0.15; the ringing of an arm that stops is far smaller than its stop).
LOBE = 0.05
#: A deviation is clearly motion past this many noise stds.
CLEAR = 6.0
#: The oscillation's frequency, read from two lobes, is fitted within this much of it.
RATES = (0.8, 0.9, 1.0, 1.1, 1.2)


def soft_edge(t: np.ndarray, q: np.ndarray, noise: np.ndarray, hold: tuple[int, int],
              step: int, ref: np.ndarray | None = None) -> float | None:
    """The instant the motion after the hold ``hold`` (grid samples, inclusive; ``step``
    +1), or before it (``step`` -1), leaves the held position; None when no joint with
    noise moves clearly beside it, or when the fit misses.

    ``t`` (N,) and ``q`` (N, n) are the grid's times and joint positions; ``noise`` (n,)
    each joint's noise std (0: a still or clean joint, not used); ``ref`` the held
    position (:func:`held_at`), when the other edge's call has found it."""
    n = len(t)
    h0, h1 = hold
    noisy = noise > 0
    if h1 - h0 < 4 or not noisy.any():
        return None
    h = float(t[1] - t[0])
    if ref is None:
        ref = held_at(q, hold)
    edge = h1 if step > 0 else h0
    reach = int(round(MOTION_SPAN / h))
    far = min(max(edge + step * reach, 0), n - 1)
    if abs(far - edge) + 1 < 4:  # the samples edge, edge + step, .. far
        return None
    # The same samples as a view (they run one way from the edge): no copies.
    rows = slice(edge, far + step if far + step >= 0 else None, step)
    sig = np.where(noisy, noise, np.inf)
    away = q[rows] - ref
    # The joint that moves furthest in its noise. Dividing by a positive number keeps
    # the order of what it divides, so each joint's largest deviation over its noise is
    # its largest deviation divided by its noise: the same number, dividing n values
    # instead of all of them; a joint without noise (inf) gives 0 as each of its would.
    most = np.abs(away).max(axis=0)
    j = int(np.argmax(most / sig))
    if not noisy[j]:
        return None
    dev = away[:, j]  # the joint's deviation from the hold, as every joint's above
    clear = np.flatnonzero(np.abs(dev) / sig[j] > CLEAR)
    if len(clear) == 0:
        return None
    first = int(clear[0])
    d = dev * np.sign(dev[first])
    # The first lobe: up to where the deviation first swings back through the hold; the
    # onset is the part of it under ONSET_TOP of its top.
    back = np.flatnonzero(d[first:] < 0.0)
    top = float(d[first:first + (back[0] if len(back) else len(d))].max())
    # |d| is |dev| (a change of sign is exact): its largest is the joint's found above.
    if top < LOBE * float(most[j]) or _swings(d[first:], SWING * top) < 2:
        return None  # no oscillation: a motion's velocity ramp gives its edge
    side = np.arange(edge, far + step, step)
    end = clear[0] + int(np.argmax(d[clear[0]:] >= ONSET_TOP * top))
    end = max(end, clear[0])
    inside = int(min(round(HOLD_SPAN / h), h1 - h0))
    idx = np.arange(edge - step * inside, side[end] + step, step)
    y = (q[idx, j] - ref[j]) * np.sign(q[side[clear[0]], j] - ref[j])
    tau = (t[idx] - t[edge]) * step  # time away from the hold, 0 at its edge
    # Candidate starts: from inside the hold to the first clear sample, a quarter step
    # (at most a millisecond) apart.
    starts = np.arange(tau[0], (t[side[clear[0]]] - t[edge]) * step, max(h / 4.0, 1e-3))
    if len(starts) == 0:
        return None
    lag = np.clip(tau[None, :] - starts[:, None], 0.0, None)  # (S, K)
    limit = len(y) * max(FIT_SIGMAS * float(sig[j]), FIT_SHAPE * top) ** 2
    best = _best(lag, y, starts, [lag ** p for p in POWERS])
    if best[0] > limit:
        # An oscillation that fades in over a cycle can hide its first swings under the
        # noise: the first clear lobe is not its first, and a power of time alone
        # misses the hidden ones before it. The power times the oscillation fits them.
        w = _angular(t[side], d, clear[0], back[0] if len(back) else len(d))
        if w is not None:
            best = _best(lag, y, starts, [lag ** p * np.sin(k * w * lag) for p in POWERS
                                          for k in RATES])
    if best[0] > limit:
        return None
    return float(t[edge]) + step * best[1]


def held_at(q: np.ndarray, hold: tuple[int, int]) -> np.ndarray:
    """The position held over ``hold`` (grid samples, inclusive): each joint's median
    over its middle third."""
    h0, h1 = hold
    third = (h1 - h0 + 1) // 3
    return median0(q[h0 + third:h1 - third + 1])


def _best(lag: np.ndarray, y: np.ndarray, starts: np.ndarray, shapes: list[np.ndarray]
          ) -> tuple[float, float]:
    """The least squared residual of ``y`` fitted with ``c * shape`` over the shapes (each
    (S, K): one row per candidate start), and the start that gives it."""
    best = (np.inf, 0.0)
    for g in shapes:
        gg = np.einsum("sk,sk->s", g, g)
        c = np.where(gg > 0, (g @ y) / np.where(gg > 0, gg, 1.0), 0.0)
        r = y[None, :] - c[:, None] * g
        sse = np.einsum("sk,sk->s", r, r)
        k = int(np.argmin(sse))
        if sse[k] < best[0]:
            best = (float(sse[k]), float(starts[k]))
    return best


def _angular(t: np.ndarray, d: np.ndarray, first: int, back: int) -> float | None:
    """The oscillation's angular frequency [rad/s] from the deviation ``d`` at times
    ``t``: pi over the time from the top of its first clear lobe (from ``first``, up to
    ``back`` samples on, where it swings back) to the bottom of the next; None when the
    next lobe is not there."""
    top = first + int(np.argmax(d[first:first + back]))
    rest = d[first + back:]
    again = np.flatnonzero(rest > 0.0)
    lobe = rest[:again[0]] if len(again) else rest
    if len(lobe) < 2:
        return None
    bottom = first + back + int(np.argmin(lobe))
    half = abs(float(t[bottom] - t[top]))
    return math.pi / half if half > 0 else None


def _swings(d: np.ndarray, level: float) -> int:
    """How many times ``d`` crosses from beyond ``level`` (> 0) on one side to beyond it
    on the other: the changes of side among the samples beyond it."""
    up = d[np.abs(d) > level] > 0
    return int(np.count_nonzero(up[1:] != up[:-1]))


def soft_pause(t: np.ndarray, q: np.ndarray, noise: np.ndarray, span: tuple[float, float],
               known: tuple[tuple[int, int], np.ndarray] | None = None
               ) -> tuple[float, float]:
    """The hold from ``span[0]`` to ``span[1]`` [s] with each edge that borders an
    oscillation moved to where the oscillation leaves or reaches the held position
    (:func:`soft_edge`). The result may be short, or empty (its end before its start):
    then the rest was the oscillation's soft start or end, hidden under the noise, and
    no pause. ``known``: grid samples (inclusive) and the position :func:`held_at` gives
    for them, when the caller has found it."""
    a, b = span
    k0 = int(np.searchsorted(t, a, "left"))
    k1 = int(np.searchsorted(t, b, "right")) - 1
    if k1 - k0 < 4:
        return a, b
    # Both edges look from one held position: found once (or known already).
    ref = None
    if np.any(noise > 0) and (k0 > 0 or k1 < len(t) - 1):
        ref = known[1] if known is not None and known[0] == (k0, k1) else held_at(q, (k0, k1))
    if k0 > 0:
        edge = soft_edge(t, q, noise, (k0, k1), -1, ref)
        a = a if edge is None else edge
    if k1 < len(t) - 1:
        edge = soft_edge(t, q, noise, (k0, k1), +1, ref)
        b = b if edge is None else edge
    return a, b


def carried_edge(t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, i: int,
                 step: int) -> float | None:
    """Where the motion beside sample ``i`` (after it for ``step`` +1, before it for -1)
    leaves rest, from the positions ``q``, velocities ``qd`` and accelerations ``qdd``
    (N, n) a file carries at times ``t`` (N,).

    Near its start a motion from rest goes as a power of the time since it started,
    ``dq ~ tau^k`` (k = 2 at constant acceleration, 3 under a jerk limit), so at its first
    moving sample ``qd/qdd = tau/(k-1)`` and ``dq/qd = tau/k``: both give ``k`` and
    ``tau`` without assuming either. The first sample near ``i`` whose start falls
    between it and its neighbour on the rest side gives the edge; None when none does.
    """
    n = len(t)
    j = int(np.argmax(np.abs(qd[min(max(i + 3 * step, 0), n - 1)])))
    for b in range(i - 2 * step, i + 5 * step, step):
        a = b - step
        if not (0 <= a < n and 0 <= b < n):
            continue
        dq = float(q[b, j] - q[a, j])
        v, acc = float(qd[b, j]) * step, float(qdd[b, j])
        if abs(v) <= REST_SPEED or dq == 0.0:
            continue
        sign = math.copysign(1.0, dq)
        v, acc, dq = v * sign, acc * sign, abs(dq)
        if v <= 0 or acc <= 0:
            continue
        r1, r2 = v / acc, dq / v
        if r1 <= r2:
            continue
        k = r1 / (r1 - r2)
        tau = k * r2
        if 1.0 <= k <= 8.0 and tau <= abs(float(t[b] - t[a])) * (1 + 1e-9):
            return float(t[b]) - step * tau
    return None
