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
from dataclasses import dataclass, replace

import numpy as np

from ..core.codes import R407
from ..core.diagnostics import Diagnostic, Span, diag
from ..lang.descriptors import EpisodeValues
from ..lang.primitives import SHIVER, TILT
from .episodes import Context, Piece

__all__ = ["MIN_TILT", "SHAPED_CYCLE", "Lobe", "lobe", "roll_angle", "rotations",
           "undersampled"]

#: Smallest roll reported as a tilt [deg] (the tilt tolerance is 0.5 deg).
MIN_TILT = 0.5
#: Smallest turn of a joint or roll that is a lobe at all [deg].
MIN_LOBE = 0.05
#: Lobes of one shiver last within this factor of their median.
SAME_FREQUENCY = 1.8
#: Fewest samples of a lobe whose velocity shows its shape; shorter lobes are judged by
#: their positions, together with their neighbours (:func:`_block_shapes`).
SHAPED = 5
#: A lobe shorter than this many sample steps is too coarsely sampled to show its
#: shape: three or more in a row that are no shiver are reported as neither (R407).
COARSE = 2.5
#: Samples per cycle from which an oscillation's shape is told (its lobes' positions
#: judged together); a coarser one is reported as neither a shiver nor tilts (R407).
SHAPED_CYCLE = 6
#: The shape of a pure sine lobe's speed (a triangle's is minus that): the residual of
#: fitting one of the two to the other, relative to its norm.
SINE_SHAPE = 0.12


def roll_angle(rot: np.ndarray) -> np.ndarray:
    """The roll about the hand's forward (z) axis since the first sample [rad], (N,):
    the twist of each step's relative rotation, summed (so turns past 180 deg keep
    counting). Only the four entries of each relative rotation ``R_k^T R_{k+1}`` that
    the twist needs are formed, each summed from zero in the order of the inner index
    (as a matrix product of the stack would, at a fifth of its cost)."""
    a, b = rot[:-1], rot[1:]

    def rel(i: int, k: int) -> np.ndarray:
        return ((0.0 + a[:, 0, i] * b[:, 0, k]) + a[:, 1, i] * b[:, 1, k]) + a[:, 2, i] * b[:, 2, k]

    step = np.arctan2(rel(1, 0) - rel(0, 1), rel(0, 0) + rel(1, 1))
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
    joint's velocity over the lobe (each relative to the velocity's norm); 0 for a lobe
    of fewer than :data:`SHAPED` samples (:func:`_block_shapes` judges those)."""
    t = c.rest.t[p.i0:p.i1 + 1]
    v = c.rest.v[p.i0:p.i1 + 1, j]
    if len(t) < SHAPED or p.t1 <= p.t0:
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


def _rise(u: np.ndarray, sine: bool) -> np.ndarray:
    """A lobe's position from 0 to 1 over ``u`` in [0, 1]: at a sine's speed, or at a
    triangle's (a rest-to-rest tilt: constant acceleration, then deceleration)."""
    if sine:
        return 0.5 * (1.0 - np.cos(math.pi * u))
    return np.where(u <= 0.5, 2.0 * u * u, 1.0 - 2.0 * (1.0 - u) ** 2)


