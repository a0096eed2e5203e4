"""The speeding-up and slowing-down phases of an approach or a retreat.

A computed approach speeds up once and slows down once. A hand moved by a person often
surges: it slows down well below its top speed in the middle of the motion and speeds up
again. Each surge is a motion of its own, with its own speed-up and slow-down, and its
acceleration can be the episode's peak; reading only the first speed-up and the last
slow-down (from the episode's top speed) would leave it unread and report a lower peak
with full confidence.

- **Surges.** The hand's speed along its travel is split at each dip: a local minimum
  below :data:`DIP` of the top speed both before it (since the last dip) and after it
  (up to the next), where both of those tops reach :data:`SURGE` of the episode's top
  speed (a wobble of a hand near rest is no surge) and stand more than :data:`DISTINCT`
  stds of the filtered speed's noise above the dip (a wobble of the noise is none). The
  speed is first averaged over :data:`SPAN`: a hand's surge lasts longer, a tremor or
  a jittered clock's wobble does not; and a surge lasts at least that long (a dip
  closer to the piece's ends or to the dip before is none), and the first and the last
  reach their top at least that far inside the piece (a speed highest at the piece's
  edge is the filter's edge, or a motion cut there). A motion with one speed-up
  and one slow-down has no dip: it is one surge, read as before.
- **Phases.** In each surge, from its start to the first sample at 95 % of its own top
  speed (the speed-up), and from the last such sample to its end (the slow-down); each
  is read up to or from its top speed beside it (a bang-bang law's switch). At a dip the
  acceleration turns from slowing down to speeding up: its step there is up to twice
  the level (the transients it leaves in a recording grow with it).
- **A motion cut by the recording.** A phase at the recording's first or last sample,
  where the arm is not at rest, is cut: it is left out (unless nothing else is left),
  as before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .signal import centred_mean

__all__ = ["DIP", "DISTINCT", "SPAN", "SURGE", "Phase", "phases", "surges"]

#: A dip splits two surges when the speed there is below this share of both tops.
DIP = 0.8
#: ... and both tops reach this share of the episode's top speed.
SURGE = 0.25
#: ... and both tops stand this many stds of the speed's noise above the dip.
DISTINCT = 6.0
#: The speed is averaged over this long [s] before its dips are looked for.
SPAN = 0.1


@dataclass(frozen=True)
class Phase:
    """A phase's samples ``a``..``b`` of its piece, the samples ``lo``..``hi`` its
    peak is looked for in (up to or from its surge's top speed), and whether it starts
    or ends at a dip between two surges."""

    a: int
    b: int
    lo: int
    hi: int
    at_dip: bool = False


def surges(speed: np.ndarray, h: float, noise: float = 0.0) -> list[tuple[int, int]]:
    """The surges of a piece: sample ranges ``(start, end)`` of ``speed`` (N,), sampled
    every ``h`` [s] with a noise std of ``noise``, the first starting at 0, the last
    ending at N - 1, each next starting at the dip where the one before ends (see the
    module's docstring)."""
    n = len(speed)
    if n < 3:
        return [(0, n - 1)]
    half = min(int(0.5 * SPAN / h), (n - 1) // 2)
    if half > 0:
        speed = centred_mean(speed, half)
    dips = _dips(speed, SURGE * float(speed.max()), DISTINCT * noise)
    least_span, kept = max(1, int(round(SPAN / h))), [0]
    for d in dips:
        if d - kept[-1] >= least_span and n - 1 - d >= least_span:
            kept.append(d)
    # A surge at either end of the piece has its top inside it: a speed highest at the
    # piece's first or last samples is a filter's edge or a cut motion, not a surge.
    if len(kept) > 1 and int(np.argmax(speed[:kept[1] + 1])) < least_span:
        kept.pop(1)
    if len(kept) > 1 and n - 1 - (kept[-1] + int(np.argmax(speed[kept[-1]:]))) < least_span:
        kept.pop()
    bounds = [*kept, n - 1]
    return list(zip(bounds[:-1], bounds[1:], strict=True))


def _dips(speed: np.ndarray, least: float, rise: float) -> list[int]:
    """The dips of the finite ``speed`` (N,): a walk that, rising, keeps the top since
    the last dip and starts falling at the first sample under :data:`DIP` of it (by more
    than ``rise``, the top at least ``least``); falling, keeps the lowest sample (the
    first of equal ones), and rises again at the first sample not under it that it is
    under :data:`DIP` of (by more than ``rise``, the sample at least ``least``): that
    lowest sample is a dip. Each stretch of the walk is found with running maxima and
    minima over the samples left, not one sample at a time."""
    dips: list[int] = []
    n, i = len(speed), 0  # the walk rises from sample i, its top first speed[i]
    while i < n - 1:
        top = np.maximum.accumulate(speed[i:])
        fall = np.flatnonzero((top[1:] >= least) & (speed[i + 1:] < DIP * top[1:])
                              & (top[1:] - speed[i + 1:] > rise))
        if len(fall) == 0:
            break
        f = i + 1 + int(fall[0])  # falling from here, the lowest first speed[f]
        low = np.minimum.accumulate(speed[f:])[:-1]  # the lowest before each next sample
        after = speed[f + 1:]
        up = np.flatnonzero((after >= low) & (after >= least) & (low < DIP * after)
                            & (after - low > rise))
        if len(up) == 0:
            break
        r = f + 1 + int(up[0])
        dips.append(f + int(np.argmin(speed[f:r])))
        i = r
    return dips


def phases(speed: np.ndarray, h: float, at_rest0: bool, at_rest1: bool,
           noise: float = 0.0) -> list[Phase]:
    """The phases of a piece whose hand moves at ``speed`` (N,) along its travel
    (sampled every ``h`` [s], with a noise std of ``noise``), which
    starts (``at_rest0``) and ends (``at_rest1``) where the arm was at rest, or else at
    the recording's first or last sample (see the module's docstring)."""
    n = len(speed)
    runs = surges(speed, h, noise)
    out: list[Phase] = []
    for k, (s, e) in enumerate(runs):
        part = speed[s:e + 1]
        top_v = float(part.max())
        fast = np.flatnonzero(part >= 0.95 * top_v)
        a, b = s + int(fast[0]), s + int(fast[-1])
        top = a + int(np.argmax(speed[a:b + 1]))
        if k > 0 or at_rest0:
            out.append(Phase(s, a, s, top, k > 0))
        if k < len(runs) - 1 or at_rest1:
            out.append(Phase(b, e, top, e, k < len(runs) - 1))
    return out or [Phase(0, n - 1, 0, n - 1)]
