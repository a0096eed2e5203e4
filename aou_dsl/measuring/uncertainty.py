"""How much each measured descriptor can be trusted: a parametric bootstrap of the noise.

A recording's joints carry noise whose level :func:`.signal.joint_noise` estimates joint
by joint. The measurement is a chain of filters, thresholds, episode boundaries, fits and
medians: no closed formula carries that noise through all of it. So it is carried by
doing it again. The recording is smoothed (the measurement's own velocity filter, as a
position filter), fresh noise at each joint's estimated level is added, and the copy is
measured with the recording's own filters and thresholds (its noise pinned, not
re-estimated). :data:`FIRST` copies are measured, :data:`REPLICATES` when they or
the base do not all read the recording's segmentation; they give each descriptor a
std, and its 95 % interval is the value +- Student's t of that many copies times the
std, widened to take in the value less what the noise adds on average (the copies'
mean beside the smoothed recording's own reading, times :data:`BIAS`: the larger of
noisy readings is biased up), for a duration a sampling step at each edge and the
edges' own placement error (:data:`EDGES`), and for a peak acceleration what its
reading cannot resolve above it (:data:`PEAK_SHAPE`) and at least what the noise gives
its own episode's reading (:func:`.episode_spread.episode_noise`). docs/measure.md gives the
coverage measured over simulated recordings.

A count or a presence that differs between the copies is a segmentation the noise can
flip: its interval spans what the copies read, and R411 names it with the noise level;
so does a value whose interval reaches more than 20 % of itself from it.
A trajectory without noise (compiled, or computed by a planner) is measured exactly:
every interval is the value itself.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..core.codes import R411
from ..core.diagnostics import AouError, Span, diag
from ..core.trajectory import Trajectory
from ..lang.descriptors import REGISTRY
from .episode_spread import beyond_noise, episode_noise
from .episodes import COMPUTED_NOISE
from .linearised import Linearised
from .recognisers import every_named
from .signal import JointNoise, short_window, smooth, to_grid, unwrap
from .staircase import dequantised, held_offsets, staircase_joints

__all__ = ["REPLICATES", "Inferred", "Spread", "attach", "vague"]

#: Re-noised copies measured first; when they are all readable and read the
#: recording's segmentation (every count and every presence), as the smoothed base
#: does, that is all.
FIRST = 4
#: Copies measured in all when the first ones do not agree (a segmentation the noise
#: may flip is looked at more closely).
REPLICATES = 10
#: Two-sided 95 % quantiles of Student's t by degrees of freedom (copies less one).
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306,
       9: 2.262}
#: The seed of the copies' noise: the same file gives the same intervals.
SEED = 20240
#: The error of placing a pause's edges where the motion beside it stops, as a fraction
#: of a duration or of a speed over one (the refinement's own error on noisy recordings,
#: about 1 % of the duration over the generated recordings of the tests, whatever the
#: noise: not something re-noised copies show).
EDGES = 0.01
#: What the noise adds to a reading on average (the larger of noisy readings is biased
#: up, a peak-to-peak range grows with the noise) is read as the copies' mean less the
#: smoothed base's reading, times this. The base keeps part of the noise a reading sees
#: (its filter passes what is slower than its window; a reading over a phase sees just
#: that), so the copies, the base's noise and their own, show only part of the bias:
#: for a bias in proportion to the noise level ``s``, the copies show
#: ``(sqrt(1 + r^2) - r) s`` of the recording's ``s`` when the base keeps ``r`` of it,
#: at least ``sqrt(2) - 1`` of it (``r`` = 1): the bias is at most ``1 + sqrt(2)`` times
#: what they show. (A bias in the noise squared they show whole; this only widens it.)
BIAS = 1.0 + math.sqrt(2.0)
#: The unit of a hand's peak acceleration, and how far above its reading the peak may
#: lie without any noise, as a fraction of it: the reading is a mean of the
#: acceleration over a phase, or over a run of it, with positive weights, so never
#: above the peak; a profile that rises less than an arm's transients above the
#: phase's level is read as the level (aou_dsl/measuring/peaks.py). Over the shipped
#: and 100 generated behaviours logged with 1e-6 rad of noise, approaches read up to
#: 0.71 % low (five of 88 more than 0.29 %), at 250 Hz as at 1 kHz, retreats up to
#: 0.19 %: not something re-noised copies show, since no noise makes it.
ACCELERATION = "m/s^2"
PEAK_SHAPE = 0.01


@dataclass(frozen=True)
class Spread:
    """A descriptor's uncertainty.

    Attributes:
        sd: the std the noise gives it (0 for a count the copies agree on; None when
            absent or when the copies disagree on its presence).
        low, high: its 95 % interval (a count's: the least and most the copies read;
            None where it is absent in the recording and in every copy).
        stable: whether every copy reads the same count and the same presence, and
            the interval reaches no further than 20 % of the value from it: whether
            the value can be trusted.
        absent_in: how many copies read it absent.
    """

    sd: float | None
    low: float | int | None
    high: float | int | None
    stable: bool
    absent_in: int = 0

    def to_json(self) -> dict:
        def r(v: float | int | None) -> float | int | None:
            return round(v, 6) if isinstance(v, float) else v

        return {"sd": r(self.sd), "low": r(self.low), "high": r(self.high),
                "stable": self.stable, "absent_in_copies": self.absent_in}


def exact(value: float | int | None) -> Spread:
    """The spread of a value read without noise."""
    return Spread(None if value is None else 0.0, value, value, True)


def _copies(rec: Trajectory, cols: np.ndarray, jn: JointNoise, rng: np.random.Generator,
            restamp: np.ndarray | None = None
            ) -> tuple[Trajectory, Callable[[], Trajectory], dict[str, np.ndarray]]:
    """``rec`` with its arm joints smoothed (the base); a maker of copies of the base
    with fresh noise at each moving joint's level, rounded again where the recording's
    rounding is coarser than its noise (other columns as they are); and the
    recording's own arm joints on the measurement's uniform clock (``"grid"``) and on
    its own (``"raw"``), which the copies' kinematics are expanded about."""
    t = np.asarray(rec.t, float)
    q_all = np.asarray(rec.q, float)
    stairs = unwrap(q_all[:, cols])[0]
    q = dequantised(t, stairs, jn)
    level = jn.effective
    h0 = float(np.median(np.diff(t)))
    window = short_window(float(level.max()), h0)
    grid = to_grid(t, q, window * h0)
    base = smooth(grid.q, window, 0, grid.h, order=3) if window > 3 else grid.q
    tt = t - t[0]
    smooth_q = np.column_stack([np.interp(tt, grid.t, base[:, j]) for j in range(q.shape[1])])
    moving = level > 0
    smooth_q[:, ~moving] = q[:, ~moving]
    base_q = q_all.copy()
    base_q[:, cols] = smooth_q

    # A joint whose rounding is coarser than its white noise logs a staircase, which
    # stays put over a pause where white noise averages out: its copies hold each pause
    # anywhere in its step, and are rounded to the same steps, on a grid shifted at
    # random (where the truth lies in a step is unknown). Their white noise, the
    # rounding's size, makes them step back and forth where the truth may lie near the
    # middle between two steps.
    rounded = staircase_joints(jn)
    step = np.where(rounded, jn.quantum, 0.0)

    def copy() -> Trajectory:
        qc = q_all.copy()
        x = smooth_q + rng.standard_normal(q.shape) * level
        if rounded.any():
            x += held_offsets(t, stairs, jn, rng)
            shift = rng.uniform(0.0, 1.0, q.shape[1]) * step
            x[:, rounded] = (np.round((x[:, rounded] + shift[rounded]) / step[rounded])
                             * step[rounded] - shift[rounded])
        qc[:, cols] = x
        if restamp is not None:  # the same samples, stamped on another arrival
            stamps = restamp + rng.permutation(t - restamp)
            if bool(np.all(np.diff(stamps) > 0)):
                return rec.with_(q=qc, t=stamps)
        return rec.with_(q=qc)

    return rec.with_(q=base_q), copy, {"grid": grid.q, "raw": q}


