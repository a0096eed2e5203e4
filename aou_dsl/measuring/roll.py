"""Rolls of the hand in place: tilts and shivers.

The roll is measured about the hand's own forward axis and unwrapped (a 200 deg tilt
reads 200, not 160). Each roll piece between two stops is a *lobe* of the turning
joint's velocity. A tilt is a deliberate rest-to-rest roll: its speed rises and falls
linearly (a triangle, peak speed twice the mean). A shiver is an oscillation: its lobes
alternate in direction at one frequency, and its speed rises and falls like a sine
(peak speed pi/2 times the mean). The two are told apart by that speed profile and by
the frequency (lobes of one shiver last equally long), not by counting reversals: three
slow tilts back and forth stay three tilts, and a tremor between two tilts does not
swallow them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..descriptors import EpisodeValues
from .episodes import Context, Piece

__all__ = ["MIN_TILT", "Lobe", "lobe", "roll_angle", "rotations"]

#: Smallest roll reported as a tilt [deg] (the tilt tolerance is 0.5 deg).
MIN_TILT = 0.5
#: Smallest turn of a joint or roll that is a lobe at all [deg].
MIN_LOBE = 0.05
#: Lobes of one shiver last within this factor of their median.
SAME_FREQUENCY = 1.8


def roll_angle(rot: np.ndarray) -> np.ndarray:
    """The roll about the hand's forward (z) axis since the first sample [rad], (N,):
    the twist of each step's relative rotation, summed (so turns past 180 deg keep
    counting)."""
    rel = np.einsum("nji,njk->nik", rot[:-1], rot[1:])
    step = np.arctan2(rel[:, 1, 0] - rel[:, 0, 1], rel[:, 0, 0] + rel[:, 1, 1])
    return np.concatenate([[0.0], np.cumsum(step)])


@dataclass(frozen=True)
class Lobe:
    """A roll piece: its piece, roll change [deg] (signed), the joint that turned most,
    that joint's range [deg], and its shape: > 0 when the speed profile is closer to a
    sine than to a triangle, < 0 the other way, 0 when too short to tell."""

    piece: Piece
    roll: float
    joint: int
    swing: float
    shape: float
    turn: float  # the joint's signed change [rad]

    @property
    def duration(self) -> float:
        return self.piece.t1 - self.piece.t0

    @property
    def sign(self) -> float:
        if abs(self.roll) >= MIN_LOBE:
            return math.copysign(1.0, self.roll)
        return math.copysign(1.0, self.turn) if self.turn else 0.0


def _shape(c: Context, p: Piece, j: int) -> float:
    """Residual of the best triangle minus that of the best half sine, fitted to the
    joint's velocity over the lobe (each relative to the velocity's norm)."""
    t = c.rest.t[p.i0:p.i1 + 1]
    v = c.rest.v[p.i0:p.i1 + 1, j]
    if len(t) < 5 or p.t1 <= p.t0:
        return 0.0
    u = np.clip((t - p.t0) / (p.t1 - p.t0), 0.0, 1.0)
    norm = float(np.linalg.norm(v))
    if norm == 0.0:
        return 0.0
    out = []
    for tmpl in (1.0 - np.abs(2.0 * u - 1.0), np.sin(math.pi * u)):
        k = float(v @ tmpl) / float(tmpl @ tmpl)
        out.append(float(np.linalg.norm(v - k * tmpl)) / norm)
    return out[0] - out[1]


def lobe(c: Context, p: Piece) -> Lobe | None:
    """The roll piece ``p`` as a lobe; None when nothing turned beyond the noise."""
    seg = c.q[p.i0:p.i1 + 1]
    rng = np.ptp(seg, axis=0) - 6.0 * c.noise
    j = int(np.argmax(rng))
    roll = math.degrees(p.roll1 - p.roll0)
    swing = math.degrees(float(max(rng[j], 0.0)))
    if max(abs(roll), swing) < MIN_LOBE:
        return None
    return Lobe(p, roll, j, swing, _shape(c, p, j), float(seg[-1, j] - seg[0, j]))


def _alternating(lobes: list[Lobe]) -> list[tuple[int, int]]:
    """Maximal index ranges of lobes that alternate in direction."""
    out, start = [], 0
    for k in range(1, len(lobes) + 1):
        if k == len(lobes) or lobes[k].sign * lobes[k - 1].sign >= 0:
            out.append((start, k - 1))
            start = k
    return out


def _shiver_block(lobes: list[Lobe], a: int, b: int) -> tuple[int, int] | None:
    """Within alternating lobes a..b, the oscillation: from the first to the last
    sine-like lobe, with the small ramp lobes beside them, trimmed of lobes much longer
    than the rest (a tilt beside a tremor); None when it is no oscillation."""
    sine = [k for k in range(a, b + 1) if lobes[k].shape > 0]
    if not sine:
        return None
    lo, hi = sine[0], sine[-1]
    while lo > a and lobes[lo - 1].shape >= 0:
        lo -= 1
    while hi < b and lobes[hi + 1].shape >= 0:
        hi += 1
    med = float(np.median([lobes[k].duration for k in range(lo, hi + 1)]))
    while lo < hi and lobes[lo].duration > SAME_FREQUENCY * med:
        lo += 1
    while hi > lo and lobes[hi].duration > SAME_FREQUENCY * med:
        hi -= 1
    weight = sum(max(abs(lobes[k].roll), lobes[k].swing) * lobes[k].shape
                 for k in range(lo, hi + 1))
    if hi - lo + 1 < 3 or weight <= 0:
        return None
    # A lobe beside the oscillation at its frequency, not clearly a tilt, is part of it
    # (a ramp lobe that noise made look less like a sine).
    while lo > a and _same_beat(lobes[lo - 1], med):
        lo -= 1
    while hi < b and _same_beat(lobes[hi + 1], med):
        hi += 1
    return lo, hi


def _same_beat(lb: Lobe, median: float) -> bool:
    return (median / SAME_FREQUENCY <= lb.duration <= SAME_FREQUENCY * median
            and lb.shape > -0.08)


def _shiver(c: Context, lobes: list[Lobe]) -> EpisodeValues:
    t0, t1 = lobes[0].piece.t0, lobes[-1].piece.t1
    i0, i1 = lobes[0].piece.i0, lobes[-1].piece.i1
    rng = np.ptp(c.q[i0:i1 + 1], axis=0)
    j = int(np.argmax(rng))
    return EpisodeValues("shiver", t0, t1, {
        "amplitude": math.degrees(float(rng[j])), "joint": float(j),
        "cycles": len(lobes) / 2.0})


def _tilt(lb: Lobe) -> EpisodeValues | None:
    angle = abs(lb.roll)
    if angle < MIN_TILT:
        return None
    return EpisodeValues("tilt", lb.piece.t0, lb.piece.t1, {
        "angle": angle, "signed": lb.roll, "velocity": angle / max(lb.duration, 1e-9),
        "joint": float(lb.joint)})


def rotations(c: Context, lobes: list[Lobe]) -> list[EpisodeValues]:
    """Consecutive lobes (no pause or translation between them) as tilts and shivers."""
    out: list[EpisodeValues] = []
    k = 0
    blocks = []
    for a, b in _alternating(lobes):
        blk = _shiver_block(lobes, a, b)
        if blk is not None:
            blocks.append(blk)
    for lo, hi in blocks:
        out += [e for e in (_tilt(lb) for lb in lobes[k:lo]) if e is not None]
        out.append(_shiver(c, lobes[lo:hi + 1]))
        k = hi + 1
    out += [e for e in (_tilt(lb) for lb in lobes[k:]) if e is not None]
    return out
