"""Rolling a DMP sequence out to a new goal, tempo and intensity, keeping its meaning.

The scaling rules (docs/dmp.md):

- **Goal.** The arm starts where the sequence starts; the goal moves. The whole motion
  is mapped by the similarity about the start position that takes the old goal to the
  new one: a rotation ``R`` (the smallest turning the old line from start to goal into
  the new) and a scale ``s`` (the ratio of the two lengths). Each motion's start and goal
  poses are mapped so, its position weights become ``s R W`` and its orientation weights
  ``R W``: the DMP then rolls out exactly the mapped motion. Distances scale by ``s``;
  the gaze stays locked on the new goal; gaze, tilt and shiver angles are unchanged.
- **Tempo.** A time scale ``K`` multiplies every DMP's ``execution_time_`` and every
  hold: pause durations scale by ``K``, tilt velocities by ``1 / K``, and accelerations
  by ``s / K^2``. A pinned acceleration keeps its value: that motion's own time scale is
  ``sqrt(s)`` instead. A shiver keeps its frequency (the arm's limits allow it) and
  lasts ``K`` times as many whole cycles (at least 3).
- **Intensity.** The descriptors the study found to change how strongly the state reads
  (the synthesis' spans, docs/synthesis.md) move with the intensity without a re-plan:
  a pause's hold, a motion's time scale (its acceleration), a shiver's amplitude. Counts
  and distances are the parts themselves: changing them needs a re-plan.

The DMPs are rolled out on a grid of about :data:`ROLL_DT` that ends exactly at each
motion's end (:func:`_grid`); what the DMP misses there of its goal (under 0.3 mm) and
of rest is faded in over the motion by quintics, so every motion ends exactly at rest
at its goal. Each motion's DMP runs from a little before its slot
to a little after (its lead-in and run-out, :data:`aou_dsl.dmp.fit.PAD`); the hand's pose
is the start pose moved by every motion's displacement, so these margins overlap their
neighbours smoothly. The result is sampled at the sequence's rate.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.codes import D602
from ..core.diagnostics import AouError, Span, diag
from ..lang.primitives import PAUSE
from .allowed import DIVERGED, Diverged, check_goal, check_options
from .export import DmpSequence
from .parts import Scaling, Shape, descriptor_name, dmp_kinds, scaled, shape_of

__all__ = ["Rollout", "predict", "roll", "similarity"]

_WHERE = Span.whole_file("<dmp>")


def _accel() -> dict[str, str]:
    """The moving kinds whose peak acceleration is a descriptor (a rollout may pin it),
    and its name."""
    return {kind: name for kind, name, how in scaled() if how is Scaling.PEAK}

#: Step of the DMPs' rollouts [s] (the library integrates orientation every millisecond
#: within it); the rollout is then sampled at the sequence's rate through a cubic spline.
ROLL_DT = 0.002


@dataclass
class Rollout:
    """A sequence rolled out: the hand's poses on one clock, and what it should measure.

    Attributes:
        t: sample times [s], shape (N,); pos (N, 3) [m], quat (N, 4) ``(w, x, y, z)``.
        part: the index of the part each sample belongs to, shape (N,).
        shiver: the shiver joint's offset [rad] and its two derivatives, shape (3, N).
        parts: ``(kind, t_start, t_end)`` of every part.
        goal: the goal [m]; scale, rotation: the similarity (``s``, ``R`` (3, 3)).
        time_scale, intensity, pinned: as asked.
        predicted: the descriptors the scaling rules predict.
        offset: when the sequence's first part starts on this clock [s] (the lead-in
            of a first motion is rest before it).
        schedule: the intensity changes of a running behaviour, ``(from part,
            intensity)`` in order (:mod:`.intensity`).
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    part: np.ndarray
    shiver: np.ndarray
    parts: list[tuple[str, float, float]]
    goal: tuple[float, float, float]
    scale: float
    rotation: np.ndarray
    time_scale: float
    intensity: float
    pinned: tuple[str, ...] = ()
    predicted: dict[str, Any] = field(default_factory=dict)
    offset: float = 0.0
    schedule: tuple[tuple[int, float], ...] = ()


