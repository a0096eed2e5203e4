"""A recording simulator: turns a compiled trajectory into what a real arm's logger writes.

``aouc measure`` must read recordings of real arms, not only the compiler's own clean
output. This module imitates the way from a compiled trajectory to a log file:

1. :func:`dynamic_replay`: the arm itself. The robot's URDF is loaded in pybullet (gravity
   on) and follows the trajectory's ``q``/``qd`` under position control with the URDF's
   effort limits, so the recorded motion carries the arm's own tracking lag and
   smoothing. The result is the arm's joint positions at the physics rate.
2. :class:`Logger`: how the state is sampled and written: rate, timing jitter with
   occasional long gaps, dropped samples, encoder noise on the joints that move,
   quantisation (encoder resolution or a fixed number of decimals), a log that starts
   mid-motion, extra constant columns (finger joints), shuffled columns, continuous
   joints wrapped into [-pi, pi), and wrong units (ms, deg) for broken exports.
3. :func:`record` samples the arm's signal at the logger's timestamps with a cubic
   Hermite interpolation (positions and velocities, so the motion stays smooth), and
   :func:`to_csv_text` / :func:`to_json_doc` write the result as a CSV (``t`` then one
   column per joint) or as a document of the trajectory format.

Every random draw comes from a seeded generator, one independent stream per effect, so
changing the noise does not move the timestamps and a seed reproduces a log exactly.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np

__all__ = [
    "PRESETS",
    "URDF_PATHS",
    "NOISE_LEVELS",
    "Logger",
    "UrdfJoint",
    "dynamic_replay",
    "noisy",
    "record",
    "to_csv_text",
    "to_json_doc",
    "urdf_joints",
    "urdf_path",
]

#: example-robot-data URDF of each robot name, relative to its robots folder.
URDF_PATHS: dict[str, str] = {
    "panda": "panda_description/urdf/panda.urdf",
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
}

GRAVITY = 9.81  # [m/s^2]


# --- the robot's URDF ------------------------------------------------------------------------


def urdf_path(robot: str) -> str:
    """Absolute path of the robot's URDF (a robot name of :data:`URDF_PATHS`, or a path)."""
    if robot.endswith(".urdf") and os.path.exists(robot):
        return os.path.abspath(robot)
    import example_robot_data as erd

    rel = URDF_PATHS.get(robot)
    if rel is None:
        raise ValueError(f"no URDF known for robot `{robot}`; known: {', '.join(URDF_PATHS)}")
    return os.path.normpath(os.path.join(erd.getModelPath(rel), rel))


@dataclass(frozen=True)
class UrdfJoint:
    """A non-fixed joint of a URDF: type, position limits [rad or m] and effort limit
    [N m or N]. A continuous joint has infinite limits."""

    name: str
    type: str
    lower: float
    upper: float
    effort: float

    @property
    def wraps(self) -> bool:
        """A joint that turns without end (continuous, or limits a full turn or more apart):
        loggers often report it wrapped into [-pi, pi)."""
        return self.type == "continuous" or (
            self.type == "revolute" and self.upper - self.lower >= 2 * math.pi - 1e-9)


@lru_cache(maxsize=16)
def urdf_joints(robot: str) -> dict[str, UrdfJoint]:
    """The non-fixed joints of the robot's URDF, by name."""
    root = ET.parse(urdf_path(robot)).getroot()
    out: dict[str, UrdfJoint] = {}
    for j in root.iter("joint"):
        kind = j.get("type", "fixed")
        if kind in ("fixed", "floating", "planar"):
            continue
        lim = j.find("limit")
        lo = float(lim.get("lower", "-inf")) if lim is not None else -math.inf
        hi = float(lim.get("upper", "inf")) if lim is not None else math.inf
        if kind == "continuous":
            lo, hi = -math.inf, math.inf
        effort = float(lim.get("effort", "inf")) if lim is not None else math.inf
        out[j.get("name", "")] = UrdfJoint(j.get("name", ""), kind, lo, hi, effort)
    return out


