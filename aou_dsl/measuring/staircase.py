"""A coarse encoder's staircase read back as the motion it rounds.

An encoder that counts in steps coarser than its noise logs a staircase: the value
stays on one step while the joint moves across it, then jumps. Filtered as it is, a
slow motion's speed rises at each jump and falls between them, and the dips between
jumps read as the motion stopping: one retreat read as five, a shiver's rounded
swing read as a pause.

What the staircase does say exactly is *when* the joint crossed the middle between
two steps: at a jump, between the sample before and the sample after. So the joint
is read as passing through that middle at the jump (the midpoint of the two samples'
times), and moving at an even pace from one crossing to the next. A step held much
longer than the joint took to cross the steps beside it is a hold: the joint is read
as reaching the step's value at the pace it arrived with, staying there, and leaving
at the pace it left with. Before the first jump and after the last one the joint
holds its step.

Only joints whose rounding is coarser than their white noise are read this way
(where noise makes the samples dither, every jump is a crossing too, but the noise
is what the filters already expect).
"""

from __future__ import annotations

import math

import numpy as np

from .signal import JointNoise

#: A step held longer than this many times its neighbours' crossing times (together)
#: is a hold, not a slow crossing.
HOLD = 1.0


def staircase_joints(jn: JointNoise) -> np.ndarray:
    """Whether each joint logs a staircase: it moves, and its rounding's error (std
    quantum / sqrt(12)) is larger than its white noise."""
    return jn.moving & (jn.quantum > 0) & (jn.quantum / math.sqrt(12.0) > jn.sigma)


def dequantised(t: np.ndarray, q: np.ndarray, jn: JointNoise) -> np.ndarray:
    """``q`` (samples x joints, at times ``t``) with each staircase joint's column read
    as the motion through its crossings (the module's rule); other columns as they
    are. ``q`` itself is not changed."""
    stairs = np.flatnonzero(staircase_joints(jn))
    if not len(stairs):
        return q
    out = np.array(q, dtype=float, copy=True)
    for j in stairs:
        out[:, j] = _through_crossings(t, out[:, j])
    return out


def held_offsets(t: np.ndarray, q: np.ndarray, jn: JointNoise, rng: np.random.Generator
                 ) -> np.ndarray:
    """Where within its step each staircase joint may truly have been while it held,
    drawn afresh: per joint and sample, an offset uniform over one step at each end of
    each hold (drawn on its own: a hold may be a slow drift within its step), none at
    a crossing (its value is known), and even between knots. The re-noised copies add
    it: a shift of the whole grid moves both ends of a motion alike, where each end's
    hold lies anywhere in its step on its own; and a short hold, slow motion or rest,
    is told apart only where the copies agree."""
    out = np.zeros(np.shape(q))
    for j in np.flatnonzero(staircase_joints(jn)):
        kt, _, hold = _knots(t, np.asarray(q[:, j], float))
        if not len(kt):
            continue
        u = rng.uniform(-0.5, 0.5, len(kt)) * float(jn.quantum[j])
        out[:, j] = np.interp(t, kt, np.where(hold, u, 0.0))
    return out


def _through_crossings(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    kt, kv, _ = _knots(t, x)
    return x if not len(kt) else np.interp(t, kt, kv)


def _knots(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The motion's knots through a staircase ``x``: times, values, and whether each is
    one of a hold's two (else a crossing). None when ``x`` never steps."""
    jumps = np.flatnonzero(x[1:] != x[:-1]) + 1  # the first sample on a new step
    if not len(jumps):
        return np.empty(0), np.empty(0), np.empty(0, bool)
    at = (t[jumps - 1] + t[jumps]) / 2
    middle = (x[jumps - 1] + x[jumps]) / 2
    # The time each step is held: from the crossing onto it to the crossing off it
    # (the first and the last run to the log's ends).
    edges = np.concatenate(([t[0]], at, [t[-1]]))
    held = np.diff(edges)
    level = np.concatenate(([x[0]], x[jumps]))
    # A step's neighbours' crossing times; at the log's ends, the one neighbour's.
    before = np.concatenate(([held[1] if len(held) > 1 else held[0]], held[:-1]))
    after = np.concatenate((held[1:], [held[-2] if len(held) > 1 else held[0]]))
    n = len(held)
    k = np.arange(n)
    holds = (k == 0) | (k == n - 1) | (held > HOLD * (before + after))
    # Reached at the pace it arrived with (at once where the log starts on it), left at
    # the pace it left with (held to the log's end).
    reach = np.where(k == 0, edges[:-1], edges[:-1] + before / 2)
    leave = np.where(k == n - 1, edges[1:], edges[1:] - after / 2)
    holds &= leave > reach
    # Per step, in time order: the crossing onto it (none for the first), its reach and
    # its leave (a hold's only).
    times = np.stack([np.concatenate(([t[0]], at)), reach, leave], axis=1)
    values = np.stack([np.concatenate(([x[0]], middle)), level, level], axis=1)
    kept = np.stack([k > 0, holds, holds], axis=1)
    is_hold = np.broadcast_to(np.array([False, True, True]), kept.shape)
    return times[kept], values[kept], is_hold[kept]