def _block_shapes(c: Context, lobes: list[Lobe]) -> list[float]:
    """The shapes of consecutive lobes too short for a velocity's shape, from their
    positions: the joint passes through one extreme at each reversal, and between two it
    rises as a sine's or a triangle's speed would take it. Both models are fitted to all
    the lobes at once (the extremes shared by neighbours; a lobe of a few samples alone
    could not tell them apart); each lobe's shape is its two residuals' difference over
    their sum and the noise's, scaled like a velocity's shape (a sine's is
    +:data:`SINE_SHAPE`, a triangle's minus that). Lobes under 3 samples get 0."""
    j = max(lobes, key=lambda lb: lb.swing).joint
    r = c.rest
    edges: list[float] = []
    rows, cols, ends, owner = [], [], [], []
    for k, lb in enumerate(lobes):
        p = lb.piece
        if not edges or p.t0 > edges[-1] + 1e-9:
            edges.append(p.t0)
        e0 = len(edges) - 1
        edges.append(p.t1)
        idx = np.arange(p.i0, p.i1 + 1)
        rows.append(idx)
        cols.append((r.t[idx] - p.t0) / max(p.t1 - p.t0, 1e-12))
        ends.append(e0)
        owner.append(np.full(len(idx), k))
    idx, u, who = np.concatenate(rows), np.clip(np.concatenate(cols), 0, 1), np.concatenate(owner)
    e0 = np.asarray(ends)[who]
    y = r.q[idx, j]
    res = []
    for sine in (False, True):
        rise = _rise(u, sine)
        a = np.zeros((len(idx), len(edges)))
        a[np.arange(len(idx)), e0] = 1.0 - rise
        a[np.arange(len(idx)), e0 + 1] = rise
        miss = y - a @ np.linalg.lstsq(a, y, rcond=None)[0]
        res.append(np.bincount(who, miss * miss, minlength=len(lobes)))
    count = np.bincount(who, minlength=len(lobes))
    total = res[0] + res[1] + 9.0 * float(c.noise[j]) ** 2 * count
    return [SINE_SHAPE * float((res[0][k] - res[1][k]) / total[k])
            if count[k] >= 3 and total[k] > 0 else 0.0 for k in range(len(lobes))]


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


def _extreme(y: np.ndarray, k: int, sign: float, most: float) -> float:
    """The extreme of ``y`` at sample ``k`` (``sign`` +1 a maximum, -1 a minimum), with
    the part its samples missed: the parabola through it and its neighbours peaks
    between them. The correction is at most ``most`` (what samples this far apart can
    miss of a sine), so that noise on finely sampled data adds nothing."""
    if k == 0 or k == len(y) - 1:
        return float(y[k])
    a = 0.5 * (y[k + 1] - 2.0 * y[k] + y[k - 1]) * sign
    b = 0.5 * (y[k + 1] - y[k - 1])
    miss = -b * b / (4.0 * a) if a < 0 else 0.0
    return float(y[k]) + sign * min(max(miss, 0.0), most)


def _shiver(c: Context, lobes: list[Lobe]) -> EpisodeValues:
    """A shiver: the peak-to-peak range of the joint that moved most, its extremes read
    between the samples when they are a few per cycle."""
    t0, t1 = lobes[0].piece.t0, lobes[-1].piece.t1
    i0, i1 = lobes[0].piece.i0, lobes[-1].piece.i1
    seg = c.q[i0:i1 + 1]
    rng = np.ptp(seg, axis=0)
    j = int(np.argmax(rng))
    per_cycle = 2.0 * float(np.median([lb.duration for lb in lobes])) / c.rest.h
    most = 0.5 * float(rng[j]) * (1.0 - math.cos(math.pi / max(per_cycle, 2.0)))
    y = seg[:, j]
    top = _extreme(y, int(np.argmax(y)), 1.0, most)
    bottom = _extreme(y, int(np.argmin(y)), -1.0, most)
    return EpisodeValues(SHIVER, t0, t1, {
        "amplitude": math.degrees(top - bottom), "joint": float(j),
        "cycles": len(lobes) / 2.0, "frequency": _frequency(lobes)})


def _frequency(lobes: list[Lobe]) -> float:
    """A shiver's frequency [Hz]: a lobe is one swing, half a cycle. The swings that fade
    it in and out are shorter than the full ones, so it is read from the full ones (the
    lobes within 15 % of the longest)."""
    longest = max(lb.duration for lb in lobes)
    full = [lb.duration for lb in lobes if lb.duration >= 0.85 * longest]
    return 0.5 / max(float(np.median(full)), 1e-9)


def _tilt(lb: Lobe) -> EpisodeValues | None:
    angle = abs(lb.roll)
    if angle < MIN_TILT:
        return None
    return EpisodeValues(TILT, lb.piece.t0, lb.piece.t1, {
        "angle": angle, "signed": lb.roll, "velocity": angle / max(lb.duration, 1e-9),
        "joint": float(lb.joint)})


