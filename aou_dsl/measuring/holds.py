"""Where the arm is at rest: pauses (holds), and the instants where one motion ends and
the next begins without a hold.

A sample is at rest when every joint's filtered speed is under its own noise threshold.
Noise makes a slowly decelerating motion look still for a while before it stops, so the
edges of a rest run are not where the motion stops: each edge is refined by following
the motion beside it back to zero velocity (it stops with a nearly constant
deceleration, so its velocity is a straight line there). A rest whose refined span lasts
:data:`MIN_PAUSE` or more, and in which the joints hold one position within their noise
for most of it, is a pause; a shorter one is the boundary between two episodes (a
rest-to-rest boundary, or a reversal). Motion that reverses or stops without ever
looking still (a fast shiver, coarse sampling) is found from the speed's dips to zero,
also between two samples: sampled a few times per cycle, a shiver's samples can all
miss its reversals, where its leading joint's velocity changes sign. A short rest inside
a slow motion's start or end, which the noise hid and let out again, is no boundary
when the motion on both sides moves the same way and points at a stop beyond it.
A pause beside an oscillation, whose envelope fades in and out, has its edges placed by
:mod:`.onset`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .extrema import maxima
from .onset import REST_SPEED, carried_edge, soft_pause
from .rest import CLEARLY, LONG_WINDOW, Rest, leading, rest_at_end, rest_signals
from .signal import NOISE_SIGMAS, line_fit, median0, odd, row_max, runs

__all__ = ["MIN_PAUSE", "REST_SPEED", "Boundary", "Rest", "boundaries", "rest_at_end",
           "rest_signals"]

#: Shortest rest that counts as a pause [s] (the language's shortest pause is 0.2 s).
MIN_PAUSE = 0.15
#: A held joint stays within this many times its filtered noise of one position.
HELD_SIGMAS = 5.0
#: Drift of a held joint that is no motion [rad] (0.001 deg).
STILL_ANGLE = 2e-5
#: The velocity ramp beside a stop is followed up to this fraction of its peak.
RAMP_TOP = 0.6
#: The joints move the same way on both sides of a rest when the cosine between their
#: ways along the two ramps (each joint's in units of its threshold) is over this.
PASSING = 0.5
#: The ramps on both sides of a rest the motion passes through point at one stop when
#: they meet zero within this many velocity filter spans of each other; the stop is a
#: boundary of its own when no other lies within :data:`AWAY` spans of it.
AGREE = 2.0
AWAY = 4.0


@dataclass(frozen=True)
class Boundary:
    """A pause from ``t0`` to ``t1``, or the boundary between two episodes: the first
    stops at ``t0``, the next starts at ``t1`` (the same instant, unless motion too slow
    to see lies between). ``i0``..``i1`` are the grid samples it covers (inclusive)."""

    t0: float
    t1: float
    i0: int
    i1: int
    pause: bool


def _rest_runs(r: Rest) -> tuple[list[tuple[int, int]], set[int]]:
    """Runs of rest samples: isolated noise spikes inside a rest are closed, and a rest
    long enough for the slow check is split where slow motion shows; also the run ends
    that such a split made (their motion is followed with the long filter)."""
    rest = r.level < 1.0
    # A short spell of "motion" inside a rest is closed when it is a noise spike (shorter
    # than half the filter) or when no joint left the rest position by more than its
    # noise (a rounded position flickering between two neighbouring steps).
    short = r.window // 2 if r.window > 3 else 0
    longest = max(r.window, odd(0.1 / r.h))
    for i0, i1 in runs(~rest):
        if i0 == 0 or i1 == len(rest) - 1 or i1 - i0 + 1 > longest:
            continue
        away = np.abs(r.q[i0:i1 + 2] - r.q[i0 - 1]).max(axis=0)
        if i1 - i0 < short or np.all(away <= 4.0 * r.noise + 1.01 * r.quantum + 1e-12):
            rest[i0:i1 + 1] = True
    slow_edges: set[int] = set()
    if r.ratio_long is not None:
        # A full window from each end: next to a rest, the start of a slow motion looks
        # still for a while; its edge is refined, not split off.
        width = odd(LONG_WINDOW / r.h)
        for i0, i1 in runs(rest):
            a, b = i0 + width, i1 - width
            if b > a:
                slow = row_max(r.ratio_long[a:b + 1]) >= 1
                for s0, s1 in runs(slow):
                    slow_edges.update((a + s0 - 1, a + s1 + 1))
                rest[a:b + 1] &= ~slow
    return runs(rest), slow_edges


def _lead(r: Rest, seg: np.ndarray, slow: bool) -> tuple[np.ndarray, int, float] | None:
    """The velocity of the joint that leads the motion over ``seg`` (the samples beside
    a rest, away from it), signed positive and in units of its filter's threshold; the
    filter's window; and that threshold in units of the rest test's own (the long
    filter's is lower: its ramp crosses the rest test's threshold later). Of the short
    and the long filter, the one that sees the motion first (the long one sees it half
    its window early, which is allowed for), or the long one for an edge that slow
    motion made (``slow``)."""
    found = []
    # ``seg`` runs one way from the rest: the same rows as a view, without a copy.
    stop = int(seg[-1]) + (1 if seg[-1] >= seg[0] else -1)
    rows = slice(int(seg[0]), stop if stop >= 0 else None, 1 if seg[-1] >= seg[0] else -1)
    for v, thr, window, ratios in ((r.v, r.thr, r.window, r.ratio),
                                   (r.v_long, r.thr_long, 0, r.ratio_long)):
        if v is None or thr is None or ratios is None:
            continue
        width = window or odd(LONG_WINDOW / r.h)
        ratio = ratios[rows]
        moving = np.flatnonzero(row_max(ratio) > CLEARLY)
        if len(moving) == 0:
            continue
        near = ratio[moving[0]:moving[0] + max(3, width)]
        j = int(np.argmax(near.max(axis=0)))
        k = moving[0] + int(np.argmax(near[:, j]))
        vj = v[rows, j] * (1.0 if v[seg[k], j] >= 0 else -1.0) / thr[rows, j]
        up = np.flatnonzero(vj > CLEARLY)
        if len(up):
            # A filter sees motion half its window before it starts.
            found.append((int(up[0]) + width // 2, vj, width, window == 0,
                          float(thr[seg[0], j] / r.thr[seg[0], j])))
    if not found:
        return None
    found.sort(key=lambda f: (not f[3]) if slow else f[0])
    return found[0][1], found[0][2], found[0][4]


class Zero(NamedTuple):
    """Where the motion beside a rest meets zero velocity (:func:`_ramp_zero`)."""

    at: float  # the edge, within the rest and the motion's first clearly moving sample
    firm: bool  # a straight ramp was followed
    raw: float | None = None  # where the ramp followed back meets zero, anywhere
    heading: np.ndarray | None = None  # the joints' way along the ramp, in thresholds


def _ramp_zero(r: Rest, i: int, step: int, far: int, slow: bool = False) -> Zero:
    """Where the motion beside rest sample ``i`` (after it for ``step`` +1, before it for
    -1) is at zero velocity: the signed velocity of its leading joint, a straight line
    near a stop, is fitted from the edge up to :data:`RAMP_TOP` of its first peak and
    followed back to zero. The result lies between the rest sample ``far`` and the
    first clearly moving sample; motion too weak to follow leaves the edge where it is.
    Also whether a straight ramp was followed (a firm edge)."""
    if r.carried is not None:
        exact = carried_edge(r.t, r.q, *r.carried, i, step)
        if exact is not None:
            return Zero(exact, True)
    t, n = r.t, len(r.t)
    reach = max(3, int(round(1.0 / r.h)))
    seg = (np.arange(i + 1, min(i + 1 + reach, n)) if step > 0
           else np.arange(i - 1, max(i - 1 - reach, -1), -1))
    lead = _lead(r, seg, slow) if len(seg) >= 2 else None
    if lead is None:
        return Zero(float(t[i]), False)
    vj, window, unit = lead
    up = int(np.argmax(vj > CLEARLY))
    # The first peak: after the velocity is clearly up, where it falls back under 80 %
    # of its running maximum. The ramp runs from the last sample at or under zero (a
    # settling wiggle is no part of it) up to RAMP_TOP of that peak.
    run = np.maximum.accumulate(vj[up:])
    past = np.flatnonzero(vj[up:] < 0.8 * run)
    peak = run[past[0]] if len(past) else run[-1]
    m = max(up + int(np.argmax(vj[up:] >= RAMP_TOP * peak)), 2)
    low = np.flatnonzero(vj[:up] <= 0)
    first = int(low[-1]) + 1 if len(low) else 0
    ramp, vr = t[seg[first:m]], vj[first:m]
    # The motion stops between its first clearly moving sample and the far end of the
    # rest (give or take a step), and no further into the rest than its ramp takes to
    # fall through the threshold (twice that, plus the filter's reach).
    line = (line_fit(ramp - ramp[0], vr) if len(ramp) >= 2
            else None)  # the ramp's line, followed back to zero below
    slope = abs(line[0]) if line is not None else 0.0
    reach_in = 2.0 / (slope * unit) + (window // 2 + 1) * r.h if slope > 0 else math.inf
    edge = float(t[i])
    far_t = edge - step * min(abs(float(t[far]) - edge) + r.h, reach_in)
    bounds = sorted((far_t, float(t[seg[up]])))
    t0 = _zero(ramp, vr, line=line)
    if t0 is None:
        return Zero(edge, False)
    # The filter rounds the corner at the stop: samples whose window reaches across it
    # are left out of a second fit.
    keep = np.abs(ramp - t0) > (window // 2) * r.h
    if keep.all():  # none left out: the same samples, the line already fitted
        t0 = _zero(ramp, vr, straight=True, line=line)
        if t0 is None:
            return Zero(edge, False)
    elif keep.sum() >= 2:
        t0 = _zero(ramp[keep], vr[keep], straight=True)
        if t0 is None:
            return Zero(edge, False)
    return Zero(float(min(max(t0, bounds[0]), bounds[1])), True, t0,
                step * (r.q[seg[min(up + window, len(seg) - 1)]] - r.q[i]) / r.thr[i])


def _zero(t: np.ndarray, v: np.ndarray, straight: bool = False,
          line: tuple[float, ...] | None = None) -> float | None:
    """Where the velocity ``v`` (positive, over the ramp ``t``) reached zero: the line
    through it followed back. With ``straight``, None unless the ramp is a straight line
    within 10 % of its height (a ramp that bends, like a shiver's soft start, is not
    followed: its rest edge is kept). ``line``: that line's slope and intercept in
    ``t - t[0]``, when the caller has fitted it already."""
    if len(t) < 2:
        return None
    x = t - t[0]
    slope, icpt = line if line is not None else line_fit(x, v)
    if not math.isfinite(slope) or abs(slope) < 1e-15:
        return None
    if straight and len(t) >= 4:
        miss = float(np.sqrt(np.mean((slope * x + icpt - v) ** 2)))
        if miss > 0.1 * float(np.max(np.abs(v))) + 1.0 / NOISE_SIGMAS:
            return None
    return float(t[0] - icpt / slope)


def _crossings(r: Rest) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the leading joint's velocity changes sign between two samples ``i`` and
    ``i + 1``: those ``i``, the leading joint, and the speed level there (every joint's
    velocity interpolated to the crossing). Sampled a few times per cycle, an
    oscillation's samples can all miss its reversals; the level between them does not."""
    ratio = r.ratio
    # Each row's first largest, column by column (as row_max finds the largest).
    lead = ratio[:-1, 0] + ratio[1:, 0]
    j = np.zeros(len(lead), np.intp)
    for k in range(1, ratio.shape[1]):
        pair = ratio[:-1, k] + ratio[1:, k]
        ahead = pair > lead
        j[ahead] = k
        np.maximum(lead, pair, out=lead)
    va, vb = leading(r.v, j, 0), leading(r.v, j, 1)
    idx = np.flatnonzero(va * vb < 0)
    j = j[idx]
    frac = (va[idx] / (va[idx] - vb[idx]))[:, None]
    v = r.v[idx] + frac * (r.v[idx + 1] - r.v[idx])
    thr = r.thr[idx] + frac * (r.thr[idx + 1] - r.thr[idx])
    return idx, j, np.max(np.abs(v) / thr, axis=1)


