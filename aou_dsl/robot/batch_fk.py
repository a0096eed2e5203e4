"""Forward kinematics of many configurations at once, and the joint-space side of the
acceleration self-check.

Measuring evaluates the end-effector pose at every sample of a recording (60 000 samples
for a minute at 1 kHz). Pinocchio computes one configuration per call; for a serial arm
of revolute and prismatic joints the chain of transforms is evaluated here for all
samples together with numpy, which is about ten times faster. Arms with other joint
types fall back to Pinocchio, one sample at a time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.memo import Keyed, table
from .kinematics import ArmModel, rotate_columns

__all__ = ["batch_fk", "batch_fk_jacobian", "classical_acceleration", "linear_jacobian",
           "rows_fk"]

_AXES = {"X": 0, "Y": 1, "Z": 2}


def _joint_kind(joint: Any) -> tuple[str, np.ndarray] | None:
    """``("R"|"P", unit axis)`` of a one-degree-of-freedom revolute or prismatic joint."""
    name = joint.shortname()
    if joint.nq != 1 or joint.nv != 1:
        return None
    for prefix, kind in (("JointModelR", "R"), ("JointModelP", "P")):
        tail = name[len(prefix):]
        if name.startswith(prefix) and tail in _AXES:
            axis = np.zeros(3)
            axis[_AXES[tail]] = 1.0
            return kind, axis
    if name in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
        axis = np.asarray(joint.extract().axis, float)
        return ("R" if "Revolute" in name else "P"), axis / np.linalg.norm(axis)
    return None


def _chain(arm: ArmModel) -> list[tuple[int, int, str, np.ndarray, np.ndarray, np.ndarray]] | None:
    """Per joint: (parent, q index, kind, axis, fixed rotation, fixed translation); None
    when a joint type is not handled here."""
    model = arm.model
    out = []
    for i in range(1, model.njoints):
        kind = _joint_kind(model.joints[i])
        if kind is None:
            return None
        m = model.jointPlacements[i]
        # C-ordered copies: numpy's matrix product of Eigen's column-major views is slow.
        out.append((int(model.parents[i]), int(model.joints[i].idx_q), kind[0], kind[1],
                    np.ascontiguousarray(m.rotation, float),
                    np.ascontiguousarray(m.translation, float)))
    return out


def batch_fk(arm: ArmModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions (N, 3) [m] and rotations (N, 3, 3) of every row of ``q``
    (N, n), in the base frame; the same as :meth:`ArmModel.fk`."""
    q = np.atleast_2d(np.asarray(q, float))
    chain = _chain(arm)
    if chain is None:
        return arm.fk(q)
    pos, rot, _ = _chain_fk(arm, chain, q, jacobian=False)
    return pos, rot


