"""A compiled trajectory -> a sequence of DMP parts (:func:`to_dmp`).

One part per episode of the compiler's timeline (``Trajectory.episodes``):

- a move (approach, retreat, gaze, tilt): a ``CartesianDMP`` of the hand's pose from rest
  to rest (:mod:`.fit`);
- a hold (pause): a hold of the pose for its duration;
- an oscillation (shiver): an oscillation of the roll about the hand's forward axis, made
  by the robot's shiver joint as the compiler makes it: peak-to-peak amplitude,
  frequency, whole cycles.

Which kind becomes which is the registry of :mod:`.parts` (a plugin kind's ``dmp`` part;
a plugin kind without one is refused with K802).

Each part carries the values it shows (distance, peak acceleration, turn, duration,
amplitude); the sequence carries the descriptors measured on the whole trajectory, which
the scaling rules of a rollout start from (:mod:`.rollout`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.codes import D601
from ..core.diagnostics import AouError, Span, diag
from ..lang.primitives import PAUSE

__all__ = ["DmpPart", "DmpSequence", "to_dmp"]


@dataclass
class DmpPart:
    """One part of a sequence.

    Attributes:
        kind: the episode's kind (``approach``, ``retreat``, ``gaze``, ``tilt``, ``pause``,
            ``shiver``).
        duration: [s].
        start, end: the hand's pose at the part's ends: position [m] (3,) and quaternion
            ``(w, x, y, z)`` (4,), in the robot's base frame.
        dmp: the ``CartesianDMP`` of a motion; None for a hold or a shiver.
        values: what the part shows: ``distance`` [m], ``peak_acceleration`` [m/s^2],
            ``turn`` [deg] (rotation of the hand from start to end), ``amplitude`` [deg,
            peak to peak], ``frequency`` [Hz], ``cycles``.
        lead: for a motion, the time from the DMP's start to the episode's [s]: the DMP
            is held at rest that long before and about as long after
            (:data:`aou_dsl.dmp.fit.PAD`), so it runs ``duration + 2 lead`` in all.
    """

    kind: str
    duration: float
    start: np.ndarray
    end: np.ndarray
    dmp: Any = None
    values: dict[str, float] = field(default_factory=dict)
    lead: float = 0.0


@dataclass
class DmpSequence:
    """A behaviour as DMP parts, with what a rollout needs to make joint motion again.

    Attributes:
        robot, ee_frame, joint_names: as the source trajectory's.
        goal: the goal it was compiled for [m].
        q_start: the joint configuration at the start [rad], seeds the inverse kinematics.
        shiver_joint: the joint that shivers.
        rate: sample rate of the source [Hz].
        behaviour, state: name and state (None when unknown).
        intensity: the intensity the behaviour expresses (0.5: the study's stimulus).
        descriptors: the eleven descriptors measured on the source trajectory.
        parts: the parts, in time order.
        files: the files it was read from (:func:`aou_dsl.dmp.read_dmp`: the manifest and
            every part file), none when made in memory.
    """

    robot: str
    ee_frame: str | None
    joint_names: tuple[str, ...]
    goal: tuple[float, float, float]
    q_start: np.ndarray
    shiver_joint: str
    rate: float
    behaviour: str
    state: str | None
    intensity: float
    descriptors: dict[str, Any]
    parts: list[DmpPart]
    files: tuple[str, ...] = ()

    @property
    def duration(self) -> float:
        return float(sum(p.duration for p in self.parts))


def _span(tr: Any) -> Span:
    return Span.whole_file(tr.path)


def _shiver_values(offset: np.ndarray, duration: float) -> dict[str, float]:
    """Amplitude [deg], cycles and frequency [Hz] of a shiver's joint offset (rad)."""
    amplitude = float(offset.max() - offset.min())
    tol = 1e-3 * max(amplitude, 1e-12)
    signs = np.sign(offset[np.abs(offset) > tol])
    crossings = int(np.count_nonzero(signs[1:] != signs[:-1]))
    cycles = max(1, int(round((crossings + 1) / 2)))
    return {"amplitude": math.degrees(amplitude), "cycles": float(cycles),
            "frequency": cycles / duration}


def _move_values(pos: np.ndarray, quat: np.ndarray, acc: np.ndarray) -> dict[str, float]:
    import pytransform3d.rotations as pr

    return {"distance": float(np.linalg.norm(pos[-1] - pos[0])),
            "peak_acceleration": float(np.linalg.norm(acc, axis=1).max()),
            "turn": math.degrees(pr.quaternion_dist(quat[0], quat[-1]))}


def to_dmp(trajectory: Any, *, intensity: float = 0.5, behaviour: str | None = None,
           state: str | None = None, descriptors: dict | None = None) -> DmpSequence:
    """The DMP sequence of a compiled trajectory (see the module's docstring).

    Args:
        trajectory: an :class:`aou_dsl.core.trajectory.Trajectory` with its episodes (a
            compiled one, or one read from a trajectory file ``aouc compile`` wrote).
        intensity: the intensity it expresses, in [0, 1] (the shipped and synthesized
            files at 0.5 are the study's stimuli).
        behaviour, state: recorded in the manifest.
        descriptors: the trajectory's measured descriptors, when known (else measured).

    Raises:
        AouError: D601 when the trajectory has no episodes or no goal (a recording);
            K802 when an episode is of a plugin kind whose plugin gives no DMP part.
    """
    from ..measuring.measured import measure
    from ..robot.load import load_arm
    from .fit import fit_pose_dmp, quaternions
    from .parts import Shape, dmp_kind

    tr = trajectory
    if not tr.episodes or tr.goal is None:
        raise AouError(diag(D601, "the trajectory carries no episodes and goal of the "
                            "compiler: only a compiled trajectory can become DMPs",
                            _span(tr), hint="compile the .aou file, or give the .json "
                            "`aouc compile` wrote"))
    shapes = {kind: (entry.shape if (entry := dmp_kind(kind, _span(tr))) else None)
              for kind in dict.fromkeys(k for k, _a, _e in tr.episodes)}
    arm = load_arm(tr.robot, tr.ee_frame)
    cols = tr.columns(arm.joint_names)
    q = np.asarray(tr.q[:, cols], dtype=float)
    pos, rot = arm.fk(q)
    quat = quaternions(rot)
    qd = tr.qd[:, cols] if tr.qd is not None else np.gradient(q, tr.t, axis=0)
    qdd = tr.qdd[:, cols] if tr.qdd is not None else np.gradient(qd, tr.t, axis=0)
    acc = arm.accelerations(q, qd, qdd)
    if acc is None:
        acc = np.gradient(np.gradient(pos, tr.t, axis=0), tr.t, axis=0)
    j = arm.joint_names.index(arm.spec.shiver_joint)
    parts: list[DmpPart] = []
    for kind, a, e in tr.episodes:
        i0 = int(np.searchsorted(tr.t, a - 1e-9))
        i1 = max(i0, int(np.searchsorted(tr.t, e + 1e-9)) - 1)
        pose0 = np.concatenate([pos[i0], quat[i0]])
        pose1 = np.concatenate([pos[i1], quat[i1]])
        part = DmpPart(kind, float(e - a), pose0, pose1)
        shape = shapes[kind]
        if shape is Shape.MOVE and i1 - i0 >= 3:
            t = tr.t[i0:i1 + 1] - tr.t[i0]
            part.dmp, lead = fit_pose_dmp(t, pos[i0:i1 + 1], quat[i0:i1 + 1])
            part.lead = lead - float(tr.t[i0] - a)
            part.values = _move_values(pos[i0:i1 + 1], quat[i0:i1 + 1], acc[i0:i1 + 1])
        elif shape is Shape.OSCILLATION:
            part.end = pose0
            part.values = _shiver_values(q[i0:i1 + 1, j] - q[i0, j], part.duration)
        else:
            # a hold (or a move too short to fit) keeps the pose; a kind no DMP folder
            # holds is written as a pause
            part.kind = kind if shape in (Shape.MOVE, Shape.HOLD) else PAUSE
            part.end = pose0
        parts.append(part)
    measured = descriptors or measure(tr).descriptors.to_json()
    return DmpSequence(tr.robot, tr.ee_frame, tuple(arm.joint_names),
                       tuple(float(x) for x in tr.goal),  # type: ignore[arg-type]
                       q[0].copy(), arm.spec.shiver_joint, _rate(tr.t),
                       behaviour or tr.title or "behaviour", state, float(intensity),
                       measured, parts)


def _rate(t: np.ndarray) -> float:
    return float(round(1.0 / float(np.median(np.diff(t))), 6)) if len(t) > 1 else 250.0
