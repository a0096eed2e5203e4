"""Robot models for the numerical stages: Pinocchio models of the arm's joints.

Shared by the compiler and by ``aouc measure``; it knows only the robot (its URDF,
:mod:`aou_dsl.core.robot_specs`, a robot description), never a behaviour. The robot is loaded by
:mod:`aou_dsl.robot.load`, once per process; Pinocchio is imported there, so only the
commands that need kinematics pay for it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..core.robot_specs import DEFAULT_JOINT_JERK, RobotSpec

__all__ = ["ArmModel", "arm_model", "frame_id", "lifted"]


@dataclass(frozen=True)
class ArmModel:
    """A robot reduced to its arm joints, with the limits aou plans with.

    Attributes:
        spec: the robot's spec (a built-in arm of :data:`aou_dsl.core.robot_specs.ROBOTS`, or one
            read from a robot file).
        model: the reduced ``pinocchio.Model`` (arm joints only; grippers locked;
            continuous joints as revolute joints of one angle).
        frame_id: id of the end-effector frame in ``model``.
        lower, upper: joint position limits [rad], shape (n,).
        vmax: joint velocity limits from the URDF (or the robot file) [rad/s], shape (n,).
        amax: joint acceleration limits from the robot's spec [rad/s^2], shape (n,).
        jmax: joint jerk limits from the robot's spec [rad/s^3], shape (n,).
        effort: joint effort limits from the URDF [N m] (inf where it gives none),
            shape (n,).
        key: what the arm was made from, the content of its files included
            (:func:`~aou_dsl.robot.load.robot_key`): the key of every cache of results
            computed on the arm. An arm made by hand has none (``()``): nothing made from
            it is cached.
    """

    spec: RobotSpec
    model: Any  # pinocchio.Model (pinocchio ships no type hints)
    frame_id: int
    lower: np.ndarray
    upper: np.ndarray
    vmax: np.ndarray
    amax: np.ndarray
    effort: np.ndarray
    jmax: np.ndarray
    key: Any = field(default=(), compare=False)

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.spec.arm_joints

    @property
    def n(self) -> int:
        return len(self.spec.arm_joints)

    @property
    def plan_vmax(self) -> np.ndarray:
        """Joint velocity limits the compiler plans with [rad/s], shape (n,)."""
        return self.vmax * self.spec.velocity_scale

    @property
    def plan_amax(self) -> np.ndarray:
        """Joint acceleration limits the compiler plans with [rad/s^2], shape (n,)."""
        return self.amax * self.spec.accel_scale

    def data(self):
        return self.model.createData()

    def fk(self, q: np.ndarray, frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Forward kinematics of every row of ``q``, shape (N, n).

        Returns:
            positions, shape (N, 3) [m], and rotations, shape (N, 3, 3), of the
            end-effector frame (or ``frame``) in the base frame.
        """
        import pinocchio as pin

        fid = self.frame_id if frame is None else frame_id(self.model, frame)
        data = self.model.createData()
        q = np.atleast_2d(np.asarray(q, dtype=float))
        pos = np.empty((len(q), 3))
        rot = np.empty((len(q), 3, 3))
        for i, qi in enumerate(q):
            pin.framesForwardKinematics(self.model, data, qi)
            m = data.oMf[fid]
            pos[i] = m.translation
            rot[i] = m.rotation
        return pos, rot


    @functools.cached_property
    def _chain(self):
        return _revolute_chain(self)

    def accelerations(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
                      ) -> np.ndarray | None:
        """The end-effector's classical linear acceleration ``J qdd + Jdot qd`` [m/s^2]
        at every row of ``q``, ``qd``, ``qdd`` (N, n), in the base frame's axes, all rows
        at once with numpy; shape (N, 3). None when the arm has a joint other than a
        revolute one (:meth:`fk`'s Pinocchio is then the only way).

        The same quantity as Pinocchio's ``getFrameClassicalAcceleration`` (in
        ``LOCAL_WORLD_ALIGNED``) up to rounding: each link's angular velocity, angular
        acceleration and origin acceleration follow from its parent's, outwards along
        the chain."""
        chain = self._chain
        if chain is None:
            return None
        q, qd, qdd = _samples_last(q, qd, qdd)
        n = q.shape[1]
        # Over the rows at once, samples last: vectors (3, n); rotations by their columns,
        # (3, 3, n) with cols[k, i] row i of column k. A fixed placement is then one
        # matrix product, a joint's rotation a few operations on contiguous rows. The
        # base frame is at rest: its velocities and accelerations are None (zero).
        cols = {0: np.repeat(np.eye(3)[:, :, None], n, axis=2)}
        omega: dict[int, Any] = {0: None}
        alpha: dict[int, Any] = {0: None}
        acc: dict[int, Any] = {0: None}
        for i, (parent, iq, axis, r_fix, p_fix) in enumerate(chain[0], start=1):
            c_par, w_par, a_par = cols[parent], omega[parent], alpha[parent]
            base = (r_fix.T @ c_par.reshape(3, -1)).reshape(3, 3, n)
            z = _times(base, axis)  # the joint's axis in the base frame
            cols[i] = rotate_columns(base, axis, q[iq])
            zd, zdd = z * qd[iq], z * qdd[iq]
            if w_par is None:  # on the base: the joint's origin does not move
                acc[i], omega[i], alpha[i] = acc[parent], zd, zdd
                continue
            r = _times(c_par, p_fix)  # parent origin -> joint origin
            acc[i] = _cross(a_par, r) + _cross(w_par, _cross(w_par, r))
            if acc[parent] is not None:
                acc[i] += acc[parent]
            omega[i] = w_par + zd
            alpha[i] = a_par + zdd + _cross(w_par, zd)
        j, p_frame = chain[1]
        if omega[j] is None:  # no joint moves the frame
            return np.zeros((n, 3))
        r = _times(cols[j], p_frame)
        w = omega[j]
        out = _cross(alpha[j], r) + _cross(w, _cross(w, r))
        if acc[j] is not None:
            out += acc[j]
        return out.T


    @functools.cached_property
    def _turns(self):
        return _z_chain(self._chain)

    def acceleration_norms(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
                           ) -> np.ndarray | None:
        """``|J qdd + Jdot qd|``, the magnitude of :meth:`accelerations` [m/s^2], at every
        row, shape (N,); None when the arm has a joint other than a revolute one.

        A magnitude does not depend on the axes a vector is written in: each link's
        angular velocity ``w``, angular acceleration ``alpha`` and origin acceleration
        ``a`` are carried in the link's own axes (turned so that its joint turns about
        ``z``, :func:`_z_chain`), outwards along the chain. A joint then turns three
        vectors by a fixed matrix and by its angle, not a rotation matrix, and
        ``w x (w x p) = w (w . p) - p |w|^2``: about half the work of
        :meth:`accelerations`, equal to it up to rounding."""
        turns = self._turns
        if turns is None:
            return None
        q, qd, qdd = _samples_last(q, qd, qdd)
        n = q.shape[1]
        # Per link, (3, 3, n): w, alpha and a, each (3, n) in the link's axes; None for
        # the base (at rest).
        state: dict[int, Any] = {0: None}
        for i, (parent, iq, into, p, into_skew, into_p) in enumerate(turns[0], start=1):
            v = state[parent]
            if v is None:  # on the base: the joint's origin does not move
                out = np.zeros((3, 3, n))
            else:
                # The joint origin's a + alpha x p + w (w . p) - p |w|^2 in the parent's
                # axes, all three vectors then written in the joint's fixed axes (into).
                w = v[0]
                out = into @ v
                out[2] += into_skew @ v[1]
                out[2] += out[0] * (p @ w)
                out[2] -= np.multiply.outer(into_p, np.einsum("ij,ij->j", w, w))
                c, s = np.cos(q[iq]), np.sin(q[iq])  # and turned by the joint's angle
                x = out[:, 0].copy()
                out[:, 0] *= c
                out[:, 0] += s * out[:, 1]
                out[:, 1] *= c
                out[:, 1] -= s * x
            # The joint's own turn about z: w += z qd, alpha += z qdd + w x z qd.
            out[1, 0] += out[0, 1] * qd[iq]
            out[1, 1] -= out[0, 0] * qd[iq]
            out[1, 2] += qdd[iq]
            out[0, 2] += qd[iq]
            state[i] = out
        j, p, skew = turns[1]
        v = state[j]
        if v is None:  # no joint moves the frame
            return np.zeros(n)
        w = v[0]
        acc = v[2] + skew @ v[1] + w * (p @ w) - np.multiply.outer(p, np.einsum(
            "ij,ij->j", w, w))
        return np.sqrt(np.einsum("ij,ij->j", acc, acc))