def batch_fk_jacobian(arm: ArmModel, q: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """:func:`batch_fk` of every row of ``q`` (N, n) and the end-effector's Jacobian
    there, (N, 6, n): d(position)/dq above d(rotation)/dq (the rotation's angular
    velocity per unit joint speed), in the base frame's axes (Pinocchio's
    ``LOCAL_WORLD_ALIGNED``). None for an arm whose joints are not all revolute or
    prismatic."""
    q = np.atleast_2d(np.asarray(q, float))
    chain = _chain(arm)
    if chain is None:
        return None
    pos, rot, jac = _chain_fk(arm, chain, q, jacobian=True)
    assert jac is not None
    return pos, rot, jac


def _chain_fk(arm: ArmModel, chain: list, q: np.ndarray, jacobian: bool
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    n = len(q)
    qt = np.ascontiguousarray(q.T)
    # Rotations are kept as (3, 3, N) arrays, column by column with the samples last, so
    # that a fixed transform is one matrix product over all samples and a joint's
    # rotation is a few operations on contiguous rows.
    cols = {0: np.repeat(np.eye(3)[:, :, None], n, axis=2)}
    poss = {0: np.zeros((3, n))}

    def times(m: np.ndarray, c: np.ndarray) -> np.ndarray:  # R @ m for a fixed 3x3 m
        return (m.T @ c.reshape(3, -1)).reshape(3, 3, n)

    for i, (parent, iq, kind, axis, r_fix, p_fix) in enumerate(chain, start=1):
        c_par, p_par = cols[parent], poss[parent]
        base = times(r_fix, c_par)
        p = p_par + np.tensordot(p_fix, c_par, axes=1)
        if kind == "R":
            cols[i] = rotate_columns(base, axis, qt[iq])
            poss[i] = p
        else:
            cols[i] = base
            poss[i] = p + np.tensordot(axis, base, axes=1) * qt[iq]
    frame = arm.model.frames[arm.frame_id]
    c_j, p_j = cols[int(frame.parentJoint)], poss[int(frame.parentJoint)]
    p_f = np.ascontiguousarray(frame.placement.translation, float)
    r_f = np.ascontiguousarray(frame.placement.rotation, float)
    pos = p_j + np.tensordot(p_f, c_j, axes=1)
    rot = times(r_f, c_j).transpose(2, 1, 0)
    if not jacobian:
        return pos.T, rot, None
    # Each joint on the way to the frame: its axis in the base frame, and for a
    # revolute one the lever from its origin to the hand.
    jac = np.zeros((n, 6, q.shape[1]))
    on_path, at = set(), int(frame.parentJoint)
    while at > 0:
        on_path.add(at)
        at = int(arm.model.parents[at])
    for i, (_, iq, kind, axis, _, _) in enumerate(chain, start=1):
        if i not in on_path:
            continue
        z = np.tensordot(axis, cols[i], axes=1)  # (3, N)
        if kind == "R":
            lever = pos - poss[i]
            jac[:, 0, iq] = z[1] * lever[2] - z[2] * lever[1]
            jac[:, 1, iq] = z[2] * lever[0] - z[0] * lever[2]
            jac[:, 2, iq] = z[0] * lever[1] - z[1] * lever[0]
            jac[:, 3:, iq] = z.T
        else:
            jac[:, :3, iq] += z.T
    return pos.T, rot, jac


def rows_fk(arm: ArmModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`batch_fk` of the rows of ``q`` (N, n), each row's values those of any batch
    of two rows or more holding it (:func:`.rows.by_rows`), but for the last few rows of
    a batch (below). A build asks it twice of the same samples: its checks, then its
    measurement, whose grid holds them all but the last. The last few answers are kept
    by the arm and the samples' bytes; an ask for the first rows of a kept batch is
    answered from it (:func:`_first_rows`); every answer is given back as copies."""
    from .rows import by_rows, content_key

    q = np.asarray(q, float)
    key = (Keyed(id(arm), arm), content_key(q))
    found = _ROWS_FK.get(key)
    kept = found[1] if found is not None else _first_rows(arm, q, key)
    if kept is None:
        kept = by_rows(q, lambda rows: batch_fk(arm, rows))
    if found is None:
        _ROWS_FK.put(key, (key, kept))
    pos, rot = (np.array(x, order="K") for x in kept)
    return pos, rot


#: A batch's last rows that are computed again when a batch is answered from the first
#: rows of a kept one, and the alignment of the batch that computes them.
_TAIL, _ALIGN = 64, 64


def _first_rows(arm: ArmModel, q: np.ndarray, key: tuple) -> tuple[np.ndarray, ...] | None:
    """The answer for the rows ``q`` (keyed ``key``) when they are the first rows of a
    kept batch of the same arm (its bytes from the start, as many columns); None when
    they are not.

    A row's values do not depend on the rows beside it, except in the last few rows of a
    batch: the matrix products of :func:`batch_fk` run their last columns through
    another kernel, whose rounding can differ (seen up to three rows from the end, and
    only there). So the last :data:`_TAIL` rows are computed again, as the last rows of
    a batch of their own whose length is that of ``q`` modulo :data:`_ALIGN` (each
    column then falls where it falls in ``q``'s own product); the rows before them in
    that batch must equal the kept ones, or ``q`` is computed whole."""
    from .rows import by_rows

    arm_key, ((dtype, shape, content),) = key
    m = shape[0]
    r = 2 * _TAIL + m % _ALIGN
    if m <= r:
        return None
    for (kept_arm, ((kdtype, kshape, kcontent),)), answer in _ROWS_FK.values():
        if not (kept_arm == arm_key and kdtype == dtype and kshape[1:] == shape[1:]
                and kshape[0] > m and kcontent.data.startswith(content.data)):
            continue
        tail = by_rows(q[m - r:], lambda rows: batch_fk(arm, rows))
        if not all(np.array_equal(t[:r - _TAIL], a[m - r:m - _TAIL])
                   for t, a in zip(tail, answer, strict=True)):
            return None
        out = tuple(np.array(a[:m], order="K") for a in answer)
        for o, t in zip(out, tail, strict=True):
            o[m - _TAIL:] = t[r - _TAIL:]
        return out
    return None


#: The last answers of :func:`rows_fk`, by arm (the key holds it, so its id stays its
#: own) and samples, each with its key (for :func:`_first_rows`): a motion's 5,000
#: samples and their poses are under a megabyte.
_ROWS_FK = table("aou_dsl.robot.batch_fk.rows_fk", 4)


def linear_jacobian(arm: ArmModel, q: np.ndarray) -> np.ndarray:
    """d(end-effector position)/dq at the configuration ``q`` (n,), shape (3, n), in
    the base frame's axes."""
    import pinocchio as pin

    jac = pin.computeFrameJacobian(arm.model, arm.model.createData(), np.asarray(q, float),
                                   arm.frame_id, pin.LOCAL_WORLD_ALIGNED)
    return np.asarray(jac[:3])


def classical_acceleration(arm: ArmModel, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
                           ) -> np.ndarray:
    """The end-effector's linear acceleration ``J qdd + Jdot qd`` [m/s^2] at each row of
    ``q``, ``qd``, ``qdd`` (K, n), from Pinocchio's second-order kinematics; (K, 3)."""
    import pinocchio as pin

    data = arm.model.createData()
    out = np.empty((len(q), 3))
    for k in range(len(q)):
        pin.forwardKinematics(arm.model, data, q[k], qd[k], qdd[k])
        pin.updateFramePlacements(arm.model, data)
        out[k] = pin.getFrameClassicalAcceleration(
            arm.model, data, arm.frame_id, pin.LOCAL_WORLD_ALIGNED).linear
    return out
