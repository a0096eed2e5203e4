"""The compiler: a validated behaviour -> a sampled joint trajectory, stage by stage.

``compile_behaviour`` runs layout, geometry, IK, timing and sampling and returns a
:class:`CompileResult` with the trajectory, the timeline, the diagnostics and the time
each stage took. It never raises for a problem of the input: a behaviour that cannot be
compiled gives a result with error diagnostics and no trajectory.
"""

from __future__ import annotations

import functools
import math
import re
import time
from dataclasses import dataclass, field

import numpy as np

from ..core.codes import C303, C304, C305, C308, C309, K802, V124
from ..core.diagnostics import AouError, Diagnostic, Fix, diag, has_errors, refused
from ..core.memo import Keyed, cached
from ..core.trajectory import Trajectory
from ..fit.plan import hint_edit
from ..fit.refusals import AccelerationShort, ShiverTooFast, TiltTooFast, Unreachable
from ..lang.ir import Behaviour
from ..lang.layout import layout
from ..lang.primitives import LOOK_SHIVER_F, Shiver, Timing
from ..lang.timeline import Episode, Pose, Timeline
from ..robot.geometry import ReachFrame, reach_frame
from ..robot.identity import frame_definition
from ..robot.ik import IKStatus, solve_path
from ..robot.kinematics import ArmModel, lifted
from ..robot.load import load_arm
from .kind_timing import missing, timing_of
from .reuse import solved_path, timed_path
from .start import CODES, start_diagnostic
from .timing import (
    JointSegment,
    PathSegment,
    TimingFailure,
    shiver_segment,
    tilt_segment,
)

__all__ = [
    "CompileOptions",
    "CompileResult",
    "compile_behaviour",
    "evaluate",
    "positions",
    "sample",
    "target_path",
]

#: Waypoint spacing of the IK path: along the line of sight [m], of bearing and roll [rad].
STEP_LENGTH = 0.005
STEP_ANGLE = math.radians(0.5)
MIN_WAYPOINTS = 8
DEFAULT_RATE = 250.0  # Hz


@dataclass(frozen=True)
class CompileOptions:
    """Options of ``aouc compile``: sample ``rate`` [Hz], IK ``step_*`` sizes, the folders
    of the robot's ``package://`` meshes; ``start_seed``, a joint configuration [rad] the
    start pose is solved from instead of the robot's posture (another IK branch,
    :mod:`.branches`); ``lift``, a factor on the arm's velocity, acceleration and jerk
    x of the motion as declared)."""
    rate: float = DEFAULT_RATE
    step_length: float = STEP_LENGTH
    step_angle: float = STEP_ANGLE
    package_dirs: tuple[str, ...] = ()
    start_seed: tuple[float, ...] | None = None
    lift: float = 1.0


@dataclass
class CompileResult:
    """What the compiler made of one behaviour. ``trajectory`` is None on error."""

    behaviour: Behaviour
    timeline: Timeline | None = None
    trajectory: Trajectory | None = None
    diagnostics: list[Diagnostic] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    ik_position_error: float = 0.0
    ik_rotation_error: float = 0.0
    #: Kept for investigation: the reach frame and one timed segment per episode.
    frame: ReachFrame | None = None
    segments: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.trajectory is not None and not has_errors(self.diagnostics)


def _waypoints(ep: Episode, frame: ReachFrame, opts: CompileOptions
               ) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """Path coordinate samples (K,) and end-effector targets of a moving episode; kept
    for recompilations by what they depend on (neither is changed by their users)."""
    step = timing_of(ep.kind).step(opts.step_length, opts.step_angle)
    key = (frame.goal.tobytes(), frame.R0.tobytes(), ep.start, ep.end, ep.path_length, step)
    return _kept_waypoints(Keyed(key, (ep, frame, step)))


@cached(maxsize=256)
def _kept_waypoints(probe: Keyed) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    ep, frame, step = probe.value
    n = max(MIN_WAYPOINTS, math.ceil(ep.path_length / step) + 1)
    s = np.linspace(0.0, ep.path_length, n)
    targets = frame.targets(ep.start, ep.end, (si / ep.path_length for si in s))
    s.setflags(write=False)  # shared by the compilations that keep it
    return s, targets


def _start_configuration(arm: ArmModel, frame: ReachFrame, pose: Pose,
                         seed: tuple[float, ...] | None = None):
    """IK of the start pose, by continuation from the robot's posture (or from
    ``seed``). The same reach always starts the same way, so the result is kept for
    recompilations."""
    if not arm.key:  # an arm not loaded from files: nothing to know it by
        return _solve_start(arm, frame.target(pose), seed)
    key = (arm.key, arm.frame_id, frame.goal.tobytes(), frame.R0.tobytes(), pose, seed)
    return _solved_start(Keyed(key, (arm, frame.target(pose), seed)))


