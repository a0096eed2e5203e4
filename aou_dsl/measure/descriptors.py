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
#: Smallest roll reported as a tilt [rad] (the tilt tolerance is 0.5 deg).
MIN_TILT = math.radians(0.5)
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


def _derivatives(x: np.ndarray, dt: float, window: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, first and second derivative along axis 0: central differences when
    ``window`` <= 2, else a cubic Savitzky-Golay filter of ``window`` samples (odd)."""
    if window <= 2:
        v = np.gradient(x, dt, axis=0)
        return x, v, np.gradient(v, dt, axis=0)
    from scipy.signal import savgol_filter

    w = min(window, len(x) if len(x) % 2 else len(x) - 1)
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
    """Clean data: the time where the speed reaches zero next to the rest sample ``i``.

    Motion comes to rest (and leaves it) with a nearly constant acceleration, so the speed
    is linear in time there: a line through the few moving samples beside the rest run
    (``direction`` -1: before it, +1: after it), while the speed keeps growing away from
    the rest, is extrapolated to zero. This undoes the one-sample smear of central
    differences.
    """
    idx: list[int] = []
    j = i + direction
    while 0 <= j < len(t) and len(idx) < 6:
        if idx and speed[j] < speed[idx[-1]]:
            break  # no longer moving away from rest
        idx.append(j)
        j += direction
    if len(idx) < 3:
        return float(t[i])
    slope, icpt = np.polyfit(t[idx], speed[idx], 1)
    if slope == 0:
        return float(t[i])
    lo, hi = sorted((float(t[idx[-1]]), float(t[i])))
    return float(np.clip(-icpt / slope, lo, hi))


def _refine_noisy(t: np.ndarray, qd: np.ndarray, i: int, direction: int, half: int) -> float:
    """Noisy data: where the motion next to rest sample ``i`` starts or stops.

    The joint moving fastest 0.3 s away is followed back toward the rest: its *signed*
    filtered velocity is linear in time near a constant-deceleration stop and its noise
    averages out, unlike the speed (a maximum of absolute values, biased upward). The
    samples within half a filter window of the rest are skipped (the filter rounds the
    corner there); a line through the next 0.2 s is extrapolated to zero.
    """
    dt = t[1] - t[0]
    far = i + direction * int(round(0.3 / dt))
    if not 0 <= far < len(t):
        return float(t[i])
    j = int(np.argmax(np.abs(qd[far])))
    idx = np.arange(i + direction * half, i + direction * (half + int(round(0.2 / dt))),
                    direction)
    idx = idx[(idx >= 0) & (idx < len(t))]
    if len(idx) < 5:
        return float(t[i])
    slope, icpt = np.polyfit(t[idx], qd[idx, j], 1)
    if slope == 0:
        return float(t[i])
    t0 = -icpt / slope
    lo, hi = sorted((float(t[i]), float(t[idx[0]])))
    # The stop lies between the rest sample and the first sample used, give or take the
    # filter's reach.
    return float(np.clip(t0, lo - half * dt, hi + half * dt))


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
    # Clean data: central differences. Noisy data: a cubic Savitzky-Golay filter of
    # 0.2 s for joint speeds; the rest threshold is 5.5 times the filtered speed's noise
    # (its gain is the norm of the filter's coefficients).
    wq = 1 if clean else _odd(0.2 / dt)
    qs, qd, _ = _derivatives(q, dt, wq)
    pos, rot = arm.fk(qs if clean else q)
    pos_s = pos if clean else _derivatives(pos, dt, wq)[0]
    pacc = np.gradient(np.gradient(pos, dt, axis=0), dt, axis=0) if clean else None
    goal = np.asarray(rec.goal, float)
    g = goal - pos_s
    dist = np.linalg.norm(g, axis=1)
    z_axes = rot[:, :, 2]
    cosang = np.einsum("ij,ij->i", z_axes, goal - pos) / np.maximum(
        np.linalg.norm(goal - pos, axis=1), 1e-12)
    gaze_error = float(np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0))).max())

    speed = np.abs(qd).max(axis=1)
    if clean:
        thr = REST_SPEED
    else:
        from scipy.signal import savgol_coeffs

        gain = float(np.linalg.norm(savgol_coeffs(wq, 3, deriv=1, delta=dt)))
        thr = max(REST_SPEED, 5.5 * sigma * gain)
    sig = _Signals(t, dt, pos, pos_s, rot, q, dist, g, pacc, sigma, thr)
    rest = speed < thr
    if not clean:
        # Close gaps of a few samples in a rest run: a noise spike is not motion.
        for i0, i1 in _runs(~rest):
            if i1 - i0 < 3 and i0 > 0 and i1 < len(rest) - 1:
                rest[i0:i1 + 1] = True
    diags: list[Diagnostic] = []

    # --- pauses -----------------------------------------------------------------------
    pauses: list[tuple[float, float, int, int]] = []
    for i0, i1 in _runs(rest):
        if t[i1] - t[i0] < 0.6 * MIN_PAUSE:
            continue  # an instant of rest (a reversal, the stop between two episodes)
        if clean:
            t0 = _refine(t, speed, i0, -1, thr) if i0 > 0 else float(t[i0])
            t1 = _refine(t, speed, i1, +1, thr) if i1 < len(t) - 1 else t_last
        else:
            t0 = _refine_noisy(t, qd, i0, -1, wq // 2) if i0 > 0 else float(t[i0])
            t1 = _refine_noisy(t, qd, i1, +1, wq // 2) if i1 < len(t) - 1 else t_last
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
        timeline += _motion_episodes(sig, a, b, speed)
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
                     ) -> list[MeasuredEpisode]:
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
            pieces.append(piece)
    return _merge_shivers(pieces, sig.q, t)


def _classify(sig: _Signals, s: int, e: int) -> MeasuredEpisode | None:
    """What moved between samples s and e; None when nothing moved beyond the noise."""
    t, pos, rot, q, dist, g = sig.t, sig.pos_s, sig.rot, sig.q, sig.dist, sig.g
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
            return MeasuredEpisode(kind, float(t[s]), float(t[e]), {
                "distance": float(np.linalg.norm(dp)),
                "peak_acceleration": _peak_acceleration(sig, s, e)})
        y0, x0 = rot[s][:, 1], rot[s][:, 0]
        dh = abs(_signed_angle(g[s], g[e], y0))
        dv = abs(_signed_angle(g[s], g[e], x0))
        return MeasuredEpisode("gaze", float(t[s]), float(t[e]), {
            "plane": float(dh >= dv), "swept": math.degrees(max(dh, dv))})
    roll = _roll(rot[s], rot[e])
    if abs(roll) < MIN_TILT:
        return None  # a roll below what tilt is measured to: jitter
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
