"""Synthetic joint trajectories with analytically known descriptors, built without the
compiler: Cartesian time laws written out here, turned into joints by a small Newton IK
on Pinocchio. `aouc measure` must recover what these functions put in."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.robot.load import load_arm

RATE = 250.0


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    return pin.exp3(np.asarray(axis, float) * angle)


@dataclass
class Synth:
    """Builds a trajectory piece by piece; every piece starts and ends at rest.

    The end-effector starts ``d`` metres from ``goal`` along ``u`` and looks at the goal.
    ``state`` tracks distance, horizontal bearing (about ``y0``), roll; ``t`` the clock.
    """

    robot: str = "panda"
    d: float = 0.30
    u: tuple = (-0.6, 0.0, 0.8)
    goal: tuple = (0.55, 0.0, 0.25)
    rate: float = RATE
    poses: list = field(default_factory=list)  # (p, R) per sample, or ("q", offset)
    joint_offsets: list = field(default_factory=list)

    def __post_init__(self):
        self.arm = load_arm(self.robot)
        u = np.asarray(self.u, float)
        self.uu = u / np.linalg.norm(u)
        z0 = -self.uu
        up = np.array([0.0, 0.0, 1.0])
        y0 = up - (up @ z0) * z0
        y0 /= np.linalg.norm(y0)
        self.R0 = np.column_stack([np.cross(y0, z0), y0, z0])
        self.h = 0.0
        self.roll = 0.0
        self.poses = []
        self.joint_offsets = []
        self._add(self._pose())

    def _pose(self) -> tuple[np.ndarray, np.ndarray]:
        y0 = self.R0[:, 1]
        b = _rot(y0, self.h)
        p = np.asarray(self.goal) + self.d * (b @ self.uu)
        r = b @ self.R0 @ _rot([0, 0, 1], self.roll)
        return p, r

    def _add(self, pose, offset: float = 0.0) -> None:
        self.poses.append(pose)
        self.joint_offsets.append(offset)

    @staticmethod
    def _bang(length: float, a: float, rate: float) -> np.ndarray:
        """Positions along a rest-to-rest bang-bang law with peak acceleration ``a``,
        sampled at ``rate`` after the start (the start itself excluded)."""
        length = abs(length)
        half = math.sqrt(length / a)
        t = np.arange(1, int(math.ceil(2 * half * rate)) + 1) / rate
        t = np.minimum(t, 2 * half)
        return np.where(t < half, 0.5 * a * t * t, length - 0.5 * a * (2 * half - t) ** 2)

    def hold(self, seconds: float) -> Synth:
        for _ in range(int(round(seconds * self.rate))):
            self._add(self._pose())
        return self

    def _move(self, coordinate: str, delta: float, a: float) -> Synth:
        """Change ``coordinate`` (d, h or roll) by ``delta`` rest to rest, bang-bang with
        peak acceleration ``a``; everything else stays."""
        start = getattr(self, coordinate)
        for s in self._bang(delta, a, self.rate):
            setattr(self, coordinate, start + math.copysign(s, delta))
            self._add(self._pose())
        setattr(self, coordinate, start + delta)
        return self

    def line(self, delta: float, a: float) -> Synth:
        """Move along the line of sight: ``delta`` < 0 approaches, > 0 retreats [m]."""
        return self._move("d", delta, a)

    def arc(self, delta: float, alpha: float) -> Synth:
        """Horizontal gaze: turn the bearing by ``delta`` [rad], angular acceleration
        ``alpha``; the distance stays and the gaze stays on the goal."""
        return self._move("h", delta, alpha)

    def tilt(self, delta: float, alpha: float) -> Synth:
        """Roll about the forward axis by ``delta`` [rad]."""
        return self._move("roll", delta, alpha)

    def shiver(self, amplitude: float, f: float, cycles: int) -> Synth:
        """The last joint oscillates ``amplitude`` [rad] peak to peak (sin^2 envelope over
        the first and last cycle, so it starts and ends at rest)."""
        duration = cycles / f
        t = np.arange(1, int(round(duration * self.rate)) + 1) / self.rate
        edge = np.minimum(t, duration - t)
        env = np.where(edge < 1 / f, np.sin(math.pi * f * edge / 2) ** 2, 1.0)
        for x in amplitude / 2 * np.sin(2 * math.pi * f * t) * env:
            self._add(self._pose(), float(x))
        return self

    def recording(self, noise: float = 0.0, seed: int = 0) -> Trajectory:
        q = self._ik()
        q[:, -1] += np.asarray(self.joint_offsets)
        if noise:
            q = q + np.random.default_rng(seed).normal(0.0, noise, q.shape)
        t = np.arange(len(q)) / self.rate
        return Trajectory(t, q, self.arm.joint_names, self.robot, None, tuple(self.goal))

    def _ik(self) -> np.ndarray:
        model, data, fid = self.arm.model, self.arm.model.createData(), self.arm.frame_id
        q = np.array(self.arm.spec.posture, float)
        out = np.empty((len(self.poses), model.nq))
        cache = {}
        for i, (p, r) in enumerate(self.poses):
            key = (p.tobytes(), r.tobytes())
            if key in cache:
                out[i] = q = cache[key]
                continue
            target = pin.SE3(r, p)
            for _ in range(200 if i == 0 else 20):
                pin.framesForwardKinematics(model, data, q)
                dm = data.oMf[fid].actInv(target)
                err = pin.log6(dm).vector
                if np.linalg.norm(err) < 1e-10:
                    break
                j = -pin.Jlog6(dm.inverse()) @ pin.computeFrameJacobian(
                    model, data, q, fid, pin.LOCAL)
                dq = -np.linalg.pinv(j) @ err
                q = q + np.clip(dq, -0.1, 0.1)
            cache[key] = q.copy()
            out[i] = q
        return out