def _spread(name: str, value: float | int | None, base: float | int | None,
            reads: list[float | int | None], step: float) -> Spread:
    """The spread of descriptor ``name`` read ``value`` in the recording, ``base`` in
    its smoothed base and ``reads`` in the re-noised copies; ``step`` the sampling
    step [s]."""
    d = every_named()[name]
    if d.is_count:
        counts = [int(c or 0) for c in reads]
        n, b = int(value or 0), int(base or 0)
        lo, hi = min([n, b, *counts]), max([n, b, *counts])
        sd = float(np.std(counts, ddof=1)) if len(counts) > 1 else 0.0
        return Spread(sd, lo, hi, lo == hi)
    present = [float(r) for r in reads if r is not None]
    absent = len(reads) - len(present)
    if value is None:
        if not present and base is None:
            return Spread(None, None, None, True, absent)
        seen = present + ([] if base is None else [float(base)])
        return Spread(None, min(seen), max(seen), False, absent)
    v = float(value)
    if len(present) < 2 or base is None:
        return Spread(None, v, v, False, absent)
    sd = float(np.std(present, ddof=1))
    corrected = v - BIAS * (float(np.mean(present)) - float(base))
    # Each of a duration's two edges falls on a sample (known to a step at best), and
    # is placed by following the motion beside it back to rest (its own error).
    timed = d.unit == "s" or d.unit.endswith("/s")  # a duration, or a speed over one
    half = (T95[len(present) - 1] * sd + (2 * step if d.unit == "s" else 0.0)
            + (EDGES * abs(v) if timed else 0.0))
    # A peak acceleration is a mean of the acceleration over what it is read from:
    # never above the peak, and below it by what the reading did not resolve.
    above = PEAK_SHAPE * abs(v) if d.unit == ACCELERATION else 0.0
    low = min(v, corrected) - half
    if name in REGISTRY:  # the eleven are magnitudes: none reaches below zero
        low = max(low, 0.0)
    return Spread(sd, low, max(v, corrected) + half + above, absent == 0, absent)


