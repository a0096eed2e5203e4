"""The measurement's shorter ways to numbers it computed before, against the plain ways,
to the bit: the soft edge of a hold (its joint picked from each joint's largest deviation,
its lobe's swings counted), the self-check's five samples, the clock's uniformity, the
leading joint's velocities, the median of unequal episodes, the hold test of a log
without a gap, a hold's position found once for its two edges, a piece's phases found by
index on the grid's own clock and a pause's anchor averaged once. Each plain form is
written here as the code read before: NumPy's general calls, on values that tell them
apart (signed zeros, ties, magnitudes over many decades, both layouts of the joints)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from aou_dsl.measuring import holds, onset
from aou_dsl.measuring.episode_spread import _median
from aou_dsl.measuring.episodes import Samples, _five, _length, pieces, translation
from aou_dsl.measuring.onset import (
    CLEAR,
    FIT_SHAPE,
    FIT_SIGMAS,
    HOLD_SPAN,
    LOBE,
    MOTION_SPAN,
    ONSET_TOP,
    POWERS,
    RATES,
    SWING,
    _angular,
    _best,
    _swings,
    held_at,
    soft_edge,
    soft_pause,
)
from aou_dsl.measuring.rest import leading as _leading
from aou_dsl.measuring.signal import _uniform


def _plain_swings(d: np.ndarray, level: float) -> int:
    side = np.sign(d) * (np.abs(d) > level)
    side = side[side != 0]
    return int(np.count_nonzero(np.diff(side)))


def _plain_soft_edge(t, q, noise, hold, step, ref=None):
    """soft_edge as it read before: every deviation divided by its joint's noise."""
    n = len(t)
    h0, h1 = hold
    if h1 - h0 < 4 or not np.any(noise > 0):
        return None
    h = float(t[1] - t[0])
    if ref is None:
        ref = held_at(q, hold)
    edge = h1 if step > 0 else h0
    reach = int(round(MOTION_SPAN / h))
    far = int(np.clip(edge + step * reach, 0, n - 1))
    side = np.arange(edge, far + step, step)
    if len(side) < 4:
        return None
    rows = slice(edge, far + step if far + step >= 0 else None, step)
    sig = np.where(noise > 0, noise, np.inf)
    z = np.abs(q[rows] - ref) / sig
    j = int(np.argmax(z.max(axis=0)))
    clear = np.flatnonzero(z[:, j] > CLEAR)
    if not np.isfinite(sig[j]) or len(clear) == 0:
        return None
    d = (q[rows, j] - ref[j]) * np.sign(q[side[clear[0]], j] - ref[j])
    back = np.flatnonzero(d[clear[0]:] < 0.0)
    top = float(d[clear[0]:clear[0] + (back[0] if len(back) else len(d))].max())
    if top < LOBE * float(np.abs(d).max()) or _plain_swings(d[clear[0]:], SWING * top) < 2:
        return None
    end = clear[0] + int(np.argmax(d[clear[0]:] >= ONSET_TOP * top))
    end = max(end, clear[0])
    inside = int(min(round(HOLD_SPAN / h), h1 - h0))
    idx = np.arange(edge - step * inside, side[end] + step, step)
    y = (q[idx, j] - ref[j]) * np.sign(q[side[clear[0]], j] - ref[j])
    tau = (t[idx] - t[edge]) * step
    starts = np.arange(tau[0], (t[side[clear[0]]] - t[edge]) * step, max(h / 4.0, 1e-3))
    if len(starts) == 0:
        return None
    lag = np.clip(tau[None, :] - starts[:, None], 0.0, None)
    limit = len(y) * max(FIT_SIGMAS * float(sig[j]), FIT_SHAPE * top) ** 2
    best = _best(lag, y, starts, [lag ** p for p in POWERS])
    if best[0] > limit:
        w = _angular(t[side], d, clear[0], back[0] if len(back) else len(d))
        if w is not None:
            best = _best(lag, y, starts, [lag ** p * np.sin(k * w * lag) for p in POWERS
                                          for k in RATES])
    if best[0] > limit:
        return None
    return float(t[edge]) + step * best[1]


def _hold_between(rng: np.random.Generator, n: int = 1200, joints: int = 4):
    """A hold in the middle of ``n`` samples at 500 Hz: before it an approach of every
    joint, after it a shiver of one joint fading in (or another approach), each joint
    with its own noise (some none)."""
    h = 0.002
    t = np.arange(n) * h
    h0, h1 = n // 3, n // 2
    q = np.tile(rng.normal(size=joints), (n, 1))
    ramp = np.clip((h0 - np.arange(n)) * h, 0.0, None)[:, None]
    # Each joint's share over decades, as its noise: the joint furthest in its noise is
    # often not the one furthest in radians.
    share = rng.normal(size=joints) * 10.0 ** rng.uniform(-3, 0, joints)
    q += share * ramp ** rng.uniform(1.5, 3.0)
    tau = np.clip((np.arange(n) - h1) * h, 0.0, None)
    lead = int(rng.integers(joints))
    if rng.random() < 0.7:
        fade = np.minimum(tau / rng.uniform(0.05, 0.4), 1.0) ** rng.uniform(1.5, 3.5)
        q[:, lead] += rng.uniform(0.005, 0.05) * fade * np.sin(2 * np.pi * rng.uniform(3, 8) * tau)
    else:
        q[:, lead] += rng.normal() * tau ** 2
    noise = np.where(rng.random(joints) < 0.25, 0.0,
                     10.0 ** rng.uniform(-7, -2, joints))
    q = q + rng.normal(size=q.shape) * noise
    if rng.random() < 0.5:
        q = np.asfortranarray(q)  # a compiled trajectory's joints lie by columns
    return t, q, noise, (h0, h1)


