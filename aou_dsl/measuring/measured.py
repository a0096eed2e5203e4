"""The eleven expressive descriptors, measured from a joint trajectory: compiled by aou,
or recorded on a real arm.

The steps (docs/measure.md explains the choices):

1. :mod:`.signal`: continuous joints unwrapped; the noise of each joint estimated from
   its own samples (still joints have none, rounded ones their resolution); one uniform
   clock (linear interpolation, never a spline through noise); a velocity filter just
   long enough for that noise.
2. :mod:`.fk`: forward kinematics of every sample: the hand's position, rotation and
   unwrapped roll about its forward axis.
3. :mod:`.holds`: pauses (every joint still, within its noise) with their edges refined
   to where the motion stops, and the instants between two episodes.
4. :mod:`.episodes` and :mod:`.roll`: the motion between them, classified by what
   moved: approach, retreat, gaze, tilt, shiver; then each plugin kind's pass claims its
   own episodes (:mod:`.recognisers`).
5. The descriptors, from those episodes by :func:`aou_dsl.lang.descriptors.derive`: the
   same function that derives what a file declares; the plugins' descriptors after the
   eleven, aggregated the same way (:func:`.recognisers.extra_values`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.codes import R401, R403, R405, R406
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.trajectory import Trajectory
from ..lang.cv import CVPoint, composition, infer
from ..lang.descriptors import (
    Descriptors,
    EpisodeValues,
    derive,
    qualify,
)
from ..lang.primitives import PAUSE
from ..robot.batch_fk import batch_fk
from ..robot.load import load_arm
from .cuts import Cut, cut_motion, judge_cuts
from .episode_spread import per_episode, unequal
from .episodes import (
    COMPUTED_NOISE,
    STILL_TRANSLATION,
    Context,
    Piece,
    Samples,
    pieces,
    translation,
)
from .holds import MIN_PAUSE, REST_SPEED, Boundary, Rest, boundaries, rest_at_end, rest_signals
from .recognisers import claimed, every_named, extra_values
from .roll import MIN_TILT, Lobe, lobe, roll_angle, rotations, undersampled
from .signal import (
    Grid,
    JointNoise,
    joint_noise,
    median0,
    row_sum,
    short_window,
    smooth,
    to_grid,
    unwrap,
)
from .staircase import dequantised
from .stamps import (
    STAMP_FOLLOW,
    evened,
    judge_stamps,
    read_on_evened,
    stamp_share,
    stamped_on_arrival,
)

__all__ = ["MIN_PAUSE", "MIN_TILT", "STILL_TRANSLATION", "LineOfSight", "Measured",
           "measure"]


@dataclass(frozen=True)
class LineOfSight:
    """How far the hand's forward axis points away from the goal over time: the model
    assumes it never does (the gaze is locked on the goal).

    Attributes:
        t: times from the first sample [s], (N,).
        angle: angle between the forward axis and the direction to the goal [deg], (N,).
    """

    t: np.ndarray
    angle: np.ndarray

    @property
    def median(self) -> float:
        return float(median0(self.angle))

    @property
    def max(self) -> float:
        return float(self.angle.max())

    def to_json(self) -> dict:
        return {"median_deg": round(self.median, 6), "max_deg": round(self.max, 6)}


@dataclass
class Measured:
    """The result of measuring one trajectory.

    ``noise`` is the largest joint noise [rad] (``joint_noise`` per arm joint,
    ``resolution`` the grid rounded positions lie on, 0 for none); ``gaze_error`` the
    largest line-of-sight angle [deg] (NaN without a goal);
    episode times are from the first sample, which is at ``t_origin`` on the
    recording's own clock; ``uncertainty`` each descriptor's 95 % interval
    (:mod:`.uncertainty`).
    """

    descriptors: Descriptors
    episodes: list[EpisodeValues]
    cv: CVPoint
    diagnostics: list[Diagnostic]
    noise: float
    gaze_error: float
    duration: float
    joint_noise: tuple[float, ...] = ()
    line_of_sight: LineOfSight | None = None
    t_origin: float = 0.0
    resolution: tuple[float, ...] = field(default=())
    #: Per descriptor, its :class:`.uncertainty.Spread` (empty when not computed).
    uncertainty: dict[str, Any] = field(default_factory=dict)
    #: The C-V point's and the line of sight's spread (:class:`.uncertainty.Inferred`;
    #: None when not computed).
    inferred: Any = None
    #: The plugins' descriptors, by name, after the eleven (empty without plugins).
    extra: dict[str, float | int | None] = field(default_factory=dict)
    #: The motions the recording cuts short (:mod:`.cuts`).
    cuts: tuple[Cut, ...] = ()

    def to_json(self) -> dict:
        eps = [{"kind": e.kind, "start": round(e.t_start + self.t_origin, 4),
                "end": round(e.t_end + self.t_origin, 4), "counts": e.counts,
                "values": {k: round(v, 6) for k, v in e.values.items()}}
               for e in qualify(self.episodes)]
        los = self.line_of_sight
        return {
            "descriptors": {**self.descriptors.to_json(), **{
                k: (round(v, 6) if isinstance(v, float) else v)
                for k, v in self.extra.items()}},
            "episodes": eps,
            "cv": self.cv.to_json(),
            "noise": self.noise,
            "joint_noise": list(self.joint_noise),
            "line_of_sight": los.to_json() if los is not None else None,
            "gaze_error_deg": (round(self.gaze_error, 6) if math.isfinite(self.gaze_error)
                               else None),
            "duration": round(self.duration, 6),
            "diagnostics": [d.to_json() for d in self.diagnostics],
            "uncertainty": {k: s.to_json() for k, s in self.uncertainty.items()},
            "inferred_uncertainty": (None if self.inferred is None
                                     else self.inferred.to_json()),
            "uncertainty_level": 0.95,
        }


def _bad(path: str, message: str, **fields) -> AouError:
    return AouError(diag(R401, message, Span.whole_file(path), **fields))


def _checked(rec: Trajectory, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(rec.t, float)
    q = np.asarray(rec.q, float)[:, cols]
    if t.ndim != 1 or len(t) < 3 or q.shape[0] != len(t):
        raise _bad(rec.path, f"a trajectory needs at least 3 samples, found {len(t)}")
    if not (np.isfinite(t).all() and np.isfinite(q).all()):  # whole first: rows are short
        bad = ~(np.isfinite(t) & np.isfinite(q).all(axis=1))
        i = int(np.argmax(bad))
        raise _bad(rec.path, f"sample {i} is not a finite number", sample=i)
    step = np.diff(t)
    if (step <= 0).any():
        i = int(np.argmax(step <= 0)) + 1
        raise _bad(rec.path, f"time must increase strictly: sample {i} has t={t[i]:g}s "
                   f"after t={t[i - 1]:g}s", sample=i)
    return t, q


#: Forward kinematics of the rows of joint positions, on the grid (``"grid"``) or at the
#: recording's own samples (``"raw"``): positions (N, 3) and rotations (N, 3, 3).
Kinematics = Callable[[np.ndarray, str], tuple[np.ndarray, np.ndarray]]


def _context(rec: Trajectory, pinned: JointNoise | None = None, fk: Kinematics | None = None
             ) -> tuple[Context, list[Boundary], JointNoise]:
    """The per-sample signals of a trajectory and its boundaries; also the joints'
    noise and resolution (``pinned``: that noise, not the one the samples show: the
    re-noised copies of :mod:`.uncertainty` are read with the recording's filters;
    ``fk``: their kinematics, to first order about the recording's)."""
    arm = load_arm(rec.robot, rec.ee_frame, rec.package_dirs, rec.ee_definition)
    cols = rec.columns(arm.joint_names)
    t, q = _checked(rec, cols)
    q, _ = unwrap(q)
    jn = joint_noise(t, q) if pinned is None else pinned
    q = dequantised(t, q, jn)
    noise = jn.effective
    h0 = float(median0(np.diff(t)))  # a checked clock: finite
    window = short_window(float(noise.max()), h0)
    grid = to_grid(t, q, window * h0)
    carried = _carried(rec, cols, grid)
    rest = rest_signals(grid.t, grid.h, grid.q, noise, jn.quantum, grid.density, window,
                        grid.t_last, carried)
    from ..robot.batch_fk import rows_fk

    pos, rot = rows_fk(arm, grid.q) if fk is None else fk(grid.q, "grid")
    pos_s = smooth(pos, window, 0, grid.h) if window > 3 else pos
    goal = None if rec.goal is None else np.asarray(rec.goal, float)
    raw = None
    if grid.resampled:
        raw = Samples(t - t[0], q, (batch_fk(arm, q) if fk is None else fk(q, "raw"))[0])
    ctx = Context(arm, rec.path, rest, grid.q, noise, pos, pos_s, rot, roll_angle(rot),
                  goal, rot[0][:, 1].copy(), rot[0][:, 0].copy(), _edge_rest(rec, rest),
                  raw, _computed(noise, grid, carried))
    return ctx, boundaries(rest), jn


def _carried(rec: Trajectory, cols: np.ndarray, grid: Grid
             ) -> tuple[np.ndarray, np.ndarray] | None:
    """The joint velocities and accelerations the file carries, on the grid's samples
    (None when it carries none, or when the grid is not the file's own clock)."""
    if rec.qd is None or rec.qdd is None or grid.resampled:
        return None
    qd, qdd = np.asarray(rec.qd, float), np.asarray(rec.qdd, float)
    if qd.shape != np.shape(rec.q) or qdd.shape != qd.shape:
        return None
    n = len(grid.t)
    # Every column in its own place (a compiled trajectory's): the rows as they are; the
    # rest reads single values of them and sums none, so a view reads as the copy did.
    every = len(cols) == qd.shape[1] and bool(np.all(cols == np.arange(len(cols))))
    qd, qdd = (qd[:n], qdd[:n]) if every else (qd[:n, cols], qdd[:n, cols])
    if not (np.isfinite(qd).all() and np.isfinite(qdd).all()):
        return None
    return qd, qdd


def _computed(noise: np.ndarray, grid: Grid,
              carried: tuple[np.ndarray, np.ndarray] | None) -> bool:
    """Whether the trajectory was computed (aou's own, a planner's), not recorded on an
    arm: its joints carry no noise, or the velocities and accelerations it carries are
    the derivatives of its positions (each step is their trapezoid with its end
    correction, within :data:`COMPUTED_NOISE` for most samples). A logger's velocities
    are an estimate: they miss its positions by about their noise."""
    if float(noise.max()) <= COMPUTED_NOISE:
        return True
    if carried is None or len(grid.t) < 3:
        return False
    qd, qdd = carried
    h = np.diff(grid.t)[:, None]
    step = np.diff(grid.q, axis=0)
    miss = step - h * (qd[1:] + qd[:-1]) / 2 + h * h * (qdd[1:] - qdd[:-1]) / 12
    moving = step != 0
    return bool(moving.any() and np.median(np.abs(miss[moving])) <= COMPUTED_NOISE)


def _edge_rest(rec: Trajectory, rest: Rest) -> tuple[bool, bool]:
    """Whether the arm is at rest at the first and last sample: from the velocities the
    file carries, else from the rest test."""
    qd = rec.qd
    if qd is None or np.shape(qd) != np.shape(rec.q) or not np.isfinite(qd).all():
        return rest_at_end(rest, last=False), rest_at_end(rest, last=True)
    qd = np.asarray(qd, float)  # the first and the last row's speeds, not every row's
    return (bool(np.abs(qd[0]).max() <= REST_SPEED),
            bool(np.abs(qd[-1]).max() <= REST_SPEED))


def _episodes(ctx: Context, parts: list[Piece | Boundary],
              coarse: list[tuple[float, float, float]] | None = None,
              cuts: list[Cut] | None = None) -> list[EpisodeValues]:
    """Pauses, translations and rolls in time order; oscillations sampled too coarsely
    to tell a shiver from tilts are added to ``coarse`` (see :func:`.roll.rotations`),
    translations the recording cuts short to ``cuts`` (:mod:`.cuts`)."""
    out: list[EpisodeValues] = []
    lobes: list[Lobe] = []
    g0 = None
    if ctx.goal is not None:
        first = parts[0] if parts else None
        p0 = first.p0 if isinstance(first, Piece) else ctx.pos_s[0]
        if isinstance(first, Boundary):
            idx = np.arange(first.i0, first.i1 + 1)
            p0 = ctx.pos[idx].mean(axis=0)
        g0 = ctx.goal - p0

    def flush() -> None:
        out.extend(rotations(ctx, lobes, coarse))
        lobes.clear()

    for part in parts:
        if isinstance(part, Boundary):
            flush()
            t0 = part.t0
            if out and out[-1].kind == PAUSE:  # nothing moved since the last pause
                t0 = out.pop().t_start
            out.append(EpisodeValues(PAUSE, t0, part.t1, {"duration": part.t1 - t0}))
            continue
        moved = translation(ctx, part, g0)
        if moved is not None:
            if cuts is not None and (cut := cut_motion(ctx, part, moved)) is not None:
                cuts.append(cut)
            flush()
            out.append(moved)
            continue
        lb = lobe(ctx, part)
        if lb is not None:
            lobes.append(lb)
    flush()
    return out


def _line_of_sight(ctx: Context) -> LineOfSight | None:
    if ctx.goal is None:
        return None
    g = ctx.goal - ctx.pos_s
    norm = np.sqrt(row_sum(g * g))  # np.linalg.norm's, row by row
    ok = norm > 1e-6
    # Every row (the usual) taken without a selection, laid out by rows as it lays them.
    axis, g, norm, t = ((np.ascontiguousarray(ctx.rot[:, :, 2]), np.ascontiguousarray(g), norm,
                         ctx.rest.t.copy()) if ok.all() else
                        (ctx.rot[:, :, 2][ok], g[ok], norm[ok], ctx.rest.t[ok]))
    cosang = np.einsum("ij,ij->i", axis, g) / norm
    return LineOfSight(t, np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0))))


