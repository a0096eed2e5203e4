"""The eleven expressive descriptors of MODEL.md s5, measured from a joint trajectory.

The steps (docs/measure.md explains the choices):

1. Resample onto a uniform clock (a cubic spline through the samples), estimate the
   joint noise from third differences, and differentiate: central differences for clean
   data, Savitzky-Golay filters (window set by the noise) for noisy data.
2. Forward kinematics (Pinocchio): end-effector position and rotation at every sample.
3. Pauses: every joint speed under a threshold (adapted to the noise) for at least
   ``MIN_PAUSE``; their ends are refined by extrapolating the speed to zero, since
   motion stops with a constant deceleration.
4. Episodes: the motion between pauses, split where the speed comes to rest, and
   classified by what moved: distance to the goal (approach, retreat), bearing of the
   goal vector (gaze), roll about the forward axis (tilt), or a fast back-and-forth roll
   (shiver, three or more alternations with no rest).
5. The descriptors, from those episodes exactly as MODEL.md defines them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..cv import Composition, CVPoint, infer
from ..declared import DESCRIPTORS
from ..diagnostics import Diagnostic, Span, diag
from ..kinematics import ArmModel, load_arm
from .recording import Recording

__all__ = ["DESCRIPTORS", "MIN_PAUSE", "Measured", "MeasuredEpisode", "measure"]


#: Shortest rest that counts as a pause [s] (the language's shortest pause is 0.2 s).
MIN_PAUSE = 0.15
#: Joint speed under which a clean trajectory is at rest [rad/s].
REST_SPEED = 1e-4
#: Translation under which an episode has not moved the end-effector [m].
STILL_TRANSLATION = 2e-3
#: Rest instants closer than this are one stop [s].
STOP_MERGE = 0.08


@dataclass(frozen=True)
class MeasuredEpisode:
    """One episode found in the trajectory, with the values measured on it."""

    kind: str
    t_start: float
    t_end: float
    values: dict[str, float] = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return self.t_end - self.t_start

    def to_json(self) -> dict:
        return {"kind": self.kind, "t_start": round(self.t_start, 4),
                "t_end": round(self.t_end, 4),
                **{k: round(v, 6) for k, v in self.values.items()}}


@dataclass
class Measured:
    """The result of measuring one trajectory."""

    descriptors: dict[str, float | int | None]
    episodes: list[MeasuredEpisode]
    cv: CVPoint
    diagnostics: list[Diagnostic]
    noise: float  # estimated joint noise [rad]
    gaze_error: float  # worst angle between the end-effector z axis and the goal [deg]
    duration: float

    def to_json(self) -> dict:
        return {
            "descriptors": {k: (round(v, 6) if isinstance(v, float) else v)
                            for k, v in self.descriptors.items()},
            "episodes": [e.to_json() for e in self.episodes],
            "cv": self.cv.to_json(),
            "noise": self.noise,
            "gaze_error_deg": round(self.gaze_error, 6),
            "duration": round(self.duration, 6),
            "diagnostics": [d.to_json() for d in self.diagnostics],
        }


# --- signal processing --------------------------------------------------------------------


def _uniform(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resample onto a uniform clock at the median step (exact if already uniform).

    A trajectory whose last step alone is shorter (it ends between two ticks of its
    clock) keeps its samples; the last one is dropped and its time kept by the caller.
    """
    steps = np.diff(t)
    dt = float(np.median(steps))
    if np.allclose(steps[:-1], dt, rtol=1e-6, atol=1e-9):
        if abs(steps[-1] - dt) < 1e-9:
            return t - t[0], q
        return t[:-1] - t[0], q[:-1]
    from scipy.interpolate import CubicSpline

    n = int(math.floor((t[-1] - t[0]) / dt + 1e-9)) + 1
    tu = t[0] + np.arange(n) * dt
    return tu - t[0], CubicSpline(t, q, axis=0)(tu)


def _noise(q: np.ndarray) -> float:
    """Joint noise [rad] from the median absolute third difference (robust to motion)."""
    if len(q) < 8:
        return 0.0
    d3 = np.diff(q, n=3, axis=0)
    # For white noise of std s, the third difference has std s * sqrt(20).
    return float(np.median(np.abs(d3)) / 0.6745 / math.sqrt(20.0))


