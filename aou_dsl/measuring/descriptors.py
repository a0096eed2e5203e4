"""The eleven expressive descriptors, measured from a joint trajectory.

The steps (docs/measure.md explains the choices):

1. Resample onto a uniform clock (a cubic spline through the samples), estimate the
   joint noise from third differences, and differentiate: central differences for clean
   data, Savitzky-Golay filters (window set by the noise) for noisy data.
2. Forward kinematics (Pinocchio): end-effector position and rotation at every sample.
3. Pauses: every joint speed under a threshold (adapted to the noise) for at least
   ``MIN_PAUSE``; their ends are refined by extrapolating the speed to zero, since
   motion stops with a constant deceleration.
4. Episodes: the motion between pauses, split where the speed comes to rest, and
   classified by what moved: distance to the goal (approach, retreat), the goal
   vector's angle in the planes fixed by the start pose (gaze), roll about the forward
   axis (tilt), or a fast back-and-forth roll (shiver, three or more alternations with
   no rest).
5. The descriptors, from those episodes by :func:`aou_dsl.descriptors.derive`: the
   same function that derives what a file declares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..cv import CVPoint, composition, infer
from ..descriptors import REGISTRY, Descriptors, EpisodeValues, derive, spread
from ..diagnostics import AouError, Diagnostic, Span, diag
from ..kinematics import ArmModel, load_arm
from ..trajectory import Trajectory
from .signal import derivatives as _derivatives
from .signal import noise as _noise
from .signal import refine as _refine
from .signal import refine_noisy as _refine_noisy
from .signal import runs as _runs
from .signal import uniform as _uniform

__all__ = ["MIN_PAUSE", "Measured", "measure"]


#: Shortest rest that counts as a pause [s] (the language's shortest pause is 0.2 s).
MIN_PAUSE = 0.15
#: Joint speed under which a clean trajectory is at rest [rad/s].
REST_SPEED = 1e-4
#: Translation under which an episode has not moved the end-effector [m].
STILL_TRANSLATION = 2e-3
#: Smallest roll reported as a tilt [rad] (the tilt tolerance is 0.5 deg).
MIN_TILT = math.radians(0.5)
#: Rest instants closer than this are one stop [s].
STOP_MERGE = 0.08


@dataclass
class Measured:
    """The result of measuring one trajectory."""

    descriptors: Descriptors
    episodes: list[EpisodeValues]
    cv: CVPoint
    diagnostics: list[Diagnostic]
    noise: float  # estimated joint noise [rad]
    gaze_error: float  # worst angle between the end-effector z axis and the goal [deg]
    duration: float

    def to_json(self) -> dict:
        return {
            "descriptors": self.descriptors.to_json(),
            "episodes": [e.to_json() for e in self.episodes],
            "cv": self.cv.to_json(),
            "noise": self.noise,
            "gaze_error_deg": round(self.gaze_error, 6),
            "duration": round(self.duration, 6),
            "diagnostics": [d.to_json() for d in self.diagnostics],
        }


# --- geometry -------------------------------------------------------------------------------


def _signed_angle(a: np.ndarray, b: np.ndarray, normal: np.ndarray) -> float:
    """Angle from ``a`` to ``b`` about ``normal`` [rad]; both projected onto its plane."""
    a = a - (a @ normal) * normal
    b = b - (b @ normal) * normal
    return float(math.atan2(np.cross(a, b) @ normal, a @ b))


def _roll(r0: np.ndarray, r1: np.ndarray) -> float:
    """The twist about the local z axis of the rotation from ``r0`` to ``r1`` [rad]."""
    rel = r0.T @ r1
    return float(math.atan2(rel[1, 0] - rel[0, 1], rel[0, 0] + rel[1, 1]))


# --- measuring ------------------------------------------------------------------------------


def _signals(rec: Trajectory, arm: ArmModel) -> tuple[_Signals, np.ndarray, int, float]:
    """Resampled joints, their noise, derivatives and forward kinematics; the joint
    speed (N,), the filter window and the end time."""
    t, q = _uniform(np.asarray(rec.t, float),
                    np.asarray(rec.q, float)[:, rec.columns(arm.joint_names)])
    dt = float(t[1] - t[0])
    sigma = _noise(q)
    clean = sigma < 1e-7
    # Clean data: central differences. Noisy data: a cubic Savitzky-Golay filter of
    # 0.2 s for joint speeds; the rest threshold is 5.5 times the filtered speed's noise
    # (its gain is the norm of the filter's coefficients).
    wq = 1 if clean else _odd(0.2 / dt)
    qs, qd, _ = _derivatives(q, dt, wq)
    pos, rot = arm.fk(qs if clean else q)
    pos_s = pos if clean else _derivatives(pos, dt, wq)[0]
    pacc = np.gradient(np.gradient(pos, dt, axis=0), dt, axis=0) if clean else None
    if rec.goal is None:
        raise AouError(diag("R401", "the trajectory has no goal", Span.whole_file(rec.path),
                            hint="give it with --goal X,Y,Z"))
    goal = np.asarray(rec.goal, float)
    g = goal - pos_s
    if clean:
        thr = REST_SPEED
    else:
        from scipy.signal import savgol_coeffs

        gain = float(np.linalg.norm(savgol_coeffs(wq, 3, deriv=1, delta=dt)))
        thr = max(REST_SPEED, 5.5 * sigma * gain)
    sig = _Signals(t, dt, pos, pos_s, rot, q, np.linalg.norm(g, axis=1), g, pacc, sigma, thr,
                   qd, rot[0][:, 1], rot[0][:, 0])
    return sig, np.abs(qd).max(axis=1), wq, float(rec.t[-1] - rec.t[0])


def _gaze_error(sig: _Signals, goal: np.ndarray) -> float:
    """The worst angle between the end-effector's z axis and the goal [deg]."""
    to_goal = goal - sig.pos
    cosang = np.einsum("ij,ij->i", sig.rot[:, :, 2], to_goal) / np.maximum(
        np.linalg.norm(to_goal, axis=1), 1e-12)
    return float(np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0))).max())