def _dips(r: Rest, taken: np.ndarray) -> list[tuple[float, float, int]]:
    """Where the motion passes through zero speed without a rest sample: local minima of
    the speed level, at the samples or where the leading joint reverses between two of
    them, that fall under 30 % of the peaks on both sides. Where the leading joint
    reverses, the instant is its velocity's zero crossing; else the motion on each side
    is followed to zero as beside a rest. (stop, start, sample) each."""
    n = len(r.level)
    # The level at the samples (even places) and between them (odd places): at a
    # reversal the level there, else the larger of the two (never a minimum).
    seq = np.empty(2 * n - 1)
    seq[0::2] = r.level
    seq[1::2] = np.maximum(r.level[:-1], r.level[1:])
    cross, lead, between = _crossings(r)
    seq[2 * cross + 1] = np.minimum(between, seq[2 * cross + 1])
    joint = dict(zip(cross.tolist(), lead.tolist(), strict=True))
    # Only minima outside the rests (in a noisy recording, most of the tens of thousands
    # the noise makes lie in them: their prominences are not looked for) and under 30 %
    # of the peaks beside them.
    free = np.empty(len(seq), bool)
    free[0::2] = ~taken
    free[1::2] = ~(taken[:-1] | taken[1:])
    # Nor those that cannot be: the peak beside a minimum at or above the rest level
    # lies before the level next falls under it, so within the stretch between two
    # samples under the rest level; a minimum over 30 % of that stretch's highest
    # (with room for rounding) is over 30 % of its peaks.
    low = seq < 1.0
    starts = np.flatnonzero(np.concatenate([[True], low[1:]]))
    highest = np.repeat(np.maximum.reduceat(seq, starts), np.diff(np.append(starts, len(seq))))
    free &= low | (seq <= 0.3 * (1.0 + 1e-6) * highest)
    idx, prominences = maxima(-seq, free)
    kept = ~(seq[idx] > 0.3 * (seq[idx] + prominences))
    out = []
    v = r.v if r.carried is None else r.carried[0]
    for m, prom in zip(idx[kept].tolist(), prominences[kept].tolist(), strict=True):
        k = m // 2
        # Between two samples, a minimum is a reversal only where a joint's velocity
        # crosses zero there; else it is the middle of a flat stretch of equal levels
        # (a held sample, repeated), read at its sample as any other.
        rev = bool(m % 2) and k in joint
        if rev and seq[m] + prom < 2.0 * CLEARLY:  # noise flips a slow joint's sign
            continue
        if rev:  # a reversal between samples k and k + 1
            j = joint[k]
            pairs = [(k, k + 1), (k - 1, k), (k + 1, k + 2)]
            k = k if abs(r.v[k, j]) <= abs(r.v[k + 1, j]) else k + 1
        else:
            j = int(np.argmax(np.abs(r.v[k - 1]) / r.thr[k - 1]
                              + np.abs(r.v[k + 1]) / r.thr[k + 1]))
            pairs = [(k - 1, k), (k, k + 1)]
        a, b = next(((a, b) for a, b in pairs if 0 <= a and b < n and v[a, j] * v[b, j] <= 0),
                    pairs[0 if rev else -1])
        va, vb = v[a, j], v[b, j]
        if va * vb <= 0 and va != vb:
            tk = float(r.t[a] + (r.t[b] - r.t[a]) * va / (va - vb))
            out.append((tk, tk, k))
            continue
        t0, t1 = _ramp_zero(r, k, -1, k).at, _ramp_zero(r, k, +1, k).at
        out.append((t0, t1, k) if t1 > t0 else ((t0 + t1) / 2, (t0 + t1) / 2, k))
    return out