def _derivatives(x: np.ndarray, dt: float, window: int) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
    """Smoothed value, first and second derivative along axis 0."""
    if window <= 2:
        v = np.gradient(x, dt, axis=0)
        return x, v, np.gradient(v, dt, axis=0)
    from scipy.signal import savgol_filter

    w = min(window | 1, (len(x) - 1) | 1 if len(x) % 2 == 0 else len(x))
    w = max(5, w if w % 2 else w - 1)
    return (savgol_filter(x, w, 3, axis=0), savgol_filter(x, w, 3, deriv=1, delta=dt, axis=0),
            savgol_filter(x, w, 3, deriv=2, delta=dt, axis=0))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    if not mask.any():
        return []
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts = np.flatnonzero(d == 1)
    ends = np.flatnonzero(d == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def _refine(t: np.ndarray, speed: np.ndarray, i: int, direction: int, thr: float) -> float:
    """The time where the speed reaches zero next to the rest sample ``i``.

    Motion comes to rest (and leaves it) with a nearly constant acceleration, so the speed
    is linear in time there: a line through the moving samples beside the rest run
    (``direction`` -1: before it, +1: after it), while the speed keeps growing away from
    the rest and stays within a few thresholds (or, for clean data, a few samples), is
    extrapolated to zero. This undoes the smear of the differentiation filter.
    """
    idx = []
    j = i + direction
    limit = 6.0 * thr
    while 0 <= j < len(t) and len(idx) < 40:
        if idx and speed[j] < speed[idx[-1]]:
            break  # no longer moving away from rest
        if speed[j] >= limit and len(idx) >= 4:
            break
        idx.append(j)
        j += direction
    if len(idx) < 3:
        return float(t[i])
    tt, ss = t[idx], speed[idx]
    slope, icpt = np.polyfit(tt, ss, 1)
    if slope == 0:
        return float(t[i])
    t0 = -icpt / slope
    # Stay within the samples used and the rest sample.
    lo, hi = sorted((float(t[idx[-1]]), float(t[i])))
    return float(np.clip(t0, lo, hi))


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


def _joint_columns(rec: Recording, arm: ArmModel) -> np.ndarray:
    from ..diagnostics import AouError

    missing = [n for n in arm.joint_names if n not in rec.joint_names]
    if missing:
        raise AouError(diag(
            "R402", f"the trajectory lacks joint(s) {', '.join(missing)} of robot "
            f"`{rec.robot}`; its columns are {', '.join(rec.joint_names)}",
            Span.whole_file(rec.path), missing=missing))
    return np.array([rec.joint_names.index(n) for n in arm.joint_names])


def measure(rec: Recording) -> Measured:
    """Measure the eleven descriptors of a recording.

    Raises:
        AouError: R401/R402 when the recording cannot be measured.
    """
    arm = load_arm(rec.robot, rec.ee_frame)
    cols = _joint_columns(rec, arm)
    t, q = _uniform(np.asarray(rec.t, float), np.asarray(rec.q, float)[:, cols])
    t_last = float(rec.t[-1] - rec.t[0])  # the end, even if its sample was dropped
    dt = float(t[1] - t[0])
    sigma = _noise(q)
    clean = sigma < 1e-7
    # Windows: none for clean data; for noisy data wide enough to pull the noise of the
    # first derivative under 1e-3 rad/s and of the Cartesian acceleration under ~1%.
    wq = 1 if clean else max(7, int(round(0.12 / dt)))
    wp = 1 if clean else max(9, int(round(0.30 / dt)))
    qs, qd, _ = _derivatives(q, dt, wq)
    pos, rot = arm.fk(qs)
    _, _, pacc = _derivatives(pos, dt, wp)
    goal = np.asarray(rec.goal, float)
    g = goal - pos
    dist = np.linalg.norm(g, axis=1)
    z_axes = rot[:, :, 2]
    cosang = np.einsum("ij,ij->i", z_axes, g) / np.maximum(dist, 1e-12)
    gaze_error = float(np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0))).max())

    speed = np.abs(qd).max(axis=1)
    if clean:
        thr = REST_SPEED
    else:
        # Velocity noise of the filtered derivative, from the noise of the positions.
        thr = max(REST_SPEED, 8.0 * sigma * math.sqrt(12.0 / (wq ** 3)) / dt)
    rest = speed < thr
    diags: list[Diagnostic] = []

    # --- pauses -----------------------------------------------------------------------
    pauses: list[tuple[float, float, int, int]] = []
    for i0, i1 in _runs(rest):
        t0 = _refine(t, speed, i0, -1, thr) if i0 > 0 else float(t[i0])
        t1 = _refine(t, speed, i1, +1, thr) if i1 < len(t) - 1 else t_last
        if t1 - t0 >= MIN_PAUSE:
            pauses.append((t0, t1, i0, i1))
    # A trajectory that starts or ends at rest: that rest is the start/end pose, not a
    # pause, unless it lasts a pause's length (then it is one).

    # --- episodes ---------------------------------------------------------------------
    episodes: list[MeasuredEpisode] = []
    bounds = [(-1, -1)] + [(p[2], p[3]) for p in pauses] + [(len(t), len(t))]
    pause_eps = [MeasuredEpisode("pause", p[0], p[1], {"duration": p[1] - p[0]})
                 for p in pauses]
    timeline: list[MeasuredEpisode] = []
    for k in range(len(bounds) - 1):
        a, b = bounds[k][1] + 1, bounds[k + 1][0] - 1
        if k > 0:
            timeline.append(pause_eps[k - 1])
        if b - a < 2:
            continue
        timeline += _motion_episodes(t, a, b, speed, thr, pos, rot, q, dist, g, pacc)
    episodes = timeline

    # --- descriptors ------------------------------------------------------------------
    g0 = g[0]
    y0, x0 = rot[0][:, 1], rot[0][:, 0]
    for i, e in enumerate(episodes):
        if e.kind == "gaze":
            ends_at_pause = i + 1 < len(episodes) and episodes[i + 1].kind == "pause"
            e.values["ends_at_pause"] = float(ends_at_pause)
            j = int(round(e.t_end / dt))
            j = min(j, len(g) - 1)
            e.values["horizontal"] = abs(math.degrees(_signed_angle(g0, g[j], y0)))
            e.values["vertical"] = abs(math.degrees(_signed_angle(g0, g[j], x0)))
        if e.kind == "retreat":
            prev_p = i > 0 and episodes[i - 1].kind == "pause"
            next_p = i + 1 < len(episodes) and episodes[i + 1].kind == "pause"
            e.values["between_pauses"] = float(prev_p and next_p)

    def of(kind: str, cond=None) -> list[MeasuredEpisode]:
        return [e for e in episodes if e.kind == kind and (cond is None or cond(e))]

    d: dict[str, float | int | None] = dict.fromkeys(DESCRIPTORS)
    approaches = of("approach")
    if approaches:
        d["approach_acceleration"] = max(e.values["peak_acceleration"] for e in approaches)
    ps = of("pause")
    d["pause_count"] = len(ps)
    if ps:
        d["pause_duration"] = _mean(ps, "duration", diags, rec.path, "pause_duration",
                                    tol=lambda m: max(0.02, 0.02 * m))
    rs = of("retreat", lambda e: e.values.get("between_pauses"))
    d["retreat_count"] = len(rs)
    if rs:
        d["retreat_distance"] = _mean(rs, "distance", diags, rec.path, "retreat_distance",
                                      tol=lambda m: 1e-3)
        d["retreat_acceleration"] = max(e.values["peak_acceleration"] for e in rs)
    for plane in ("horizontal", "vertical"):
        gs = of("gaze", lambda e, p=plane: e.values.get("plane") == (p == "horizontal")
                and e.values.get("ends_at_pause"))
        if gs:
            d[f"{plane}_gaze"] = _mean(gs, plane, diags, rec.path, f"{plane}_gaze",
                                       tol=lambda m: 0.5)
    ts = of("tilt")
    if ts:
        d["tilt_angle"] = _mean(ts, "angle", diags, rec.path, "tilt_angle", tol=lambda m: 0.5)
        d["tilt_velocity"] = _mean(ts, "velocity", diags, rec.path, "tilt_velocity",
                                   tol=lambda m: max(0.5, 0.02 * m))
    ss = of("shiver")
    if ss:
        d["shiver_amplitude"] = _mean(ss, "amplitude", diags, rec.path, "shiver_amplitude",
                                      tol=lambda m: 0.5)

    comp = Composition(
        approach_acceleration=d["approach_acceleration"],
        pause_count=len(ps),
        pause_duration=d["pause_duration"] or 0.0,
        retreat_count=len(rs),
        retreat_distance=d["retreat_distance"] or 0.0,
        retreat_acceleration=d["retreat_acceleration"] or 0.0,
        gaze_swept=sum(max(e.values["horizontal"], e.values["vertical"])
                       for e in of("gaze", lambda e: e.values.get("ends_at_pause"))),
        tilt_swept=sum(e.values["angle"] for e in ts),
        shiver_amplitude=d["shiver_amplitude"] or 0.0,
        shiver_count=len(ss),
    )
    point, _ = infer(comp)
    return Measured(d, episodes, point, diags, sigma, gaze_error, float(rec.t[-1] - rec.t[0]))