@contextmanager
def _quiet():
    """Silence what C code prints on stdout and stderr (pybullet's banner and warnings)."""
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


# --- 1. the arm: dynamic replay -----------------------------------------------------------------


def _doc_arrays(doc: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``t`` [s] (N,), ``q`` (N, J) and ``qd`` (N, J) of a trajectory document; ``qd`` by
    central differences when the document has none."""
    t = np.asarray(doc["t"], float)
    q = np.asarray(doc["q"], float)
    qd = np.asarray(doc["qd"], float) if doc.get("qd") is not None else np.gradient(q, t, axis=0)
    return t, q, qd


def dynamic_replay(doc: dict, *, physics_rate: float = 1000.0, position_gain: float = 0.05,
                   velocity_gain: float = 0.3, command_delay: float = 0.004,
                   settle: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """The arm's actual joint positions while it follows ``doc`` under position control.

    The robot's URDF is loaded in pybullet (DIRECT mode, fixed base, gravity on). The arm
    starts at rest at ``q[0]``; at every physics step the motors of the document's joints
    get the reference position and velocity (a cubic Hermite interpolation of the
    document's ``q``/``qd``, ``command_delay`` seconds old) under ``POSITION_CONTROL``,
    each with its URDF effort limit as the maximum force. Other non-fixed joints (fingers)
    are held at their initial position. The tracking error this leaves (the command's
    delay, the soft gains' following error, sag under gravity) is the arm's own: with the
    defaults, well under a milliradian plus ``command_delay`` times the joint speed.

    Args:
        doc: a document of the trajectory format (``robot``, ``joint_names``, ``t`` [s]
            shape (N,), ``q`` [rad or m] shape (N, J), optionally ``qd`` shape (N, J)).
        physics_rate: physics steps per second [Hz]; also the rate of the result.
        position_gain, velocity_gain: pybullet's motor gains (``positionGains``,
            ``velocityGains``); the defaults are soft enough that gravity visibly sags.
        command_delay: age of the command when the motors act on it [s] (transport and
            interpolation of a real controller).
        settle: seconds the arm holds ``q[0]`` before the trajectory starts, so that it
            has sagged into its steady state when the motion begins (not returned).

    Returns:
        ``(t, q)``: times [s] from 0 to the document's duration at ``1/physics_rate``,
        shape (M,); actual joint positions [rad or m] in the document's column order,
        shape (M, J).
    """
    from scipy.interpolate import CubicHermiteSpline

    with _quiet():
        import pybullet as pb

    t_ref, q_ref, qd_ref = _doc_arrays(doc)
    names = list(doc["joint_names"])
    path = urdf_path(doc["robot"])
    # URDFs name meshes `package://<pkg>/...`; the folder holding the packages resolves them.
    robots_dir = os.path.dirname(os.path.dirname(os.path.dirname(path)))
    limits = urdf_joints(doc["robot"])
    dt = 1.0 / physics_rate
    n = int(math.floor((t_ref[-1] - t_ref[0]) * physics_rate + 1e-9)) + 1
    t = t_ref[0] + np.arange(n) * dt
    ref = CubicHermiteSpline(t_ref, q_ref, qd_ref, axis=0)
    vref = ref.derivative()
    tc = np.clip(t - command_delay, t_ref[0], t_ref[-1])
    targets, vtargets = ref(tc), vref(tc)

    with _quiet():
        cid = pb.connect(pb.DIRECT)
    try:
        pb.setAdditionalSearchPath(robots_dir, physicsClientId=cid)
        pb.setGravity(0, 0, -GRAVITY, physicsClientId=cid)
        pb.setTimeStep(dt, physicsClientId=cid)
        with _quiet():
            body = pb.loadURDF(path, useFixedBase=True, physicsClientId=cid)
        index: dict[str, int] = {}
        for i in range(pb.getNumJoints(body, physicsClientId=cid)):
            info = pb.getJointInfo(body, i, physicsClientId=cid)
            if info[2] != pb.JOINT_FIXED:
                index[info[1].decode()] = i
        missing = [nm for nm in names if nm not in index]
        if missing:
            raise ValueError(f"robot `{doc['robot']}` has no joint(s) {missing}")
        arm = [index[nm] for nm in names]
        others = [i for nm, i in index.items() if nm not in names]
        forces = [limits[nm].effort for nm in names]
        for i, nm in enumerate(names):
            pb.resetJointState(body, index[nm], float(q_ref[0, i]), 0.0, physicsClientId=cid)
        if others:
            held = [pb.getJointState(body, i, physicsClientId=cid)[0] for i in others]
            pb.setJointMotorControlArray(body, others, pb.POSITION_CONTROL,
                                         targetPositions=held, physicsClientId=cid)
        kps, kds = [position_gain] * len(arm), [velocity_gain] * len(arm)
        for _ in range(int(round(settle * physics_rate))):
            pb.setJointMotorControlArray(body, arm, pb.POSITION_CONTROL,
                                         targetPositions=q_ref[0].tolist(),
                                         targetVelocities=[0.0] * len(arm), forces=forces,
                                         positionGains=kps, velocityGains=kds,
                                         physicsClientId=cid)
            pb.stepSimulation(physicsClientId=cid)
        out = np.empty((n, len(arm)))
        for k in range(n):
            states = pb.getJointStates(body, arm, physicsClientId=cid)
            out[k] = [s[0] for s in states]
            pb.setJointMotorControlArray(body, arm, pb.POSITION_CONTROL,
                                         targetPositions=targets[k].tolist(),
                                         targetVelocities=vtargets[k].tolist(), forces=forces,
                                         positionGains=kps, velocityGains=kds,
                                         physicsClientId=cid)
            pb.stepSimulation(physicsClientId=cid)
    finally:
        pb.disconnect(physicsClientId=cid)
    return t - t[0], out


# --- 2. the logger ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Logger:
    """How a logger samples and writes the arm's joint state.

    Attributes:
        rate: nominal sample rate [Hz]; the nominal period is ``P = 1/rate`` [s].
        jitter: standard deviation of each sampling step as a fraction of ``P``
            (step = ``P * (1 + jitter * N(0, 1))``, never under ``min_step``).
        gap_probability: chance per step of a long gap instead (a stalled logger), drawn
            uniformly in [3 P, ``max_gap``].
        max_gap: longest gap [s].
        min_step: shortest step between two timestamps [s].
        drop: probability that a sample is lost (its row is missing from the log).
        noise: encoder noise std [rad or m], one value for every joint or one per joint of
            the document. Only joints that move beyond it get noise; a joint that never
            moves reads the same value to the last bit.
        quantum: encoder resolution [rad or m]: positions are rounded to multiples of it
            (0: none). Applied after the noise.
        decimals: positions rounded to this many decimals and written with exactly this
            many (None: full precision). Applied after ``quantum``, in the written unit.
        start: seconds of the motion cut from the beginning: the log starts mid-motion.
        stop: seconds cut from the end.
        extra: constant extra columns, ``(name, value)`` pairs (finger joints).
        shuffle: write the columns in a random order (extra columns mixed in).
        wrap: report joints that turn without end (continuous, or limits a full turn
            apart) wrapped into [-pi, pi).
        time_unit: ``"s"`` or ``"ms"`` (a wrong export when a reader expects seconds).
        angle_unit: ``"rad"`` or ``"deg"`` for revolute and continuous joints.
        t_origin: the first timestamp [s] (0: the log's clock starts at 0; a wall-clock
            epoch such as 1.7e9 imitates ROS stamps).
        seed: seed of every random draw.
    """

    rate: float = 1000.0
    jitter: float = 0.0
    gap_probability: float = 0.0
    max_gap: float = 0.0
    min_step: float = 4e-5
    drop: float = 0.0
    noise: float | tuple[float, ...] = 0.0
    quantum: float = 0.0
    decimals: int | None = None
    start: float = 0.0
    stop: float = 0.0
    extra: tuple[tuple[str, float], ...] = ()
    shuffle: bool = False
    wrap: bool = False
    time_unit: str = "s"
    angle_unit: str = "rad"
    t_origin: float = 0.0
    seed: int = 0

    def with_(self, **changes: Any) -> Logger:
        """A copy with some options changed."""
        return replace(self, **changes)


#: Logger settings imitating common ways of recording an arm.
PRESETS: dict[str, Logger] = {
    # Franka Control Interface (libfranka) robot state at its 1 kHz real-time loop: a very
    # regular clock, rare lost UDP packets, link-side encoder noise of a few 1e-5 rad, the
    # q of `franka::RobotState` written at full double precision, gripper width logged
    # beside the arm.
    "franka_fci": Logger(rate=1000.0, jitter=0.01, gap_probability=2e-4, max_gap=0.005,
                         drop=1e-3, noise=3e-5, extra=(("panda_finger_joint1", 0.04),
                                                       ("panda_finger_joint2", 0.04)),
                         seed=1),
    # Universal Robots RTDE `actual_q` at 500 Hz (e-Series): steady clock, a few missed
    # packets, encoder resolution 2.6e-7 rad (about 2 pi / 2^24.5), small noise.
    "ur_rtde": Logger(rate=500.0, jitter=0.02, gap_probability=5e-4, max_gap=0.01,
                      drop=2e-3, noise=2e-5, quantum=2.6e-7, seed=2),
    # A rosbag of /joint_states turned into a CSV: bursty delivery (median step 1.75 ms,
    # from 0.04 ms to 16.7 ms), lost messages, 1e-4 rad noise, fingers in the message,
    # columns in the message's own order, continuous joints wrapped, and a recording
    # started after the arm was already moving.
    "ros_joint_states": Logger(rate=1.0 / 0.00175, jitter=0.35, gap_probability=2e-3,
                               max_gap=0.0167, min_step=4e-5, drop=0.01, noise=1e-4,
                               start=0.5, extra=(("panda_finger_joint1", 0.04),
                                                 ("panda_finger_joint2", 0.04)),
                               shuffle=True, wrap=True, seed=3),
    # The plainest export: a uniform 250 Hz clock and q printed with 6 decimals, no noise.
    # Six decimals at 250 Hz put 1e-6 rad steps into accelerations of ~0.06 rad/s^2.
    "csv_6_decimals_250hz": Logger(rate=250.0, decimals=6, seed=4),
    # A demonstration recorded by hand-guiding or teleoperation through a GUI recorder:
    # 100 Hz with a loose clock, larger noise (2e-4 rad), 5 decimals, started late.
    "teleop_guided": Logger(rate=100.0, jitter=0.1, gap_probability=5e-3, max_gap=0.05,
                            drop=0.005, noise=2e-4, decimals=5, start=0.3, seed=5),
}


#: Encoder noise levels [rad] that measuring is tested under: from a good encoder read
#: over a fieldbus to a cheap one over a noisy bus.
NOISE_LEVELS = (1e-4, 3e-4, 6e-4, 1e-3)


def noisy(noise: float, rate: float, seed: int = 0) -> Logger:
    """A logger at ``rate`` [Hz] with ``noise`` [rad] of encoder noise, a 5 % jittered
    clock, 0.5 % dropped samples and a 24-bit encoder's resolution (2.6e-7 rad)."""
    return Logger(rate=rate, jitter=0.05, drop=0.005, noise=noise, quantum=2.6e-7, seed=seed)


def _timestamps(logger: Logger, duration: float, rng: np.random.Generator) -> np.ndarray:
    """Sampling instants [s] in [0, duration], shape (K,): jittered steps with gaps."""
    period = 1.0 / logger.rate
    n = int(duration / period * 1.2) + 16
    out: list[np.ndarray] = []
    t0 = float(rng.uniform(0.0, period))  # the logger's phase relative to the motion
    total = t0
    while total <= duration:
        steps = period * (1.0 + logger.jitter * rng.standard_normal(n))
        steps = np.maximum(steps, logger.min_step)
        if logger.gap_probability > 0 and logger.max_gap > 3 * period:
            gaps = rng.random(n) < logger.gap_probability
            steps[gaps] = rng.uniform(3 * period, logger.max_gap, int(gaps.sum()))
        times = total + np.concatenate([[0.0], np.cumsum(steps[:-1])])
        out.append(times)
        total = float(times[-1] + steps[-1])
    t = np.concatenate(out)
    return t[t <= duration]


def _signal(doc: dict, dynamic: bool, physics_rate: float):
    """The arm's motion as a cubic Hermite spline of time [s] -> joint positions (J,)."""
    from scipy.interpolate import CubicHermiteSpline

    if not dynamic:
        t, q, qd = _doc_arrays(doc)
        return CubicHermiteSpline(t - t[0], q, qd, axis=0)
    t, q = dynamic_replay(doc, physics_rate=physics_rate)
    # Velocities of the physics signal by central differences: the spline then passes
    # through every physics sample with a continuous slope.
    return CubicHermiteSpline(t, q, np.gradient(q, t, axis=0), axis=0)


def record(doc: dict, logger: Logger, *, dynamic: bool = True, physics_rate: float = 1000.0,
           signal=None) -> dict:
    """What ``logger`` writes while the arm performs ``doc``.

    Args:
        doc: a document of the trajectory format.
        logger: the logger's settings.
        dynamic: replay the motion on the simulated arm first (:func:`dynamic_replay`);
            False samples the document's own motion (its ``q``/``qd``, Hermite-interpolated).
        physics_rate: physics rate of the dynamic replay [Hz].
        signal: a precomputed spline ``t -> q`` (as made for ``dynamic``), to log the same
            arm motion with several loggers without replaying it again.

    Returns:
        A dict with ``t`` (K,) in ``time_unit`` starting at ``t_origin``; ``q`` (K, C) in
        ``angle_unit`` (C = J + extra columns, in ``joint_names`` order); ``joint_names``;
        ``robot``, ``ee_frame``, ``goal`` (``{"position": [x, y, z]}``), ``behaviour``,
        ``state`` from the document; ``time_unit``, ``angle_unit``, ``decimals``; and for
        tests ``t_true`` (K,) [s], the instants on the document's clock, and ``q_true``
        (K, J) [rad or m], the arm's positions there before noise, quantisation and units.
    """
    if signal is None:
        signal = _signal(doc, dynamic, physics_rate)
    ss = np.random.SeedSequence(logger.seed)
    r_time, r_drop, r_noise, r_cols = (np.random.default_rng(s) for s in ss.spawn(4))
    t_doc = np.asarray(doc["t"], float)
    duration = float(t_doc[-1] - t_doc[0])
    span = duration - logger.start - logger.stop
    if span <= 0:
        raise ValueError(f"start + stop cut {logger.start + logger.stop}s of {duration}s")
    t_true = logger.start + _timestamps(logger, span, r_time)
    keep = r_drop.random(len(t_true)) >= logger.drop
    keep[0] = True
    t_true = t_true[keep]
    q_true = np.asarray(signal(t_true))
    names = list(doc["joint_names"])
    q = q_true.copy()

    noise = np.broadcast_to(np.asarray(logger.noise, float), (len(names),))
    floor = max(float(noise.max()), logger.quantum, 1e-6 if logger.decimals is None
                else 10.0 ** -logger.decimals)
    moving = np.ptp(q_true, axis=0) > floor
    q += r_noise.standard_normal(q.shape) * np.where(moving, noise, 0.0)
    # A joint that does not move reads one value throughout (its first reading).
    q[:, ~moving] = q_true[0, ~moving]
    if logger.quantum > 0:
        q = np.round(q / logger.quantum) * logger.quantum

    joints = urdf_joints(doc["robot"])
    angular = np.array([joints[n].type in ("revolute", "continuous") if n in joints else True
                        for n in names])
    if logger.wrap:
        wraps = np.array([n in joints and joints[n].wraps for n in names])
        w = q[:, wraps]
        # Values already in [-pi, pi) keep their exact bits.
        q[:, wraps] = np.where((w >= -math.pi) & (w < math.pi), w,
                               (w + math.pi) % (2 * math.pi) - math.pi)
    if logger.angle_unit == "deg":
        q[:, angular] = np.degrees(q[:, angular])
    elif logger.angle_unit != "rad":
        raise ValueError(f"angle unit must be `rad` or `deg`, found `{logger.angle_unit}`")
    if logger.decimals is not None:
        q = np.round(q, logger.decimals)

    if logger.extra:
        names += [n for n, _ in logger.extra]
        q = np.hstack([q, np.tile([v for _, v in logger.extra], (len(q), 1))])
    if logger.shuffle:
        order = r_cols.permutation(len(names))
        names = [names[i] for i in order]
        q = q[:, order]

    t = logger.t_origin + (t_true - t_true[0])
    if logger.time_unit == "ms":
        t = t * 1000.0
    elif logger.time_unit != "s":
        raise ValueError(f"time unit must be `s` or `ms`, found `{logger.time_unit}`")
    return {
        "t": t, "q": q, "joint_names": names, "robot": doc["robot"],
        "ee_frame": doc.get("ee_frame"), "goal": doc.get("goal"),
        "behaviour": doc.get("behaviour"), "state": doc.get("state"),
        "time_unit": logger.time_unit, "angle_unit": logger.angle_unit,
        "decimals": logger.decimals, "t_true": t_true, "q_true": q_true,
    }


# --- 3. writers -------------------------------------------------------------------------------


def _fmt(decimals: int | None):
    if decimals is None:
        return repr
    return lambda v: f"{v:.{decimals}f}"


def to_csv_text(rec: dict) -> str:
    """The recording as CSV text: a header ``t,<joint names>`` and one row per sample.

    Times are written at full precision; positions at full precision, or with exactly
    the logger's ``decimals``.
    """
    fq = _fmt(rec.get("decimals"))
    lines = [",".join(["t", *rec["joint_names"]])]
    for ti, row in zip(np.asarray(rec["t"]).tolist(), np.asarray(rec["q"]).tolist(),
                       strict=True):
        lines.append(",".join([repr(ti), *(fq(v) for v in row)]))
    return "\n".join(lines) + "\n"


def to_json_doc(rec: dict, *, with_goal: bool = True) -> dict:
    """The recording as a document of the trajectory format (format ``aou-trajectory/1``).

    It holds what a recording has: ``t`` (K,), ``q`` (K, C), the joint names, robot,
    end-effector frame and, when ``with_goal``, the goal. No ``qd``/``qdd`` (a logger
    writes positions) and no descriptors.
    """
    decimals = rec.get("decimals")
    q = np.asarray(rec["q"])
    doc: dict[str, Any] = {
        "format": "aou-trajectory/1",
        "behaviour": rec.get("behaviour"),
        "state": rec.get("state"),
        "robot": rec["robot"],
        "ee_frame": rec.get("ee_frame"),
        "joint_names": list(rec["joint_names"]),
        "t": np.asarray(rec["t"]).tolist(),
        "q": (np.round(q, decimals) if decimals is not None else q).tolist(),
    }
    if with_goal and rec.get("goal") is not None:
        doc["goal"] = rec["goal"]
    return doc