def similarity(start: np.ndarray, old: np.ndarray, new: np.ndarray
               ) -> tuple[float, np.ndarray]:
    """Scale and rotation (3, 3) of the similarity about ``start`` taking ``old`` to ``new``."""
    u, w = np.asarray(old) - start, np.asarray(new) - start
    s = float(np.linalg.norm(w) / np.linalg.norm(u))
    a, b = u / np.linalg.norm(u), w / np.linalg.norm(w)
    axis = np.cross(a, b)
    sin, cos = float(np.linalg.norm(axis)), float(a @ b)
    if sin < 1e-12:
        return s, np.eye(3)
    k = axis / sin
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    angle = math.atan2(sin, cos)
    return s, np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def _factors(seq: DmpSequence, intensity: float | None) -> dict[str, float]:
    """Multipliers of the descriptors an intensity moves without a re-plan."""
    from ..lang.descriptors import REGISTRY
    from ..lang.ir import State
    from ..synth.synthesis import SPANS

    if intensity is None or seq.state is None:
        return {}
    state = State(seq.state)
    kinds = dmp_kinds()
    out = {}
    for d in REGISTRY.values():
        span = SPANS.get(state, {}).get((d.kind, d.key))
        entry = kinds.get(d.kind)
        if span is None or d.is_count or entry is None or d.key not in entry.intensity:
            continue  # an angle or a distance is the parts' geometry: a re-plan
        out[d.name] = span ** (d.stronger[state] * 2.0 * (intensity - seq.intensity))
    return out


def predict(seq: DmpSequence, s: float, k: float, factors: dict[str, float],
            pinned: tuple[str, ...]) -> dict[str, Any]:
    """The descriptors the scaling rules predict from the sequence's measured ones."""
    out = dict(seq.descriptors)

    def times(name: str, f: float) -> None:
        if out.get(name) is not None:
            out[name] = out[name] * f

    for _kind, name, how in scaled():
        f = factors.get(name, 1.0)
        if how is Scaling.PEAK:
            times(name, f if name in pinned else s * f / k ** 2)
        elif how is Scaling.TIME:
            times(name, k * f)
        elif how is Scaling.SPACE:
            times(name, s)
        elif how is Scaling.RATE:
            times(name, 1.0 / k)
        else:
            times(name, f)
    return out


def _map_pose(pose: np.ndarray, p0: np.ndarray, s: float, r: np.ndarray) -> np.ndarray:
    import pytransform3d.rotations as pr

    q = pr.concatenate_quaternions(pr.quaternion_from_matrix(r), pose[3:])
    return np.concatenate([p0 + s * r @ (pose[:3] - p0), q])