def _values(m) -> dict:
    """A measurement's descriptors, the eleven then the plugins'."""
    return {**m.descriptors, **m.extra}


def attach(m, rec: Trajectory, jn: JointNoise,
           measure_once: Callable[[Trajectory, JointNoise | None, Linearised], tuple],
           restamp: np.ndarray | None = None) -> None:
    """Give ``m`` (a :class:`.measured.Measured` of ``rec``, whose joints' noise is
    ``jn``) its uncertainty, and R411 when a count or a presence is not stable.
    ``restamp``: for a clock stamped on arrival, that clock evened out; each copy is
    then stamped afresh about it (:func:`_copies`)."""
    value = _values(m)
    table = every_named()
    if float(jn.effective.max(initial=0.0)) <= COMPUTED_NOISE:
        m.uncertainty = {k: exact(value[k]) for k in table}
        m.inferred = _inferred(m, m, [])
        return
    from ..robot.load import load_arm

    arm = load_arm(rec.robot, rec.ee_frame, rec.package_dirs, rec.ee_definition)
    cols = rec.columns(arm.joint_names)
    rng = np.random.default_rng(SEED)
    base, copy, about = _copies(rec, cols, jn, rng, restamp)
    fk = Linearised(arm, about)
    try:
        smooth_m = measure_once(base, jn, fk)[0]
    except AouError:
        smooth_m = None
    read_m: list = []
    for k in range(REPLICATES):
        if k == FIRST and len(read_m) == FIRST and _agree([m, smooth_m, *read_m]):
            break
        try:
            read_m.append(measure_once(copy(), jn, fk)[0])
        except AouError:  # a copy the noise made unreadable adds nothing
            continue
    reads = [_values(r) for r in read_m]
    smooth_read = None if smooth_m is None else _values(smooth_m)
    m.inferred = _inferred(m, smooth_m, read_m)
    beyond_noise(m, read_m, T95)
    if len(reads) < 2 or smooth_read is None:
        m.uncertainty = {k: Spread(None, value[k], value[k], False) for k in table}
    else:
        step = float(np.median(np.diff(np.asarray(rec.t, float))))
        m.uncertainty = {k: _spread(k, value[k], smooth_read[k], [r[k] for r in reads],
                                    step) for k in table}
    episode_noise(m, value)
    too_wide = [k for k, s in m.uncertainty.items() if vague(k, value[k], s)]
    # A value read from episodes the copies count differently may be read from one
    # the noise made, or miss one it hid: not to be trusted either.
    uncounted = {table[k].kind for k, s in m.uncertainty.items()
                 if table[k].is_count and not s.stable}
    over = [k for k, d in table.items() if d.kind in uncounted and not d.is_count
            and value[k] is not None and m.uncertainty[k].stable]
    for k in too_wide + over:  # not to be trusted: a verdict on it is inconclusive
        m.uncertainty[k] = replace(m.uncertainty[k], stable=False)
    shaky = [k for k, s in m.uncertainty.items() if not s.stable]
    states = m.inferred.states
    if shaky or len(states) > 1:
        noise = float(jn.effective.max())
        what = [_shaky_text(k, value[k], m.uncertainty[k], len(reads))
                + (f", read from {table[k].kind} episodes the copies count differently"
                   if k in over else "") for k in shaky]
        if len(states) > 1:
            what.append(f"the inferred state reads {m.cv.state.value}, and "
                        f"{', '.join(states)} in the re-noised copies")
        stairs = staircase_joints(jn)
        source = (f"the joints' rounding (steps of {float(jn.quantum[stairs].max()):.2g} "
                  "rad)" if stairs.any() else f"the joints' noise ({noise:.2g} rad)")
        source += (" and the clock's stamps, taken on arrival, are" if restamp is not None
                   else " is")
        m.diagnostics.append(diag(
            R411, f"{source} more than this recording's segmentation bears: "
            f"{'; '.join(what)}. "
            f"{'These are' if len(what) > 1 else 'This is'} not to be trusted",
            Span.whole_file(rec.path),
            hint=("stamp each sample when it is taken, not when it arrives; "
                  if restamp is not None else "")
            + ("log with a finer encoder resolution" if stairs.any() else
               "log at a higher rate or with less noise")
            + "; a longer pause or a slower motion stands out of the noise better",
            noise=noise, descriptors=shaky, states=list(states)))