def boundaries(r: Rest) -> list[Boundary]:
    """Pauses and episode boundaries in time order (see the module's docstring)."""
    n = len(r.t)
    out: list[Boundary] = []
    taken = np.zeros(n, bool)
    found, slow = _rest_runs(r)
    edge = r.window // 2  # the filter's reach: a rest that close to an end starts there
    pointed: list[float] = []
    for i0, i1 in found:
        i0 = 0 if i0 <= edge else i0
        i1 = n - 1 if i1 >= n - 1 - edge else i1
        taken[i0:i1 + 1] = True
        z0 = Zero(float(r.t[0]), False) if i0 == 0 else _ramp_zero(r, i0, -1, i1, i0 in slow)
        z1 = Zero(r.t_last, False) if i1 == n - 1 else _ramp_zero(r, i1, +1, i0, i1 in slow)
        t0, t1 = z0.at, z1.at
        h0, h1, ref = _held(r, t0, t1) if t1 - t0 >= MIN_PAUSE else (t0, t0, None)
        if h1 - h0 >= max(MIN_PAUSE, 0.5 * (t1 - t0)):
            # Motion too slow to see in the speed but not in the positions (the soft
            # start of a shiver) is no part of the hold. What is left of it may be too
            # short for a pause: the whole rest was a shiver's soft end or start,
            # hidden under the noise, and it is the instant between two episodes.
            a, b = soft_pause(r.t, r.q, r.noise, (max(t0, h0), min(t1, h1)), ref)
            if b - a >= MIN_PAUSE:
                out.append(Boundary(a, b, i0, i1, True))
                continue
            t0, t1 = a, b
        if 0 < i0 and i1 < n - 1:
            passing = _passing(r, z0, z1, i0, i1)
            if passing is not None:
                if passing[1]:
                    pointed.append(passing[0])
                continue
            # The instant between two episodes; when motion too slow to see fills the
            # gap between where one stops and the next starts, that gap belongs to
            # neither (it is the soft end of a shiver, or its soft start).
            t0, t1 = (t0, t1) if t1 > t0 else ((t0 + t1) / 2,) * 2
            out.append(Boundary(t0, t1, i0, i1, False))
    # Where the motion passing through a rest stops, unless a rest is found there: the
    # noise can hide a stop between two slow motions the same way (the second starts
    # before the first is seen to stop).
    near = AWAY * r.window * r.h
    for stop in pointed:
        if r.t[0] < stop < r.t_last and not any(b.t0 - near <= stop <= b.t1 + near
                                                for b in out):
            k = int(np.clip(np.searchsorted(r.t, stop), 0, n - 1))
            out.append(Boundary(stop, stop, k, k, False))
    for t0, t1, k in _dips(r, taken):
        out.append(Boundary(t0, t1, k, k, False))
    out.sort(key=lambda b: b.t0)
    return _merged(out)