def _mean(eps: list[MeasuredEpisode], key: str, diags: list[Diagnostic], path: str,
          name: str, tol) -> float:
    vals = [e.values[key] for e in eps]
    m = float(np.mean(vals))
    if max(vals) - min(vals) > tol(m):
        diags.append(diag("R403", f"{name} differs between episodes: "
                          f"{', '.join(f'{v:.4g}' for v in vals)}; reporting the mean {m:.4g}",
                          Span.whole_file(path), descriptor=name, values=vals))
    return m


def _motion_episodes(t, a, b, speed, thr, pos, rot, q, dist, g, pacc) -> list[MeasuredEpisode]:
    """Split the motion between samples a..b (inclusive) at rest instants and classify."""
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
        pieces.append(_classify(t, s, e, pos, rot, q, dist, g, pacc))
    return _merge_shivers(pieces, q, t)


def _classify(t, s, e, pos, rot, q, dist, g, pacc) -> MeasuredEpisode:
    dp = pos[e] - pos[s]
    travel = float(np.linalg.norm(np.diff(pos[s:e + 1], axis=0), axis=1).sum())
    dr = float(dist[e] - dist[s])
    acc = float(np.linalg.norm(pacc[s:e + 1], axis=1).max())
    if travel > STILL_TRANSLATION:
        if abs(dr) >= 0.7 * travel:
            kind = "approach" if dr < 0 else "retreat"
            return MeasuredEpisode(kind, float(t[s]), float(t[e]), {
                "distance": float(np.linalg.norm(dp)), "peak_acceleration": acc})
        y0, x0 = rot[s][:, 1], rot[s][:, 0]
        dh = abs(_signed_angle(g[s], g[e], y0))
        dv = abs(_signed_angle(g[s], g[e], x0))
        return MeasuredEpisode("gaze", float(t[s]), float(t[e]), {
            "plane": float(dh >= dv), "swept": math.degrees(max(dh, dv)),
            "peak_acceleration": acc})
    roll = _roll(rot[s], rot[e])
    rng = q[s:e + 1].max(axis=0) - q[s:e + 1].min(axis=0)
    return MeasuredEpisode("tilt", float(t[s]), float(t[e]), {
        "angle": abs(math.degrees(roll)), "signed": math.degrees(roll),
        "velocity": abs(math.degrees(roll)) / max(float(t[e] - t[s]), 1e-9),
        "joint": float(np.argmax(rng))})


def _merge_shivers(pieces: list[MeasuredEpisode], q, t) -> list[MeasuredEpisode]:
    """Three or more roll pieces in a row that alternate in direction are one shiver."""
    out: list[MeasuredEpisode] = []
    i = 0
    while i < len(pieces):
        j = i
        while (j + 1 < len(pieces) and pieces[j].kind == "tilt" and pieces[j + 1].kind == "tilt"
               and pieces[j].values["signed"] * pieces[j + 1].values["signed"] < 0):
            j += 1
        if j - i + 1 >= 3:
            t0, t1 = pieces[i].t_start, pieces[j].t_end
            m = (t >= t0) & (t <= t1)
            rng = q[m].max(axis=0) - q[m].min(axis=0)
            jj = int(np.argmax(rng))
            out.append(MeasuredEpisode("shiver", t0, t1, {
                "amplitude": math.degrees(float(rng[jj])), "joint": float(jj),
                "cycles": (j - i + 1) / 2.0}))
            i = j + 1
        else:
            out.append(pieces[i])
            i += 1
    return out