def measure(rec: Trajectory, *, uncertainty: bool = True) -> Measured:
    """Measure the eleven descriptors of a trajectory.

    Without a goal (``rec.goal`` None) the gaze descriptors and the line of sight are
    unknown (None), approach and retreat are told by the hand's forward axis, and R405
    says so. A recording that carries noise gets an uncertainty on every descriptor
    (:mod:`.uncertainty`, unless ``uncertainty`` is False), and R411 when its noise is
    more than a count or a presence bears.

    Raises:
        AouError: R401/R402 when the trajectory cannot be measured; R406 when a
            measured value contradicts the joint motion it came from.
    """
    try:
        m, jn = _measure(rec)
        failed: AouError | None = None
    except AouError as e:  # a clock stamped on arrival can make the hand's reading
        t, q = _joints(rec)  # contradict the joints: read on it evened out, and said so
        if e.diagnostics[0].code != R406 or not stamped_on_arrival(
                t, q, joint_noise(t, q).effective):
            raise
        rec, failed = rec.with_(t=evened(t)), e
        m, jn = _measure(rec)
    if uncertainty:
        from .uncertainty import attach

        # A noisy recording's own clock and joints, unless it was read on another clock
        clock = None if failed is not None or float(jn.effective.max(initial=0.0)) <= \
            COMPUTED_NOISE else _joints(rec)
        share = None if clock is None else stamp_share(*clock, jn.effective)
        arrival = share is not None and share < STAMP_FOLLOW
        # a clock stamped on arrival, evened out: the copies restamp it
        attach(m, rec, jn, _measure, evened(clock[0]) if clock and arrival else None)
        if clock is not None and share is not None and arrival and m.uncertainty:
            judge_stamps(m, rec.path, clock[0], share,  # read again on the evened clock
                         lambda even: _measure(rec.with_(t=even), jn)[0])
    if failed is not None:
        read_on_evened(m, rec.path, t, failed)
    judge_cuts(m, rec.path, list(m.cuts))
    return m