def _passing(r: Rest, z0: Zero, z1: Zero, i0: int, i1: int) -> tuple[float, bool] | None:
    """Where the motion passing through the rest run ``i0``..``i1`` stops (or starts),
    and whether its two ramps agree on it; None when it stops in the run. It passes
    through when the joints move the same way on both sides of the run and both ramps,
    followed back to zero, meet it beyond the same end of the run (by more than the
    velocity filter's span): noise hides a slow motion's start or end under the
    threshold for a while, and may let it out again for a few samples, and the short
    rest between is no stop. The stop is the nearer of the two zeros; ramps that meet
    zero more than :data:`AGREE` spans apart give no reading of it."""
    if z0.raw is None or z1.raw is None or z0.heading is None or z1.heading is None:
        return None
    if z0.heading @ z1.heading <= PASSING * np.linalg.norm(z0.heading) * np.linalg.norm(
            z1.heading):
        return None
    margin = r.window * r.h
    lo, hi = sorted((z0.raw, z1.raw))
    agree = hi - lo <= AGREE * margin
    if lo > r.t[i1] + margin:
        return lo, agree
    return (hi, agree) if hi < r.t[i0] - margin else None


def _held(r: Rest, t0: float, t1: float
          ) -> tuple[float, float, tuple[tuple[int, int], np.ndarray] | None]:
    """The longest stretch of ``t0``..``t1`` in which the joints stay within their noise
    of one position (the one they hold in its middle third): a pause is a hold. The
    speed of a motion can hide under the noise for a while (the soft ends of two
    shivers back to back); its positions cannot. Also, for positions tested unfiltered,
    the held one and its grid samples (inclusive), for :func:`.onset.soft_pause`."""
    k0 = int(np.searchsorted(r.t, t0, "left"))
    k1 = int(np.searchsorted(r.t, t1, "right"))
    p = r.held(k0, k1)
    if len(p) < 3:
        return t0, t0, None
    # A gap leaves fewer raw samples per filtered value (more noise); none scales by 1.
    band = HELD_SIGMAS * r.noise * r.held_gain
    band = (band if r.gapless else band * r.sparse[k0:k1, None]) + 1.01 * r.quantum + STILL_ANGLE
    third = len(p) // 3
    ref = median0(p[third:len(p) - third])
    inside = ~row_max(np.abs(p - ref) > band)  # every joint near (by columns: rows are short)
    # A brief excursion inside is noise (a logging gap); one at an end is motion.
    for a, b in runs(~inside):
        if a > 0 and b < len(inside) - 1 and b - a < r.window:
            inside[a:b + 1] = True
    a, b = max(runs(inside), key=lambda ab: ab[1] - ab[0], default=(0, -1))
    if b < a:
        return t0, t0, None
    return (t0 if a == 0 else float(r.t[k0 + a]),
            t1 if b == len(p) - 1 else float(r.t[k0 + b]),
            ((k0, k1 - 1), ref) if r.window <= 3 else None)


def _merged(bounds: list[Boundary]) -> list[Boundary]:
    """Boundaries that overlap once refined are one (a pause if either is)."""
    out: list[Boundary] = []
    for b in bounds:
        last = out[-1] if out else None
        if last is not None and b.t0 <= last.t1 + 1e-9:
            out[-1] = Boundary(min(last.t0, b.t0), max(last.t1, b.t1), min(last.i0, b.i0),
                               max(last.i1, b.i1), last.pause or b.pause)
            continue
        out.append(b)
    return out
