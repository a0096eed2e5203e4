"""An independent geometric checker of compiled trajectories.

It reads a trajectory document (``t``, ``q``, ``joint_names``, ``robot``, ``ee_frame``,
``goal.position``), loads the robot itself with example-robot-data and Pinocchio, and
measures the eleven descriptors straight from the model's definitions:

- a pause is a run of samples with every joint still (q constant) held for >= 0.15 s;
  pauses that touch are one pause;
- the motion between two pauses is cut into episodes at instants of rest (the joint speed
  drops to ~0) and each episode is classified by what it does: the goal distance falls
  (approach), rises (retreat), the goal vector turns (gaze), the end-effector rolls about
  its forward axis (tilt; three or more fast alternating rolls make a shiver);
- a retreat counts only when it is the whole motion between two pauses;
- a plane's gaze is read at every pause that ends a gaze episode turning in that plane,
  as the angle between the
  projections of g_0 and g_i on the plane with normal y_e(0) (horizontal) or x_e(0)
  (vertical); a look back to g_0 before the pause reads 0 deg;
- tilt angle = roll change within one episode, tilt velocity = angle / duration;
- shiver amplitude = peak-to-peak range of the joint that oscillates most in the tremor;
- accelerations are second differences of the end-effector position.

Nothing here imports the compiler.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

PAUSE_MIN = 0.15  # s: a hold shorter than this is an instant of rest, not a pause
STILL_Q = 1e-9  # rad: q is exactly constant in a hold of compiled data
REST_FRACTION = 0.08  # joint speed below this share of the local peak: an instant of rest
FAST_HALF_CYCLE = 0.55  # s: a roll shorter than this, in an alternating run, is a tremor
MIN_RADIAL = 5e-4  # m
MIN_ANGLE = 0.3  # deg
LOS_TOL = 0.5  # deg

TOLERANCES = {
    # name: (absolute, relative); a value passes when within either
    "pause_duration": (0.020, 0.02),
    "retreat_distance": (0.001, 0.0),
    "horizontal_gaze": (0.5, 0.0),
    "vertical_gaze": (0.5, 0.0),
    "tilt_angle": (0.5, 0.0),
    "shiver_amplitude": (0.5, 0.0),
    "approach_acceleration": (0.0, 0.03),
    "retreat_acceleration": (0.0, 0.03),
    "tilt_velocity": (0.5, 0.02),
}


@dataclass
class Episode:
    """A piece of motion between two instants of rest, classified by what it does."""

    a: int
    b: int
    kinds: set[str]
    d_change: float
    h_change: float
    v_change: float
    roll_change: float
    duration: float
    starts_at_pause: bool = False
    ends_at_pause: bool = False
    alone: bool = False  # the only episode between its two pauses


@dataclass
class Measurement:
    """The oracle's reading of one trajectory."""

    values: dict[str, float | int | None]
    pauses: list[tuple[float, float]]
    episodes: list[Episode]
    los_max_deg: float
    problems: list[str] = field(default_factory=list)
    per_episode: dict[str, list[float]] = field(default_factory=dict)


@lru_cache(maxsize=8)
def _robot(name: str, joints: tuple[str, ...]):
    import example_robot_data
    import pinocchio as pin

    full = example_robot_data.load(name).model
    keep = set(joints)
    lock = [full.getJointId(n) for n in full.names[1:] if n not in keep]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    return model