@cached(maxsize=64)
def _solved_start(probe: Keyed):
    return _solve_start(*probe.value)


def _solve_start(arm, target, seed):
    return solve_path(arm, [target], None if seed is None else np.array(seed, float))


def _ik_diag(ep: Episode, status: IKStatus, t: float, joint: str | None, b: Behaviour,
             d: float) -> Diagnostic:
    """C301-C303 at the episode whose pose at ``d`` [m] from the goal failed; when that
    pose is no closer than the start, the hint names `start` too."""
    where = f" ({joint})" if joint else ""
    s = b.settings
    hint = "move the goal (`goal`), the start direction (`from`) or shorten the motion"
    if d >= s.start - 1e-9:
        line = f"line {s.spans['start'].line}" if "start" in s.spans else \
            f"the default {s.start:g} m"
        hint = (f"this pose is {d:.3g} m from the goal, no closer than the start ({line}): "
                f"a smaller `start`, or {hint[0].lower()}{hint[1:]}")
    return refused(CODES.get(status, C303),
                   f"{ep.kind} at t={t:.2f}s: {status.value}{where} on {s.robot}", ep.span,
                   Unreachable(status.name.lower(), t, joint), hint=hint)


def _follows(arm: ArmModel, frame: ReachFrame, options: CompileOptions, tl: Timeline
             ) -> bool:
    """Whether IK follows every pose of ``tl``, from its start pose on (no timing)."""
    ik = solve_path(arm, [frame.target(tl.episodes[0].start)]) if tl.episodes else None
    if ik is None or ik.failure is not None:
        return False
    q = ik.q[0]
    for ep in tl.episodes:
        if not timing_of(ep.kind).still:
            ik = solve_path(arm, _waypoints(ep, frame, options)[1], q)
            if ik.failure is not None:
                return False
            q = ik.q[-1]
    return True


def _siblings(arm: ArmModel, frame: ReachFrame, episodes: tuple[Episode, ...],
              q: np.ndarray, options: CompileOptions) -> list[tuple[np.ndarray, np.ndarray]]:
    """The joint paths of the later episodes (``episodes[1:]``) that the statement of the
    first makes, following the reach from ``q`` (the end of the first): joint paths do not
    depend on timing, so a value that times them all can be checked before any is timed."""
    ep, later = episodes[0], episodes[1:]
    if not any(e.span == ep.span and e.kind == ep.kind for e in later):
        return []
    out = []
    for e in later:
        if timing_of(e.kind).still:
            continue
        s, targets = _waypoints(e, frame, options)
        ik = solve_path(arm, targets, q)
        if ik.failure is not None:
            break
        q = ik.q[-1]
        if e.span == ep.span and e.kind == ep.kind:
            out.append((s, ik.q))
    return out


def _too_fast(code: str, fail: TimingFailure, ep: Episode, edit: str | None,
              refusal: ShiverTooFast | TiltTooFast) -> Diagnostic:
    """C308 or C309: the limit a shiver or a tilt exceeds; the hint is the edit that
    fits (the value the message gives), when there is one; a fix when it sets one key."""
    one_key = edit is not None and len(re.findall(r"\w+=|\bfor\s", edit)) == 1
    fix = Fix(ep.span, edit, edit.split("=")[0]) if edit and one_key else None
    return refused(code, fail.reason, ep.span, refusal, fix=fix,
                   hint=f"write `{edit}`" if edit else None)