def _agree(ms: list) -> bool:
    """Whether the measurements (None: unreadable) read one segmentation: every count and
    every presence the same. The inferred state is left out: a state the first copies
    flip is already not to be trusted (R411 names it), and more copies would only add
    to the states listed, where a count's or a presence's interval is what the copies
    read, and needs them."""
    if any(x is None for x in ms):
        return False
    table = every_named()

    def shape(x) -> tuple:
        v = _values(x)
        return tuple((int(v[k] or 0) if d.is_count else v[k] is None)
                     for k, d in table.items())

    return len({shape(x) for x in ms}) == 1


@dataclass(frozen=True)
class Inferred:
    """The spread of what is read from the whole motion rather than from one descriptor:
    the C-V point (each coordinate's :class:`Spread`, and every state the recording and
    its copies infer, in order) and the line of sight's median and maximum [deg] (None
    without a goal). Each interval is made as a descriptor's is (the copies' std times
    Student's t, widened to take in the value less what the noise adds on average)."""

    C: Spread
    V: Spread
    states: tuple[str, ...]
    sight_median: Spread | None
    sight_max: Spread | None

    def to_json(self) -> dict:
        def js(s: Spread | None) -> dict | None:
            return None if s is None else s.to_json()

        return {"C": js(self.C), "V": js(self.V), "states": list(self.states),
                "line_of_sight_median_deg": js(self.sight_median),
                "line_of_sight_max_deg": js(self.sight_max)}


def _inferred(m, base, copies: list) -> Inferred:
    """The :class:`Inferred` of ``m`` (a :class:`.measured.Measured`) from the smoothed
    recording's measurement ``base`` (None when unreadable) and the copies'
    (``base`` is ``m`` and ``copies`` empty for a trajectory without noise)."""
    states = tuple(dict.fromkeys([m.cv.state.value] + [c.cv.state.value for c in copies]))
    exactly = base is m

    def one(get, floor: float = -math.inf) -> Spread | None:
        value = get(m)
        if value is None:
            return None
        if exactly:
            return exact(value)
        reads = [r for r in (get(c) for c in copies) if r is not None]
        b = None if base is None else get(base)
        if len(reads) < 2 or b is None:
            return Spread(None, value, value, False)
        sd = float(np.std(reads, ddof=1))
        corrected = value - BIAS * (float(np.mean(reads)) - b)
        t95 = T95[len(reads) - 1]
        return Spread(sd, max(floor, min(value, corrected) - t95 * sd),
                      max(value, corrected) + t95 * sd, len(states) == 1)

    def sight(attr: str):
        def get(x) -> float | None:
            los = x.line_of_sight
            return None if los is None or not len(los.angle) else getattr(los, attr)
        return get

    c, v = one(lambda x: x.cv.C), one(lambda x: x.cv.V)
    assert c is not None and v is not None
    return Inferred(c, v, states, one(sight("median"), 0.0), one(sight("max"), 0.0))


#: A value whose 95 % interval reaches further than this fraction of itself from it is
#: too vague to report without a warning (near zero: :data:`VAGUE_TOLERANCES` times the
#: descriptor's absolute tolerance).
VAGUE = 0.2
VAGUE_TOLERANCES = 3.0


def vague(name: str, value: float | int | None, s: Spread) -> bool:
    """Whether a value's interval ``s`` reaches too far from it to be trusted
    (:data:`VAGUE`); never a count's."""
    half = half_width(s, value)
    d = every_named()[name]
    if half is None or d.is_count or value is None:
        return False
    return half > max(VAGUE * abs(float(value)), VAGUE_TOLERANCES * d.abs_tol)


def _shaky_text(name: str, value, s: Spread, n: int) -> str:
    def v(x) -> str:
        return "absent" if x is None else (f"{x:.4g}" if isinstance(x, float) else str(x))

    count = every_named()[name].is_count
    if not s.absent_in and value is not None and not count:
        return f"{name} reads {v(value)}, 95 % interval {v(s.low)} to {v(s.high)}"

    if count:
        return f"{name} reads {v(value)}, from {s.low} to {s.high} in {n} re-noised copies"
    if value is None:
        return f"{name} reads absent, present in {n - s.absent_in} of {n} re-noised copies"
    return f"{name} reads {v(value)}, absent in {s.absent_in} of {n} re-noised copies"


def half_width(s: Spread, value: float | int | None) -> float | None:
    """The interval's larger distance from the value (None when absent)."""
    if value is None or s.low is None or s.high is None:
        return None
    return max(float(value) - float(s.low), float(s.high) - float(value))