def forward_kinematics(doc: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions (n, 3) and rotations (n, 3, 3) of every sample."""
    import pinocchio as pin

    names = tuple(doc["joint_names"])
    model = _robot(doc["robot"], names)
    data = model.createData()
    if not model.existFrame(doc["ee_frame"]):
        raise ValueError(f"the robot has no frame `{doc['ee_frame']}`")
    fid = model.getFrameId(doc["ee_frame"])
    cols = []
    for n in names:
        j = model.joints[model.getJointId(n)]
        cols.append((j.idx_q, j.nq))
    qs = np.asarray(doc["q"], dtype=float)
    ps = np.empty((len(qs), 3))
    rs = np.empty((len(qs), 3, 3))
    q = pin.neutral(model)
    for k, row in enumerate(qs):
        for (iq, nq), val in zip(cols, row, strict=True):
            if nq == 1:
                q[iq] = val
            else:  # a continuous joint stored as (cos, sin)
                q[iq], q[iq + 1] = math.cos(val), math.sin(val)
        pin.framesForwardKinematics(model, data, q)
        m = data.oMf[fid]
        ps[k] = m.translation
        rs[k] = m.rotation
    return ps, rs


def _signed_plane_angle(v0: np.ndarray, v: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Signed angle (deg) from the projection of v0 to the projections of the rows of v."""
    p0 = v0 - (v0 @ normal) * normal
    p = v - np.outer(v @ normal, normal)
    cross = np.cross(p0, p) @ normal
    dot = p @ p0
    return np.degrees(np.arctan2(cross, dot))


def measure(doc: dict[str, Any]) -> Measurement:
    """Measure the eleven descriptors of a trajectory document from its joints alone."""
    import pinocchio as pin

    t = np.asarray(doc["t"], dtype=float)
    q = np.asarray(doc["q"], dtype=float)
    problems: list[str] = []
    if len(t) < 2 or t[0] != 0.0 or np.any(np.diff(t) <= 0):
        problems.append("t does not start at 0 and increase strictly")
    if q.shape != (len(t), len(doc["joint_names"])):
        problems.append(f"q has shape {q.shape}, expected ({len(t)}, {len(doc['joint_names'])})")
        return Measurement(dict.fromkeys(_NAMES), [], [], float("nan"), problems)
    p, r = forward_kinematics(doc)
    goal = np.asarray(doc["goal"]["position"], dtype=float)
    g = goal - p
    dist = np.linalg.norm(g, axis=1)
    gu = g / dist[:, None]
    z = r[:, :, 2]
    los = np.degrees(np.arccos(np.clip(np.sum(z * gu, axis=1), -1.0, 1.0)))
    x0, y0 = r[0, :, 0], r[0, :, 1]
    hang = _signed_plane_angle(g[0], g, y0)
    vang = _signed_plane_angle(g[0], g, x0)
    # roll about the forward axis: the body angular velocity's z part, integrated
    droll = np.empty(len(t) - 1)
    for k in range(len(t) - 1):
        droll[k] = pin.log3(r[k].T @ r[k + 1])[2]
    roll = np.degrees(np.concatenate([[0.0], np.cumsum(droll)]))

    dq = np.abs(np.diff(q, axis=0))
    still = dq.max(axis=1) <= STILL_Q
    dt = np.diff(t)
    speed = dq.max(axis=1) / dt

    # pauses: runs of still intervals held >= PAUSE_MIN
    pauses: list[tuple[int, int]] = []
    k = 0
    n_int = len(dt)
    while k < n_int:
        if still[k]:
            j = k
            while j < n_int and still[j]:
                j += 1
            if t[j] - t[k] >= PAUSE_MIN - 1e-9:
                pauses.append((k, j))  # samples k..j are the hold
            k = j
        else:
            k += 1

    # motion segments between pauses: sample ranges [a, b]
    segments: list[tuple[int, int, bool, bool]] = []
    cursor, cur_pause = 0, False
    for a, b in pauses:
        if a > cursor:
            segments.append((cursor, a, cur_pause, True))
        cursor, cur_pause = b, True
    if cursor < len(t) - 1:
        segments.append((cursor, len(t) - 1, cur_pause, False))

    episodes: list[Episode] = []
    window = max(1, int(round(0.25 / float(np.median(dt)))))
    for a, b, p0, p1 in segments:
        cuts = [a]
        for j in range(a, b):
            lo, hi = max(a, j - window), min(b, j + window + 1)
            peak = speed[lo:hi].max()
            left = speed[j - 1] if j > a else math.inf
            right = speed[j + 1] if j + 1 < b else math.inf
            rest = peak > 0 and speed[j] <= REST_FRACTION * peak
            if rest and speed[j] <= left and speed[j] <= right and j > cuts[-1] + 1:
                # interval j holds the instant of rest: cut at its quieter end
                cuts.append(j if left <= right else j + 1)
        cuts.append(b)
        cuts = sorted(set(cuts))
        seg_eps = []
        for ea, eb in zip(cuts, cuts[1:], strict=False):
            if eb <= ea:
                continue
            ep = _classify(ea, eb, t, dist, gu, hang, vang, roll)
            if ep.kinds:
                seg_eps.append(ep)
        if seg_eps:
            seg_eps[0].starts_at_pause = p0
            seg_eps[-1].ends_at_pause = p1
            if len(seg_eps) == 1:
                seg_eps[0].alone = p0 and p1
        episodes.extend(seg_eps)

    _mark_shivers(episodes)
    values: dict[str, Any] = dict.fromkeys(_NAMES)
    per: dict[str, list[float]] = {}
    durations = [float(t[b] - t[a]) for a, b in pauses]
    values["pause_count"] = len(pauses)
    per["pause_duration"] = durations
    if durations:
        values["pause_duration"] = statistics.median(durations)

    acc = _accelerations(t, p)
    app = [e for e in episodes if "approach" in e.kinds]
    if app:
        values["approach_acceleration"] = max(_peak(acc, e) for e in app)
    ret = [e for e in episodes if "retreat" in e.kinds and e.alone]
    values["retreat_count"] = len(ret)
    if ret:
        per["retreat_distance"] = [float(np.linalg.norm(p[e.b] - p[e.a])) for e in ret]
        values["retreat_distance"] = statistics.median(per["retreat_distance"])
        values["retreat_acceleration"] = max(_peak(acc, e) for e in ret)

    # a plane is read at every pause that ends a gaze episode that turned in that plane
    for name, ang in (("horizontal_gaze", hang), ("vertical_gaze", vang)):
        reads = []
        for e in episodes:
            turned = float(np.abs(ang[e.a:e.b + 1] - ang[e.a]).max()) >= MIN_ANGLE
            if "gaze" in e.kinds and e.ends_at_pause and turned:
                reads.append(abs(float(ang[e.b])))
        per[name] = reads
        if reads:
            values[name] = max(reads)

    tilts = [e for e in episodes if e.kinds == {"tilt"}]
    if tilts:
        per["tilt_angle"] = [abs(e.roll_change) for e in tilts]
        per["tilt_velocity"] = [abs(e.roll_change) / e.duration for e in tilts]
        values["tilt_angle"] = statistics.median(per["tilt_angle"])
        values["tilt_velocity"] = statistics.median(per["tilt_velocity"])
    shivers = _shiver_groups(episodes)
    if shivers:
        amps = []
        for a, b in shivers:
            rng = np.degrees(q[a:b + 1].max(axis=0) - q[a:b + 1].min(axis=0))
            amps.append(float(rng.max()))
        per["shiver_amplitude"] = amps
        values["shiver_amplitude"] = max(amps)
    meas = Measurement(values, [(float(t[a]), float(t[b])) for a, b in pauses], episodes,
                       float(los.max()), problems, per)
    return meas


_NAMES = (
    "approach_acceleration", "pause_count", "pause_duration", "retreat_count",
    "retreat_distance", "retreat_acceleration", "horizontal_gaze", "vertical_gaze",
    "tilt_angle", "tilt_velocity", "shiver_amplitude",
)


def _classify(a, b, t, dist, gu, hang, vang, roll) -> Episode:
    d_change = float(dist[b] - dist[a])
    turn = math.degrees(math.acos(max(-1.0, min(1.0, float(gu[a] @ gu[b])))))
    # the largest excursion inside the episode too, so an out-and-back is not missed
    turn = max(turn, float(np.abs(hang[a:b + 1] - hang[a]).max()),
               float(np.abs(vang[a:b + 1] - vang[a]).max()))
    roll_change = float(roll[b] - roll[a])
    kinds: set[str] = set()
    if d_change <= -MIN_RADIAL:
        kinds.add("approach")
    elif d_change >= MIN_RADIAL:
        kinds.add("retreat")
    if turn >= MIN_ANGLE:
        kinds.add("gaze")
    if not kinds and abs(roll_change) >= MIN_ANGLE:
        kinds.add("roll")
    if not kinds and float(np.abs(roll[a:b + 1] - roll[a]).max()) >= MIN_ANGLE:
        kinds.add("roll")  # rolled out and back between two rests
    return Episode(a, b, kinds, d_change, float(hang[b] - hang[a]), float(vang[b] - vang[a]),
                   roll_change, float(t[b] - t[a]))


def _mark_shivers(episodes: list[Episode]) -> None:
    """Runs of >= 3 fast alternating rolls are a tremor; the other rolls are tilts."""
    i = 0
    while i < len(episodes):
        e = episodes[i]
        if e.kinds != {"roll"}:
            i += 1
            continue
        j = i + 1
        while (
            j < len(episodes)
            and episodes[j].kinds == {"roll"}
            and episodes[j].a == episodes[j - 1].b
            and episodes[j].roll_change * episodes[j - 1].roll_change < 0
        ):
            j += 1
        run = episodes[i:j]
        fast = [x for x in run if x.duration <= FAST_HALF_CYCLE]
        if len(run) >= 3 and len(fast) >= len(run) - 2:
            for x in run:
                x.kinds = {"shiver"}
        else:
            for x in run:
                x.kinds = {"tilt"}
        i = j


def _shiver_groups(episodes: list[Episode]) -> list[tuple[int, int]]:
    groups: list[tuple[int, int]] = []
    for e in episodes:
        if e.kinds != {"shiver"}:
            continue
        if groups and groups[-1][1] == e.a:
            groups[-1] = (groups[-1][0], e.b)
        else:
            groups.append((e.a, e.b))
    return groups


def _peak(acc: np.ndarray, e: Episode) -> float:
    """Peak inside an episode; its two end samples are instants of rest whose second
    difference mixes in the neighbouring episode's acceleration."""
    inner = acc[e.a + 1:e.b]
    return float(inner.max()) if len(inner) else 0.0


def _accelerations(t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """|d^2 p / dt^2| at every sample (second differences; 0 at both ends)."""
    acc = np.zeros(len(t))
    if len(t) < 3:
        return acc
    v = np.diff(p, axis=0) / np.diff(t)[:, None]
    a = 2.0 * np.diff(v, axis=0) / (t[2:] - t[:-2])[:, None]
    acc[1:-1] = np.linalg.norm(a, axis=1)
    return acc


# --------------------------------------------------------------------------------------
# comparison


@dataclass
class Disagreement:
    """One descriptor whose value differs from the expectation beyond tolerance."""

    source: str  # oracle | measured | declared | geometry
    descriptor: str
    expected: Any
    found: Any
    uncertain: str = ""

    def __str__(self) -> str:
        tag = " (uncertain: " + self.uncertain + ")" if self.uncertain else ""
        return f"{self.source}: {self.descriptor} expected {_fmt(self.expected)}, " \
            f"found {_fmt(self.found)}{tag}"


def _fmt(x: Any) -> str:
    if isinstance(x, float):
        return f"{x:.4g}"
    return repr(x)


def agrees(name: str, expected: Any, found: Any) -> bool:
    """Whether a found descriptor value equals the expected one within its tolerance."""
    if expected is None or found is None:
        return expected is None and found is None
    if name in ("pause_count", "retreat_count"):
        return int(round(float(found))) == int(expected) and float(found) == int(expected)
    abs_tol, rel_tol = TOLERANCES[name]
    err = abs(float(found) - float(expected))
    return err <= abs_tol + 1e-12 or err <= rel_tol * abs(float(expected)) + 1e-12


def compare(
    expected: dict[str, Any],
    found: dict[str, Any] | None,
    source: str,
    uncertain: dict[str, str] | None = None,
) -> list[Disagreement]:
    """Disagreements between an expectation and a set of found descriptor values."""
    uncertain = uncertain or {}
    out: list[Disagreement] = []
    if found is None:
        return [Disagreement(source, "*", "eleven descriptors", None)]
    for name in _NAMES:
        exp = expected.get(name)
        got = found.get(name)
        if name in ("pause_count", "retreat_count") and exp is None:
            exp = 0
        if name in ("pause_count", "retreat_count") and got is None:
            got = 0
        if not agrees(name, exp, got):
            out.append(Disagreement(source, name, exp, got, uncertain.get(name, "")))
    return out


def check(doc: dict[str, Any], expectation) -> tuple[list[Disagreement], Measurement]:
    """Every disagreement of a compiled document with the expectation of its source file.

    The oracle's own measurement, the document's ``descriptors.measured`` and its
    ``descriptors.declared`` are each compared with the expectation; the line of sight is
    checked at every sample.
    """
    unc = expectation.uncertain
    meas = measure(doc)
    out = compare(expectation.values, meas.values, "oracle", unc)
    desc = doc.get("descriptors") or {}
    out += compare(expectation.values, desc.get("measured"), "measured", unc)
    out += compare(expectation.values, desc.get("declared"), "declared", unc)
    for prob in meas.problems:
        out.append(Disagreement("geometry", "document", "a well-formed trajectory", prob))
    if not meas.los_max_deg <= LOS_TOL:
        out.append(Disagreement("geometry", "line_of_sight", f"<= {LOS_TOL} deg",
                                round(meas.los_max_deg, 3)))
    return out, meas