def compile_behaviour(b: Behaviour, options: CompileOptions = CompileOptions(),
                      timeline: Timeline | None = None) -> CompileResult:
    """Compile a validated behaviour into a joint trajectory.

    ``timeline`` is the behaviour's layout when the caller has it (validation makes
    it); otherwise it is laid out here.
    """
    res = CompileResult(b)
    clock = time.perf_counter()

    def lap(stage: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        res.timings[stage] = res.timings.get(stage, 0.0) + now - clock
        clock = now

    tl = timeline if timeline is not None else layout(b)
    res.timeline = tl
    lap("layout")
    untimed = missing({ep.kind for ep in tl.episodes})
    if untimed is not None:
        at = next(ep.span for ep in tl.episodes if ep.kind == untimed[0])
        res.diagnostics.append(diag(K802, untimed[1], at))
        return res
    arm: ArmModel = load_arm(b.settings.robot, None, options.package_dirs)
    arm = arm if options.lift == 1.0 else lifted(arm, options.lift)
    spec = arm.spec
    frame = reach_frame(b.settings.goal or spec.goal,
                        b.settings.start_direction or spec.start_direction)
    lap("model")

    segments: list[PathSegment | JointSegment] = []
    t_planned = 0.0
    start_pose = tl.episodes[0].start if tl.episodes else Pose(b.settings.start)
    first = _start_configuration(arm, frame, start_pose, options.start_seed)
    if first.failure is not None:
        res.diagnostics.append(start_diagnostic(
            arm, frame, b, first.failure, functools.partial(_follows, arm, frame, options)))
        return res
    q = first.q[0]
    worst_p, worst_r = first.worst_position_error, first.worst_rotation_error
    lap("ik")
    for i, ep in enumerate(tl.episodes):
        seg: PathSegment | JointSegment | None
        timing = timing_of(ep.kind).timing
        if timing is Timing.HOLD:
            segments.append(JointSegment(q, ep.duration))
        elif timing is Timing.OSCILLATION:
            seg, shiver_fail = shiver_segment(arm, q, ep.amplitude, ep.f, ep.duration)
            if shiver_fail is not None:
                f_ok = shiver_fail.wanted
                # a slower shiver than the look's floor reads as slow rolls: then the
                # amplitude is fitted instead (fit/amplitude.py)
                ok = bool(f_ok and f_ok >= LOOK_SHIVER_F)
                node = next((n for n in b.primitives if n.span == ep.span), None)
                timed = isinstance(node, Shiver) and node.timed  # its `for`, as written
                max_f = f_ok if ok else None
                dur = node.duration if isinstance(node, Shiver) and timed else None
                why = ShiverTooFast(shiver_fail.joint, shiver_fail.limit, max_f, dur, ep.f)
                edit = hint_edit(why) if ok else None
                res.diagnostics.append(_too_fast(C308, shiver_fail, ep, edit, why))
                return res
            segments.append(seg)
        else:
            s, targets = _waypoints(ep, frame, options)
            ik = solved_path(arm, frame, ep, q, options, targets)
            lap("ik")
            if ik.failure is not None:
                f = ik.failure
                frac = f.index / max(1, len(targets) - 1)
                t_fail = t_planned + ep.duration * frac
                d_fail = ep.start.lerp(ep.end, frac).d
                res.diagnostics.append(_ik_diag(ep, f.status, t_fail, f.joint, b, d_fail))
                return res
            worst_p = max(worst_p, ik.worst_position_error)
            worst_r = max(worst_r, ik.worst_rotation_error)
            if timing is Timing.FIXED:
                seg, tilt_fail = tilt_segment(arm, s, ik.q, ep.duration, functools.partial(
                    _siblings, arm, frame, tl.episodes[i:], ik.q[-1], options))
                if tilt_fail is not None:
                    v_ok = tilt_fail.wanted
                    edit = f"v={v_ok:g}deg/s" if v_ok else None
                    res.diagnostics.append(_too_fast(C309, tilt_fail, ep, edit, TiltTooFast(
                        tilt_fail.joint, tilt_fail.limit, v_ok,
                        math.degrees(ep.path_length / ep.duration))))
                    return res
            else:
                seg, fail = timed_path(arm, frame, ep, q, options, s, ik.q)
                if seg is None:
                    reason = fail.reason if fail is not None else "no time law"
                    res.diagnostics.append(diag(C305, f"{ep.kind}: {reason}", ep.span))
                    return res
                if fail is not None:
                    kt = timing_of(ep.kind)
                    res.diagnostics.append(refused(
                        C304, f"{ep.kind} reaches {fail.achieved:.3g} {kt.unit}, not the "
                        f"declared {fail.wanted:.3g} {kt.unit}: {fail.reason}", ep.span,
                        AccelerationShort(fail.joint, fail.achieved, fail.wanted,
                                          kt.acceleration)))
            lap("timing")
            segments.append(seg)
            q = ik.q[-1]
        t_planned += segments[-1].duration
    res.ik_position_error, res.ik_rotation_error = worst_p, worst_r
    res.frame, res.segments = frame, segments
    res.trajectory = _sample(arm, b, tl, segments, options.rate, options.package_dirs)
    lap("sample")
    return res


def target_path(res: CompileResult) -> tuple[np.ndarray, np.ndarray]:
    """The end-effector poses the trajectory is meant to follow, at its sample times:
    positions (N, 3) and rotations (N, 3, 3). For accuracy studies and benchmarks."""
    tr, tl, frame = res.trajectory, res.timeline, res.frame
    if tr is None or tl is None or frame is None:
        raise AouError(diag(C305, "the compilation failed: there is no path to follow",
                            res.behaviour.span))
    pos = np.empty((len(tr.t), 3))
    rot = np.empty((len(tr.t), 3, 3))
    for (_, t0, t1), ep, seg in zip(tr.episodes, tl.episodes, res.segments, strict=True):
        m = (tr.t >= t0) & (tr.t <= t1)
        if isinstance(seg, PathSegment):
            s = seg.law(tr.t[m] - t0)[0]
            f = s / ep.path_length if ep.path_length else np.zeros_like(s)
        else:
            f = np.zeros(int(m.sum()))
        a, b = ep.start, ep.end
        out = [frame.target(a.lerp(b, x)) for x in f]
        if out:
            pos[m] = [o[0] for o in out]
            rot[m] = [o[1] for o in out]
    return pos, rot


def sample(res: CompileResult, rate: float) -> Trajectory:
    """The compiled motion sampled at ``rate`` [Hz] (the checks' dense clock)."""
    if res.trajectory is None or res.timeline is None:
        raise AouError(diag(C305, "the compilation failed: there is nothing to sample",
                            res.behaviour.span))
    dirs = res.trajectory.package_dirs
    arm = load_arm(res.behaviour.settings.robot, None, dirs)
    return _sample(arm, res.behaviour, res.timeline, res.segments, rate, dirs)


def _clock(total: float, rate: float) -> np.ndarray:
    """Sample times at ``rate`` from 0, ending exactly at ``total`` (the motion's true
    end, at rest): a last tick closer than half a period to the end is moved onto it."""
    n = int(math.floor(total * rate + 1e-9)) + 1
    t = np.arange(n) / rate
    if total - t[-1] > 0.5 / rate:
        return np.append(t, total)
    if len(t) > 1:
        t[-1] = total
    return t


def evaluate(res: CompileResult, t: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint positions, velocities and accelerations of the compiled motion at any times
    ``t`` [s], shape (N,): each (N, n). Before the start and after the end the arm rests
    in its first and last configuration (as a controller holds it)."""
    if res.trajectory is None or not res.segments:
        raise AouError(diag(C305, "the compilation failed: there is nothing to sample",
                            res.behaviour.span))
    q, qd, qdd = _evaluate(res.segments, np.asarray(t, dtype=float))
    return q, qd, qdd


def positions(res: CompileResult, t: np.ndarray) -> np.ndarray:
    """``evaluate(res, t)[0]`` without the velocities and accelerations: the positions
    [rad], (N, n), a controller's view of the motion reads."""
    if res.trajectory is None or not res.segments:
        raise AouError(diag(C305, "the compilation failed: there is nothing to sample",
                            res.behaviour.span))
    return _evaluate(res.segments, np.asarray(t, dtype=float), positions=True)[0]


def _evaluate(segments: list[PathSegment | JointSegment], t: np.ndarray,
              positions: bool = False) -> tuple[np.ndarray, ...]:
    """``q, qd, qdd`` at times ``t`` (``q`` alone with ``positions``)."""
    bounds = np.concatenate([[0.0], np.cumsum([s.duration for s in segments])])
    n = segments[0].n  # the joints (a segment's samples have as many columns)
    out = tuple(np.empty((len(t), n)) for _ in range(1 if positions else 3))
    idx = np.clip(np.searchsorted(bounds, t, side="right") - 1, 0, len(segments) - 1)
    if len(t) > 1 and np.all(t[1:] >= t[:-1]):  # a clock: each segment's times in a row
        ends = np.searchsorted(idx, np.arange(len(segments) + 1), side="left")
        parts: list = [slice(ends[k], ends[k + 1]) for k in range(len(segments))]
    else:
        parts = [idx == k for k in range(len(segments))]
    for k, (seg, m) in enumerate(zip(segments, parts, strict=True)):
        tau = t[m] - bounds[k]
        if len(tau) == 0:
            continue
        if positions:
            out[0][m] = seg.positions(tau)
        else:
            out[0][m], out[1][m], out[2][m] = seg.sample(tau)
    return out


def _sample(arm: ArmModel, b: Behaviour, tl: Timeline,
            segments: list[PathSegment | JointSegment], rate: float,
            package_dirs: tuple[str, ...] = ()) -> Trajectory:
    """Sample the segments on one clock at ``rate``; the last sample is the end."""
    if not segments:
        raise AouError(diag(V124, "the behaviour has nothing to move or hold", b.span))
    bounds = np.concatenate([[0.0], np.cumsum([s.duration for s in segments])])
    t = _clock(float(bounds[-1]), rate)
    q, qd, qdd = _evaluate(segments, t)
    spec = arm.spec
    goal = tuple(float(x) for x in (b.settings.goal or spec.goal))
    episodes = tuple((e.kind, float(bounds[i]), float(bounds[i + 1]))
                     for i, e in enumerate(tl.episodes))
    return Trajectory(t, q, arm.joint_names, spec.name, spec.ee_frame, goal, qd, qdd,
                      episodes, title=b.name, package_dirs=package_dirs,
                      ee_definition=frame_definition(spec))