def test_soft_edge_is_the_plain_one_both_sides():
    rng = np.random.default_rng(21)
    found = 0
    for _ in range(150):
        t, q, noise, hold = _hold_between(rng)
        for step in (-1, 1):
            want = _plain_soft_edge(t, q, noise, hold, step)
            assert soft_edge(t, q, noise, hold, step) == want
            found += want is not None
    assert found >= 20  # oscillations' edges moved, not only refusals


def test_swings_count_the_plain_sign_changes():
    rng = np.random.default_rng(22)
    for _ in range(3000):
        n = int(rng.integers(0, 60))
        d = rng.normal(size=n) * 10.0 ** float(rng.integers(-9, 4))
        d[rng.random(n) < 0.1] = rng.choice([0.0, -0.0])
        level = abs(float(rng.normal())) * 10.0 ** float(rng.integers(-9, 4)) + 1e-300
        assert _swings(d, level) == _plain_swings(d, level)


def test_soft_pause_with_the_known_hold_is_soft_pause_without_it():
    rng = np.random.default_rng(23)
    for _ in range(60):
        t, q, noise, (h0, h1) = _hold_between(rng)
        span = (float(t[h0]), float(t[h1]))
        k0, k1 = int(np.searchsorted(t, span[0])), int(np.searchsorted(t, span[1], "right")) - 1
        known = ((k0, k1), held_at(q, (k0, k1)))
        assert soft_pause(t, q, noise, span, known) == soft_pause(t, q, noise, span)
        # a position found over other samples is not taken for this hold's
        other = ((k0 + 1, k1), held_at(q, (k0, k1)) + 1.0)
        assert soft_pause(t, q, noise, span, other) == soft_pause(t, q, noise, span)


def test_hold_test_without_a_gap_is_the_test_of_every_row():
    """Holds whose joints wander about the edge of their band: the band as one row
    (a log without a gap) and as every row scaled by 1 find the same hold."""
    from aou_dsl.measuring.rest import rest_signals

    rng = np.random.default_rng(27)
    moved = 0
    for _ in range(200):
        n, joints, h = 400, 3, 0.004
        t = np.arange(n) * h
        noise = 10.0 ** rng.uniform(-6, -3, joints)
        quantum = np.where(rng.random(joints) < 0.3, 10.0 ** rng.uniform(-6, -4, joints), 0.0)
        window = int(rng.choice([3, 5, 7]))
        band = holds.HELD_SIGMAS * noise + 1.01 * quantum + holds.STILL_ANGLE
        q = rng.normal(size=joints) + rng.uniform(-0.5, 0.5, (n, joints)) * band
        for _ in range(int(rng.integers(0, 3))):  # a stretch about the band's edge
            a = int(rng.integers(0, n - 60))
            j = int(rng.integers(joints))
            q[a:a + int(rng.integers(5, 60)), j] += rng.uniform(0.8, 2.0) * band[j]
        r = rest_signals(t, h, q, noise, quantum, np.ones(n), window, float(t[-1]))
        plain = replace(r)
        plain.__dict__["gapless"] = False
        assert r.gapless
        t0, t1 = float(t[int(rng.integers(0, 40))]), float(t[int(rng.integers(n - 40, n))])
        got, want = holds._held(r, t0, t1), holds._held(plain, t0, t1)
        assert got[:2] == want[:2]
        moved += got[:2] != (t0, t1)
    assert moved >= 20  # holds cut short by a joint beyond its band


def test_length_is_numpys_norm_in_either_layout():
    rng = np.random.default_rng(28)
    for _ in range(200):
        x = rng.normal(size=(50, 3)) * 10.0 ** rng.integers(-8, 8, size=(50, 3))
        x[rng.random(x.shape) < 0.05] = -0.0
        for rows in (x, np.asfortranarray(x)):  # a row of positions laid out by columns
            for v in (rows[7], rows[7] - rows[3], rows[:, 1], rows[5, ::-1]):
                assert _length(v) == float(np.linalg.norm(v))