def _quintic(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The quintics from rest to (1, 0, 0) and to (0, 1, 0) in value, slope, curvature."""
    return (10 * x ** 3 - 15 * x ** 4 + 6 * x ** 5, -4 * x ** 3 + 7 * x ** 4 - 3 * x ** 5)


def _roll_move(dmp: Any, start: np.ndarray, goal: np.ndarray, s: float, r: np.ndarray,
               duration: float) -> tuple[np.ndarray, np.ndarray]:
    """One motion rolled out to ``duration``, ending there at rest: times and poses (n, 7)."""
    import pytransform3d.rotations as pr

    d = copy.deepcopy(dmp)
    wp, wr = d.forcing_term_pos.weights_.copy(), d.forcing_term_rot.weights_.copy()
    d.execution_time_ = duration
    d.forcing_term_pos.weights_ = s * r @ wp
    d.forcing_term_rot.weights_ = r @ wr
    d.dt_, run_t = _grid(duration)
    d.configure(start_y=start, goal_y=goal)
    with np.errstate(all="ignore"):  # a diverging DMP is refused below, not warned of
        t, y = d.open_loop(run_t=run_t)
    t = np.asarray(t) - t[0]
    y = np.asarray(y, dtype=float)
    if len(t) < 3 or not np.isfinite(y).all() or np.abs(y[:, :3]).max() > DIVERGED:
        raise Diverged
    x = np.clip(t / duration, 0.0, 1.0)
    h0, h1 = _quintic(x)
    dt = float(t[-1] - t[-2])
    # The end's velocity to second order (a backward difference is half a step early).
    miss = goal[:3] - y[-1, :3]
    v_end = (3.0 * y[-1, :3] - 4.0 * y[-2, :3] + y[-3, :3]) / (2.0 * dt)
    y[:, :3] += np.outer(h0, miss) - np.outer(h1 * duration, v_end)
    turn = pr.compact_axis_angle_from_quaternion(
        pr.concatenate_quaternions(goal[3:], pr.q_conj(y[-1, 3:])))
    half = 0.5 * np.outer(h0, turn)  # the rotation vectors' halves, (n, 3)
    angle = np.linalg.norm(half, axis=1)
    sinc = np.where(angle > 1e-12, np.sin(angle) / np.maximum(angle, 1e-300), 1.0)
    fade = np.column_stack([np.cos(angle), half * sinc[:, None]])
    y[:, 3:] = _qmul(fade, y[:, 3:])
    return t, y


def _grid(duration: float) -> tuple[float, float]:
    """The step [s] of a motion's rollout and the run time to ask the library for, so
    that its last sample falls exactly at ``duration``. Asked for ``duration`` itself,
    the library's grid ended up to a step past it at most time scales: the fade then
    stopped a step early, leaving a velocity where the end pose is held."""
    steps = duration / ROLL_DT
    whole = abs(steps - round(steps)) <= 1e-9 * max(steps, 1.0)  # rounding aside
    dt = ROLL_DT if whole else duration / math.ceil(steps)
    # Half a step short: the library steps while below ``run_t + dt``.
    return dt, duration - 0.5 * dt


def _shiver(tau: np.ndarray, amplitude: float, f: float, duration: float) -> np.ndarray:
    from ..compiler.oscillation import shiver_offset

    x, xd, xdd, _ = shiver_offset(tau, amplitude, f, duration)
    return np.vstack([x, xd, xdd])


def roll(seq: DmpSequence, *, goal: tuple[float, float, float] | None = None,
         time_scale: float = 1.0, intensity: float | None = None,
         pinned: tuple[str, ...] = (), rate: float | None = None,
         stretch: dict[int, float] | None = None, cache: dict | None = None,
         since: int = 0, schedule: tuple[tuple[int, float], ...] = (),
         retime: bool = False) -> Rollout:
    """Roll ``seq`` out (see the module's docstring).

    Args:
        goal: the new goal [m] (default: the sequence's).
        time_scale: ``K`` in [0.25, 4].
        intensity: in [0, 1] (default: the sequence's own).
        pinned: the peak accelerations to keep, by descriptor name (of the approach,
            the retreat).
        rate: sample rate [Hz] (default: the sequence's).
        stretch: extra time scale of some motions, by part index (a blend slows the
            motion that carries it, :mod:`.blend`).
        cache: motions already rolled out, reused (a dict the caller keeps).
        since: the intensity applies from this part on; earlier parts keep the
            sequence's own (a running behaviour changes intensity, :mod:`.intensity`).
        schedule: later changes, ``(from part, intensity)`` in order, each applying
            from its part on (a behaviour whose intensity changed more than once).
        retime: a motion whose time scale is not 1 is its DMP's rollout at its own
            execution time stretched in time, not integrated again. A DMP's
            transformation system is invariant under scaling time with its execution
            time, so the two differ only by the integrator's error (under 0.04 mm on
            the shipped behaviours): the live path uses it (:mod:`.intensity`).

    Raises:
        AouError: I504 for a value out of range.
    """
    for level in (intensity, *(later for _, later in schedule)):
        check_options(time_scale, level, pinned, tuple(_accel().values()))
    p0 = seq.parts[0].start[:3]
    new_goal = tuple(float(x) for x in (goal if goal is not None else seq.goal))
    check_goal(new_goal, p0)
    s, r = similarity(p0, np.asarray(seq.goal), np.asarray(new_goal))
    factors = _factors(seq, intensity)
    per_part = [factors if i >= since else {} for i in range(len(seq.parts))]
    for first_part, later in schedule:
        factors = _factors(seq, later)
        per_part[first_part:] = [factors] * (len(seq.parts) - first_part)
    plans = _plans(seq, p0, s, r, time_scale, per_part, pinned, stretch or {},
                   {} if cache is None else cache, retime)
    first, last = plans[0], plans[-1]
    # The first motion's lead-in and the last one's run-out are rest of their own.
    offset = first.t0 - first.begin if first.spline is not None else 0.0
    for plan in plans:
        plan.t0 += offset
        plan.begin += offset
    total = max(last.t0 + last.duration, last.begin + last.runs)
    rate = rate or seq.rate
    t = np.append(np.arange(0.0, total, 1.0 / rate), total)
    if len(t) > 1 and t[-1] - t[-2] < 1e-9:
        t = t[:-1]
    pos, quat = _compose(t, plans, _map_pose(seq.parts[0].start, p0, s, r))
    which = np.zeros(len(t), dtype=int)
    shiver = np.zeros((3, len(t)))
    spans = []
    for k, plan in enumerate(plans):
        t1 = plan.t0 + plan.duration
        which[t >= plan.t0] = k
        spans.append((plan.kind, plan.t0, t1))
        if shape_of(plan.kind) is Shape.OSCILLATION:
            sel = (t >= plan.t0) & (t <= t1)
            shiver[:, sel] = _shiver(t[sel] - plan.t0, plan.amplitude, plan.freq,
                                     plan.duration)
    predicted = predict(seq, s, time_scale, factors, pinned)
    changes: tuple[tuple[int, float], ...] = ((since, float(intensity)),) \
        if intensity is not None else ()
    changes += tuple(schedule)
    level = changes[-1][1] if changes else seq.intensity
    return Rollout(t, pos, quat, which, shiver, spans, new_goal,  # type: ignore[arg-type]
                   s, r, time_scale, level, tuple(pinned), predicted, offset, changes)


@dataclass
class _Plan:
    """One part on the rollout's clock: its slot ``[t0, t0 + duration]``; a motion's DMP
    rolled out from ``begin`` for ``runs`` seconds (``spline`` of its pose, from its
    ``start``); a shiver's amplitude [rad] and frequency [Hz]."""

    kind: str
    t0: float
    duration: float
    begin: float = 0.0
    runs: float = 0.0
    spline: Any = None
    start: Any = None
    amplitude: float = 0.0
    freq: float = 0.0


class _Stretched:
    """A motion's rollout stretched ``k`` times in time (``retime``, :func:`roll`)."""

    def __init__(self, spline: Any, k: float):
        self.spline, self.k = spline, k

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return self.spline(np.asarray(t) / self.k)


def _rolled(cache: dict, i: int, p: Any, start: np.ndarray, end: np.ndarray, s: float,
            r: np.ndarray, k: float, retime: bool) -> tuple[float, Any]:
    """Motion ``i`` rolled out at time scale ``k``: its duration [s] and pose spline."""
    from scipy.interpolate import CubicSpline

    if retime and k != 1.0:
        runs, spline = _rolled(cache, i, p, start, end, s, r, 1.0, False)
        return runs * k, _Stretched(spline, k)
    key = (i, s, r.tobytes(), k)
    if key not in cache:
        try:
            tt, yy = _roll_move(p.dmp, start, end, s, r, k * p.dmp.execution_time_)
        except Diverged:
            raise AouError(diag(D602, f"part {i + 1} ({p.kind}): its DMP rolls out to "
                                f"poses that are not finite or leave {DIVERGED:g} m "
                                "(its gains or weights do not make a motion)",
                                _WHERE)) from None
        # At rest at both ends (a free end would leave a velocity where the pose is held).
        cache[key] = (float(tt[-1]), CubicSpline(tt, yy, axis=0, bc_type="clamped"))
    return cache[key]


def _plans(seq: DmpSequence, p0: np.ndarray, s: float, r: np.ndarray, time_scale: float,
           per_part: list[dict[str, float]], pinned: tuple[str, ...],
           stretch: dict[int, float], cache: dict, retime: bool = False) -> list[_Plan]:
    """Every part on one clock, each motion rolled out (``per_part``: the intensity's
    multipliers of each part)."""
    ks = [_time_scale(p, s, time_scale, per_part[i], pinned) * stretch.get(i, 1.0)
          for i, p in enumerate(seq.parts)]
    plans, t0 = [], 0.0
    for i, p in enumerate(seq.parts):
        factors = per_part[i]
        start = _map_pose(p.start, p0, s, r)
        if p.dmp is not None:
            k = ks[i]
            end = _map_pose(p.end, p0, s, r)
            runs, spline = _rolled(cache, i, p, start, end, s, r, k, retime)
            plans.append(_Plan(p.kind, t0, k * p.duration, t0 - k * p.lead, runs, spline,
                               start))
        elif shape_of(p.kind) is Shape.OSCILLATION:
            cycles = max(3, int(round(p.values["cycles"] * time_scale)))
            freq = p.values["frequency"]
            amp = math.radians(p.values["amplitude"]) * factors.get(
                descriptor_name(p.kind, "amplitude") or "", 1.0)
            plans.append(_Plan(p.kind, t0, cycles / freq, amplitude=amp, freq=freq))
        else:
            hold = descriptor_name(PAUSE, "duration") or ""
            dur = p.duration * time_scale * factors.get(hold, 1.0)
            # A motion's fitted tails reach into a hold by about half its margin, and
            # stretch with its time scale: the hold gives back what the stretch adds.
            dur += sum(0.5 * seq.parts[j].lead * (ks[j] - 1.0) for j in (i - 1, i + 1)
                       if 0 <= j < len(seq.parts) and seq.parts[j].dmp is not None)
            plans.append(_Plan(p.kind, t0, max(dur, 0.0)))
        t0 += plans[-1].duration
    return plans


def _time_scale(p: Any, s: float, time_scale: float, factors: dict[str, float],
                pinned: tuple[str, ...]) -> float:
    """The time scale of part ``p``'s DMP (1 for a part without one)."""
    if p.dmp is None:
        return 1.0
    name = _accel().get(p.kind)
    f = factors.get(name, 1.0) if name else 1.0
    return math.sqrt(s / f) if name in pinned else time_scale / math.sqrt(f)


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Products of quaternions ``(w, x, y, z)`` row by row, shapes (N, 4)."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack([aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw], axis=1)


def _compose(t: np.ndarray, plans: list[_Plan], start: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """The hand's pose at ``t``: the start pose moved by every motion's displacement so
    far (positions added, rotations applied in the base frame in turn), so that a
    motion's lead-in and run-out may overlap its neighbours'."""
    pos = np.tile(start[:3], (len(t), 1))
    quat = np.tile(start[3:], (len(t), 1))
    for plan in plans:
        if plan.spline is None:
            continue
        y = plan.spline(np.clip(t - plan.begin, 0.0, plan.runs))
        pos += y[:, :3] - plan.start[:3]
        q = y[:, 3:] / np.linalg.norm(y[:, 3:], axis=1, keepdims=True)
        inv = plan.start[3:] * np.array([1.0, -1.0, -1.0, -1.0])
        quat = _qmul(_qmul(q, np.tile(inv, (len(t), 1))), quat)
    return pos, quat