def _samples_last(*rows: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each (N, n) array of rows as (n, N), contiguous: a joint's values over the
    samples in a row of their own."""
    return tuple(np.ascontiguousarray(np.atleast_2d(np.asarray(x, dtype=float)).T)
                 for x in rows)


def _times(cols: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R @ v`` for every sample, ``R`` by its columns (3, 3, N): (3, N)."""
    out = None
    for k in (0, 1, 2):
        if v[k]:
            term = cols[k] if v[k] == 1.0 else cols[k] * v[k]
            out = term if out is None else out + term
    return np.zeros(cols.shape[1:]) if out is None else out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of the columns of (3, N) arrays."""
    out = np.empty_like(a)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


def rotate_columns(cols: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``R @ rot(axis, angle)`` for every sample, R given by its columns ``cols``
    (3, 3, N): ``cols[k, i]`` is row i of column k, over the samples."""
    c, s = np.cos(angle), np.sin(angle)
    hit = np.flatnonzero(np.abs(axis) == 1.0)
    if len(hit) == 1:  # about a coordinate axis: two columns change
        k = int(hit[0])
        i, j = (k + 1) % 3, (k + 2) % 3
        s = s if axis[k] > 0 else -s
        out = np.empty_like(cols)
        out[k] = cols[k]
        out[i] = c * cols[i] + s * cols[j]
        out[j] = c * cols[j] - s * cols[i]
        return out
    x, y, z = axis
    skew = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    rot = (c[:, None, None] * np.eye(3) + s[:, None, None] * skew
           + (1.0 - c)[:, None, None] * np.outer(axis, axis))  # (N, 3, 3)
    return np.einsum("min,nmk->kin", cols, rot)


def _revolute_chain(arm: ArmModel):
    """Per joint of ``arm.model`` (parent, q index, unit axis, placement rotation and
    translation), and the end-effector frame's (parent joint, translation); None when
    a joint is not a revolute one of one angle."""
    model = arm.model
    joints = [_revolute(model, i) for i in range(1, model.njoints)]
    if any(j is None for j in joints):
        return None
    frame = model.frames[arm.frame_id]
    return joints, (int(frame.parentJoint), np.array(frame.placement.translation, float))



def _z_chain(chain):
    """:func:`_revolute_chain` with each link's axes turned so that its joint turns about
    ``z`` (by ``C`` with ``C z = axis``): per joint (parent, q index, ``into`` the
    matrix that writes a vector of the parent's axes in the joint's before its turn,
    the joint's origin ``p`` in the parent's axes, ``into @ skew`` where
    ``skew @ v = v x p``, ``into @ p``), and the frame's (parent joint, translation,
    skew); None with the chain."""
    if chain is None:
        return None
    joints, (fj, fp) = chain
    turn = {0: np.eye(3)}
    out = []
    for i, (parent, iq, axis, r_fix, p_fix) in enumerate(joints, start=1):
        turn[i] = c = _onto_z(axis)
        into = c.T @ r_fix.T @ turn[parent]
        p = turn[parent].T @ p_fix
        out.append((parent, iq, into, p, into @ _skew(p).T, into @ p))
    p = turn[fj].T @ fp
    return out, (fj, p, _skew(p).T)


def _onto_z(axis: np.ndarray) -> np.ndarray:
    """A rotation ``C`` with ``C @ z = axis`` (a unit vector): columns ``u``,
    ``axis x u``, ``axis`` for a unit ``u`` normal to the axis."""
    u = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
    u /= np.linalg.norm(u)
    return np.column_stack([u, np.cross(axis, u), axis])


def _skew(p: np.ndarray) -> np.ndarray:
    """The matrix of ``p x .``."""
    x, y, z = p
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _revolute(model: Any, i: int) -> tuple | None:
    """Joint ``i`` of ``model`` as (parent, q index, unit axis, placement rotation and
    translation); None for a joint other than a revolute one of one angle."""
    jm = model.joints[i]
    name = jm.shortname()
    if jm.nq != 1 or jm.nv != 1:
        return None
    if name in ("JointModelRX", "JointModelRY", "JointModelRZ"):
        axis = np.eye(3)["XYZ".index(name[-1])]
    elif name == "JointModelRevoluteUnaligned":
        axis = np.asarray(jm.extract().axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
    else:
        return None
    m = model.jointPlacements[i]
    return (int(model.parents[i]), int(jm.idx_q), axis, np.array(m.rotation, dtype=float),
            np.array(m.translation, dtype=float))


def frame_id(model: Any, name: str) -> int:
    """The id of frame ``name`` in ``model``: the link's (body) frame when a joint has the
    same name as a link; -1 when there is none."""
    import pinocchio as pin

    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    bodies = [i for i in ids if model.frames[i].type == pin.FrameType.BODY]
    return (bodies or ids or [-1])[0]


def arm_model(spec: RobotSpec, model: Any, *, no_effort: tuple[str, ...] = ()) -> ArmModel:
    """An :class:`ArmModel` of a reduced Pinocchio ``model`` whose joints are
    ``spec.arm_joints``; joints in ``no_effort`` (no effort limit in the URDF) get an
    infinite one."""
    effort = np.array(model.effortLimit, dtype=float)
    for j in no_effort:
        effort[spec.arm_joints.index(j)] = np.inf
    n = len(spec.arm_joints)
    vmax = np.array(spec.joint_velocity or model.velocityLimit, dtype=float)
    return ArmModel(
        spec=spec,
        model=model,
        frame_id=frame_id(model, spec.ee_frame),
        lower=np.array(model.lowerPositionLimit),
        upper=np.array(model.upperPositionLimit),
        vmax=vmax,
        amax=np.array(spec.joint_accel, dtype=float),
        effort=effort,
        jmax=np.array(spec.joint_jerk or (DEFAULT_JOINT_JERK,) * n, dtype=float),
    )


def lifted(arm: ArmModel, factor: float) -> ArmModel:
    """``arm`` with its velocity, acceleration and jerk limits ``factor`` times higher
    (position and effort limits as they are): the plan of a motion as declared where
    the arm's limits refuse it, for a what-if (``aouc check --track``). Its key says
    so, so that no cache gives the arm's own plan for it, nor this one for the arm."""
    return replace(arm, vmax=arm.vmax * factor, amax=arm.amax * factor,
                   jmax=arm.jmax * factor, key=(*arm.key, ("lifted", factor))
                   if arm.key else ())