def test_five_samples_are_numpys_unique_clipped_linspace():
    for n in range(3, 80):
        for half in range(0, (n - 1) // 2 + 1):
            for at in range(-2, n + 2):
                want = np.unique(np.clip(np.linspace(at - half, at + half, 5).round()
                                         .astype(int), half, n - 1 - half))
                got = np.array(_five(at, half, n))
                assert got.dtype == want.dtype and np.array_equal(got, want)


def test_uniform_clock_is_allclose():
    rng = np.random.default_rng(24)
    for _ in range(20000):
        h = float(10.0 ** rng.uniform(-5, 1)) * float(rng.choice([1.0, -1.0]))
        bound = 1e-9 + 1e-6 * abs(h)
        n = int(rng.integers(1, 6))
        steps = h + rng.choice([-1.0, 1.0], n) * bound * rng.choice(
            [0.0, 0.5, 1.0, 1.0 - 1e-12, 1.0 + 1e-12, 2.0], n)
        steps += np.spacing(steps) * rng.integers(-2, 3, n)  # either side of the bound
        assert _uniform(steps, h) == bool(np.allclose(steps, h, rtol=1e-6, atol=1e-9))


def test_leading_joint_velocities_are_the_two_axis_lookup():
    rng = np.random.default_rng(25)
    x = rng.normal(size=(500, 7))
    for v in (x, np.asfortranarray(x), x[:, ::2], x[:, :1]):
        j = rng.integers(0, v.shape[1], len(v) - 1)
        rows = np.arange(len(j))
        assert np.array_equal(_leading(v, j, 0), v[rows, j])
        assert np.array_equal(_leading(v, j, 1), v[rows + 1, j])


def test_median_of_episode_values_is_numpys():
    rng = np.random.default_rng(26)
    for _ in range(5000):
        n = int(rng.integers(1, 12))
        vals = [float(v) for v in rng.normal(size=n) * 10.0 ** rng.integers(-6, 6, n)]
        if rng.random() < 0.3:
            vals = [float(round(v)) for v in vals]  # ties
        if rng.random() < 0.2:
            vals[int(rng.integers(n))] = -0.0
        if rng.random() < 0.05:
            vals[int(rng.integers(n))] = float(rng.choice([math.inf, -math.inf, math.nan]))
        got, want = _median(vals), float(np.median(vals))
        assert (math.isnan(got) and math.isnan(want)) or (
            got == want and math.copysign(1.0, got) == math.copysign(1.0, want))


# --- On a compiled trajectory: the hold test, the phases' samples, the anchors -------

@pytest.fixture(scope="module")
def compiled():
    import aou_dsl
    from aou_dsl.measuring.measured import _context

    tr = aou_dsl.compile("behaviours/hesitant.aou").compiled.trajectory
    ctx, bounds, _ = _context(tr)
    return ctx, bounds


def test_hold_test_of_the_compiled_holds_is_the_test_of_every_row(compiled):
    ctx, bounds = compiled
    r = ctx.rest
    assert r.gapless
    plain = replace(r)  # a copy whose log is taken to have gaps: every row scaled
    plain.__dict__["gapless"] = False
    for b in bounds:
        got, want = holds._held(r, b.t0, b.t1), holds._held(plain, b.t0, b.t1)
        assert got[:2] == want[:2] and got[2][0] == want[2][0]
        assert np.array_equal(got[2][1], want[2][1])
    assert holds.boundaries(r) == holds.boundaries(plain)


def test_phases_found_by_index_are_those_the_search_finds(compiled):
    """Read with the grid given as the recording's own samples (found by search), every
    approach and retreat reads the same numbers."""
    ctx, bounds = compiled
    searched = replace(ctx, raw=Samples(ctx.rest.t, ctx.q, ctx.pos))
    read = 0
    for p in pieces(ctx, bounds):
        if isinstance(p, holds.Boundary):
            continue
        got, want = translation(ctx, p, None), translation(searched, p, None)
        assert got == want
        read += got is not None
    assert read >= 4


def test_pause_anchors_are_the_gathered_means(compiled):
    ctx, bounds = compiled
    t = ctx.rest.t
    for p in pieces(ctx, bounds):
        if isinstance(p, holds.Boundary) or not (p.held0 or p.held1):
            continue
        b = next(b for b in bounds if b.pause and (b.t1 == p.t0 or b.t0 == p.t1))
        k0 = int(np.searchsorted(t, b.t0 + 0.25 * (b.t1 - b.t0), "left"))
        k1 = int(np.searchsorted(t, b.t1 - 0.25 * (b.t1 - b.t0), "right"))
        idx = np.arange(k0, k1)
        pos, roll = ctx.pos[idx].mean(axis=0), float(ctx.roll[idx].mean())
        got = (p.p0, p.roll0) if b.t1 == p.t0 else (p.p1, p.roll1)
        assert np.array_equal(got[0], pos) and got[1] == roll


def test_soft_edge_of_the_compiled_holds_is_the_plain_one(compiled):
    ctx, bounds = compiled
    r = ctx.rest
    for b in bounds:
        hold = (int(np.searchsorted(r.t, b.t0)), int(np.searchsorted(r.t, b.t1, "right")) - 1)
        for step in (-1, 1):
            assert onset.soft_edge(r.t, r.q, r.noise, hold, step) == _plain_soft_edge(
                r.t, r.q, r.noise, hold, step)