def _coarse(lobes: list[Lobe], taken: set[int], h: float) -> list[tuple[int, int]]:
    """Runs of lobes sampled too coarsely to tell a shiver from tilts: three or more in a
    row (outside the shivers ``taken``), each lasting under :data:`COARSE` sample steps
    ``h`` [s]. Sampled that coarsely an oscillation's swings lose their reversals between
    samples, so they need not alternate or last alike."""
    out: list[tuple[int, int]] = []
    few = [k not in taken and lb.duration < COARSE * h for k, lb in enumerate(lobes)]
    k = 0
    while k < len(lobes):
        end = k
        while few[k] and end + 1 < len(lobes) and few[end + 1]:
            end += 1
        if few[k] and end - k >= 2:
            out.append((k, end))
        k = end + 1
    return out


def _oscillation(c: Context, lobes: list[Lobe]) -> tuple[float, float, float]:
    """Start, end [s] and samples per cycle of coarsely sampled lobes: the joint that
    swung most turns back once per half cycle (its steps change sign), whichever
    reversals fell between samples."""
    t0, t1 = lobes[0].piece.t0, lobes[-1].piece.t1
    j = max(lobes, key=lambda lb: lb.swing).joint
    steps = np.sign(np.diff(c.q[lobes[0].piece.i0:lobes[-1].piece.i1 + 1, j]))
    steps = steps[steps != 0]
    turns = int(np.count_nonzero(steps[1:] != steps[:-1]))
    cycle = 2.0 * (t1 - t0) / turns if turns else 2.0 * (t1 - t0) / len(lobes)
    return t0, t1, cycle / c.rest.h


def rotations(c: Context, lobes: list[Lobe],
              coarse: list[tuple[float, float, float]] | None = None) -> list[EpisodeValues]:
    """Consecutive lobes (no pause or translation between them) as tilts and shivers.
    An oscillation sampled too coarsely to tell which is neither: it is added to
    ``coarse`` as (start, end [s], samples per cycle)."""
    lobes = list(lobes)
    out: list[EpisodeValues] = []
    blocks: list[tuple[int, int]] = []
    for a, b in _alternating(lobes):
        short = [k for k in range(a, b + 1) if lobes[k].piece.i1 - lobes[k].piece.i0 + 1 < SHAPED]
        if short and b > a:
            shapes = _block_shapes(c, lobes[a:b + 1])
            for k in short:
                lobes[k] = replace(lobes[k], shape=shapes[k - a])
        blk = _shiver_block(lobes, a, b)
        if blk is not None:
            blocks.append(blk)
    skip: set[int] = set()
    taken = {k for first, end in blocks for k in range(first, end + 1)}
    for lo, hi in _coarse(lobes, taken, c.rest.h):
        skip.update(range(lo, hi + 1))
        if coarse is not None:
            coarse.append(_oscillation(c, lobes[lo:hi + 1]))
    k = 0
    for lo, hi in blocks:
        out += [e for i in range(k, lo) if i not in skip and (e := _tilt(lobes[i])) is not None]
        out.append(_shiver(c, lobes[lo:hi + 1]))
        k = hi + 1
    out += [e for i in range(k, len(lobes)) if i not in skip and (e := _tilt(lobes[i])) is not None]
    return out


def undersampled(where: Span, t0: float, t1: float, per_cycle: float, h: float
                  ) -> Diagnostic:
    """R407: an oscillation sampled too coarsely to tell a shiver from tilts."""
    f = 1.0 / (per_cycle * h)
    return diag(R407, f"the hand rolls back and forth at about {f:.2g} Hz from t={t0:.3f}s to "
                f"t={t1:.3f}s, sampled {per_cycle:.2g} times per cycle: too few to tell a "
                "shiver from tilts by its speed profile, so it is reported as neither",
                where, hint=f"sample it at {math.ceil(SHAPED_CYCLE * f)} Hz or more "
                f"({SHAPED_CYCLE} samples per cycle)", start=t0, end=t1,
                frequency=f, samples_per_cycle=per_cycle)