def _pauses(sig: _Signals, speed: np.ndarray, wq: int, t_last: float
            ) -> list[tuple[float, float, int, int]]:
    """The holds: (t_start, t_end, first rest sample, last rest sample)."""
    t, clean = sig.t, sig.pacc is not None
    rest = speed < sig.thr
    if not clean:
        # Close gaps of a few samples in a rest run: a noise spike is not motion.
        for i0, i1 in _runs(~rest):
            if i1 - i0 < 3 and i0 > 0 and i1 < len(rest) - 1:
                rest[i0:i1 + 1] = True
    out = []
    for i0, i1 in _runs(rest):
        if t[i1] - t[i0] < 0.6 * MIN_PAUSE:
            continue  # an instant of rest (a reversal, the stop between two episodes)
        if clean:
            t0 = _refine(t, speed, i0, -1, sig.thr) if i0 > 0 else float(t[i0])
            t1 = _refine(t, speed, i1, +1, sig.thr) if i1 < len(t) - 1 else t_last
        else:
            t0 = _refine_noisy(t, sig.qd, i0, -1, wq // 2) if i0 > 0 else float(t[i0])
            t1 = _refine_noisy(t, sig.qd, i1, +1, wq // 2) if i1 < len(t) - 1 else t_last
        if t1 - t0 >= MIN_PAUSE:
            out.append((t0, t1, i0, i1))
    return out


def measure(rec: Trajectory) -> Measured:
    """Measure the eleven descriptors of a trajectory.

    Raises:
        AouError: R401/R402 when the trajectory cannot be measured.
    """
    arm = load_arm(rec.robot, rec.ee_frame)
    sig, speed, wq, t_last = _signals(rec, arm)
    pauses = _pauses(sig, speed, wq, t_last)
    bounds = [(-1, -1)] + [(p[2], p[3]) for p in pauses] + [(len(sig.t), len(sig.t))]
    episodes: list[EpisodeValues] = []
    for k in range(len(bounds) - 1):
        a, b = bounds[k][1] + 1, bounds[k + 1][0] - 1
        if k > 0:
            t0, t1 = pauses[k - 1][0], pauses[k - 1][1]
            episodes.append(EpisodeValues("pause", t0, t1, {"duration": t1 - t0}))
        if b - a >= 2:
            episodes += _motion_episodes(sig, a, b, speed)
    descriptors = derive(episodes)
    diags = [diag("R403", f"{name} differs between episodes: "
                  f"{', '.join(f'{v:.4g}' for v in vals)}; reporting the "
                  f"{REGISTRY[name].aggregate} {descriptors[name]:.4g}",
                  Span.whole_file(rec.path),
                  descriptor=name, values=vals)
             for name, vals in spread(episodes).items() if _unequal(name, vals)]
    point, _ = infer(composition(episodes))
    return Measured(descriptors, episodes, point, diags, sig.sigma,
                    _gaze_error(sig, np.asarray(rec.goal, float)), t_last)


def _unequal(name: str, vals: list[float]) -> bool:
    return max(vals) - min(vals) > REGISTRY[name].tolerance(float(np.median(vals)))


def _odd(x: float) -> int:
    n = max(5, int(round(x)))
    return n if n % 2 else n + 1


@dataclass(frozen=True)
class _Signals:
    """Per-sample signals shared by the episode functions (arrays of length N)."""

    t: np.ndarray
    dt: float
    pos: np.ndarray  # raw end-effector position [m], (N, 3)
    pos_s: np.ndarray  # smoothed position
    rot: np.ndarray  # (N, 3, 3)
    q: np.ndarray  # (N, n)
    dist: np.ndarray  # goal distance [m]
    g: np.ndarray  # goal vector, (N, 3)
    pacc: np.ndarray | None  # clean data: acceleration by central differences
    sigma: float  # joint noise [rad]
    thr: float  # rest speed [rad/s]
    qd: np.ndarray  # joint velocities, (N, n)
    y0: np.ndarray  # normal of the horizontal plane: the start pose's y axis, (3,)
    x0: np.ndarray  # normal of the vertical plane: the start pose's x axis, (3,)


def _peak_acceleration(sig: _Signals, s: int, e: int) -> float:
    """Peak end-effector acceleration on samples s..e [m/s^2].

    Clean data: the largest central-difference acceleration away from the ends. Noisy data: a cubic
    Savitzky-Golay second derivative with a window of 40 % of the episode (at most
    0.6 s), projected on the episode's direction of travel so that noise across it does
    not inflate the magnitude.
    """
    if sig.pacc is not None:
        # Two central differences reach two samples out: at the ends of an episode they
        # mix in the neighbouring episode's motion. Bang-bang plateaus reach the ends,
        # so leaving those samples out loses nothing of the peak.
        inner = sig.pacc[s + 2:e - 1] if e - s > 6 else sig.pacc[s:e + 1]
        return float(np.linalg.norm(inner, axis=1).max())
    from scipy.signal import savgol_filter

    w = _odd(min(0.6, 0.4 * (sig.t[e] - sig.t[s])) / sig.dt)
    lo, hi = max(0, s - w), min(len(sig.t), e + w + 1)
    acc = savgol_filter(sig.pos[lo:hi], w, 3, deriv=2, delta=sig.dt, axis=0)
    u = sig.pos_s[e] - sig.pos_s[s]
    u = u / max(np.linalg.norm(u), 1e-12)
    along = np.abs(acc[s - lo + w // 2:e - lo - w // 2 + 1] @ u)
    return float(along.max()) if along.size else float(np.abs(acc @ u).max())


def _motion_episodes(sig: _Signals, a: int, b: int, speed: np.ndarray
                     ) -> list[EpisodeValues]:
    """Split the motion between samples a..b (inclusive) at rest instants and classify."""
    t, thr = sig.t, sig.thr
    seg = speed[a:b + 1]
    peak = float(seg.max()) if len(seg) else 0.0
    if peak <= thr:
        return []
    # Rest instants: local minima of the speed well under the local peak.
    low = max(thr, 0.05 * peak)
    cand = [i for i in range(a + 1, b) if speed[i] <= speed[i - 1] and speed[i] <= speed[i + 1]
            and speed[i] < low]
    cuts: list[int] = []
    for i in cand:
        if cuts and t[i] - t[cuts[-1]] < STOP_MERGE:
            if speed[i] < speed[cuts[-1]]:
                cuts[-1] = i
            continue
        cuts.append(i)
    edges = [a] + cuts + [b]
    pieces = []
    for s, e in zip(edges[:-1], edges[1:], strict=True):
        if e - s < 2:
            continue
        piece = _classify(sig, s, e)
        if piece is not None:
            pieces.append(_refined(piece, sig, speed, s, e))
    return _merge_shivers(pieces, sig.q, t)


def _edge(t: np.ndarray, speed: np.ndarray, i: int, direction: int) -> float:
    """Clean data: where the motion leaving (``direction`` +1) or reaching (-1) the rest
    instant ``i`` is at zero speed. Near rest the time law has a constant acceleration,
    so the speed is linear: a line through the next samples, extrapolated to zero, within
    one sample of ``i``."""
    idx = [i + direction * k for k in range(1, 5)]
    if min(idx) < 0 or max(idx) >= len(t):
        return float(t[i])
    slope, icpt = np.polyfit(t[idx], speed[idx], 1)
    if slope == 0:
        return float(t[i])
    lo, hi = float(t[max(i - 1, 0)]), float(t[min(i + 1, len(t) - 1)])
    return float(np.clip(-icpt / slope, lo, hi))


def _refined(ep: EpisodeValues, sig: _Signals, speed: np.ndarray, s: int, e: int
             ) -> EpisodeValues:
    """An episode with its edges moved from the samples to where it starts and stops
    (clean data); a tilt's velocity is its angle over that duration."""
    if sig.pacc is None:
        return ep
    t0, t1 = _edge(sig.t, speed, s, +1), _edge(sig.t, speed, e, -1)
    values = dict(ep.values)
    if ep.kind == "tilt":
        values["velocity"] = values["angle"] / max(t1 - t0, 1e-9)
    return EpisodeValues(ep.kind, t0, t1, values)


#: A gaze moved in a plane when its angle there changed by more than this [deg].
MIN_GAZE_SWEEP = 0.25


def _gaze(sig: _Signals, s: int, e: int) -> EpisodeValues:
    """A gaze: its angle from the initial line of sight at its end, in each plane (fixed
    by the start pose) it moved in."""
    values: dict[str, float] = {}
    for plane, normal in (("horizontal", sig.y0), ("vertical", sig.x0)):
        start = math.degrees(_signed_angle(sig.g[0], sig.g[s], normal))
        end = math.degrees(_signed_angle(sig.g[0], sig.g[e], normal))
        if abs(end - start) > MIN_GAZE_SWEEP:
            values[plane] = abs(end)
    values["angle"] = max(values.values(), default=0.0)
    return EpisodeValues("gaze", float(sig.t[s]), float(sig.t[e]), values)


def _classify(sig: _Signals, s: int, e: int) -> EpisodeValues | None:
    """What moved between samples s and e; None when nothing moved beyond the noise."""
    t, pos, rot, q, dist = sig.t, sig.pos_s, sig.rot, sig.q, sig.dist
    dp = pos[e] - pos[s]
    travel = float(np.linalg.norm(np.diff(pos[s:e + 1], axis=0), axis=1).sum())
    if sig.pacc is None:
        # Noisy data: the largest excursion from the start, not the path length (noise
        # makes every path long); on a straight line it equals the chord.
        travel = float(np.linalg.norm(pos[s:e + 1] - pos[s], axis=1).max())
    dr = float(dist[e] - dist[s])
    rng = q[s:e + 1].max(axis=0) - q[s:e + 1].min(axis=0)
    if travel <= STILL_TRANSLATION and rng.max() < 10 * sig.sigma + 1e-6:
        return None  # jitter
    if travel > STILL_TRANSLATION:
        if abs(dr) >= 0.7 * travel:
            kind = "approach" if dr < 0 else "retreat"
            return EpisodeValues(kind, float(t[s]), float(t[e]), {
                "distance": float(np.linalg.norm(dp)),
                "peak_acceleration": _peak_acceleration(sig, s, e)})
        return _gaze(sig, s, e)
    roll = _roll(rot[s], rot[e])
    if abs(roll) < MIN_TILT:
        return None  # a roll below what tilt is measured to: jitter
    return EpisodeValues("tilt", float(t[s]), float(t[e]), {
        "angle": abs(math.degrees(roll)), "signed": math.degrees(roll),
        "velocity": abs(math.degrees(roll)) / max(float(t[e] - t[s]), 1e-9),
        "joint": float(np.argmax(rng))})


def _continues_shiver(a: EpisodeValues, b: EpisodeValues) -> bool:
    """Two roll pieces of one oscillation: they alternate in direction and last about as
    long (half periods of one frequency: the envelope changes their size, not their
    length). A rest-to-rest tilt beside a tremor lasts longer than its half periods."""
    if a.kind != "tilt" or b.kind != "tilt":
        return False
    da, db = a.t_end - a.t_start, b.t_end - b.t_start
    return a.values["signed"] * b.values["signed"] < 0 and max(da, db) <= 2.0 * min(da, db)


def _merge_shivers(pieces: list[EpisodeValues], q, t) -> list[EpisodeValues]:
    """Three or more roll pieces in a row that alternate in direction, at one frequency,
    are one shiver."""
    out: list[EpisodeValues] = []
    i = 0
    while i < len(pieces):
        j = i
        while j + 1 < len(pieces) and _continues_shiver(pieces[j], pieces[j + 1]):
            j += 1
        if j - i + 1 >= 3:
            t0, t1 = pieces[i].t_start, pieces[j].t_end
            m = (t >= t0) & (t <= t1)
            rng = q[m].max(axis=0) - q[m].min(axis=0)
            jj = int(np.argmax(rng))
            out.append(EpisodeValues("shiver", t0, t1, {
                "amplitude": math.degrees(float(rng[jj])), "joint": float(jj),
                "cycles": (j - i + 1) / 2.0}))
            i = j + 1
        else:
            out.append(pieces[i])
            i += 1
    return out