def _joints(rec: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The recording's clock and its arm's joints, unwrapped."""
    arm = load_arm(rec.robot, rec.ee_frame, rec.package_dirs, rec.ee_definition)
    t, q = _checked(rec, rec.columns(arm.joint_names))
    return t, unwrap(q)[0]


def _measure(rec: Trajectory, pinned: JointNoise | None = None, fk: Kinematics | None = None
             ) -> tuple[Measured, JointNoise]:
    """One measurement, without an uncertainty; with the joints' noise it used."""
    ctx, bounds, jn = _context(rec, pinned, fk)
    quantum = jn.quantum
    coarse: list[tuple[float, float, float]] = []
    cuts: list[Cut] = []
    where = Span.whole_file(rec.path)
    episodes, unclaimed = claimed(_episodes(ctx, pieces(ctx, bounds), coarse, cuts), where)
    descriptors = derive(episodes)
    extra = extra_values(episodes)
    values = {**descriptors, **extra}
    diags = [undersampled(where, t0 + float(rec.t[0]), t1 + float(rec.t[0]), per_cycle,
                           ctx.rest.h) for t0, t1, per_cycle in coarse]
    if ctx.goal is None:
        diags.append(diag(R405, "the trajectory has no goal: gaze descriptors and the line "
                          "of sight are not measured; approach and retreat are read along "
                          "the hand's forward axis", where,
                          hint="give it with --goal X,Y,Z, or --goal final"))
    table = every_named()
    diags += [diag(R403, f"{name} differs between episodes: "
                   f"{', '.join(f'{v:.4g}' for v in vals)}; reporting the "
                   f"{table[name].aggregate} {values[name]:.4g}", where,
                   descriptor=name, values=vals)
              for name, vals in per_episode(episodes).items() if unequal(table, name, vals)]
    diags += unclaimed
    point, _ = infer(composition(episodes))
    los = _line_of_sight(ctx)
    return Measured(descriptors, episodes, point, diags, float(ctx.noise.max()),
                    los.max if los is not None and len(los.angle) else math.nan,
                    float(ctx.rest.t_last), tuple(float(x) for x in ctx.noise), los,
                    float(rec.t[0]), tuple(float(x) for x in quantum), extra=extra,
                    cuts=tuple(cuts)), jn
