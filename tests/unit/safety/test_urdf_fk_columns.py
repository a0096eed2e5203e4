"""The replay's URDF kinematics holds its rotations by columns (``cols[k, i, n]`` is
``R_n[i, k]``) so that its products need no transposed copies; its answers are those of
the same chain evaluated with the rotations by rows (``rot[i, k, n]``, numpy's
``tensordot`` and ``matmul`` of the stack as it is), bit for bit, for every robot aou
ships, chains with a tilted axis (Rodrigues), a reversed axis and a slide, and batch
sizes whose last columns BLAS rounds through another kernel."""

from __future__ import annotations

import numpy as np
import pytest

from aou_dsl.core.robot_specs import ROBOTS
from aou_dsl.robot.load import load_arm
from aou_dsl.robot.rows import by_rows
from aou_dsl.robot.scene import urdf_path
from aou_dsl.safety.urdf_fk import Chain, _rpy, _Step, chain_fk, columns_fk, urdf_chain

SIZES = (1, 2, 3, 5, 7, 8, 9, 63, 64, 65, 700, 5487)


def _by_rows_rotations(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The chain with its rotations stacked by rows, ``(3, 3, N)``, each product numpy's
    of that stack: positions (N, 3), rotations (N, 3, 3)."""

    def mul(rot: np.ndarray, m: np.ndarray) -> np.ndarray:
        if rot.ndim == 2:
            return rot @ m
        if m.ndim == 2:
            return np.matmul(m.T, rot)
        return np.tensordot(m, rot, axes=([0], [1]))

    def turn(rot: np.ndarray, axis: np.ndarray, x: np.ndarray) -> np.ndarray:
        k = int(np.argmax(np.abs(axis)))
        if abs(axis[k]) == 1.0:
            x = x * axis[k]
            c, s = np.cos(x), np.sin(x)
            i, j = (k + 1) % 3, (k + 2) % 3
            out = rot.copy()
            out[:, i] = c * rot[:, i] + s * rot[:, j]
            out[:, j] = c * rot[:, j] - s * rot[:, i]
            return out
        u = axis
        kk = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        rk = mul(rot, kk)
        return rot + np.sin(x) * rk + (1.0 - np.cos(x)) * mul(rk, kk)

    def fk(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(q)
        rot, pos = np.eye(3), np.zeros(3)
        for s in chain.steps:
            pos = pos + mul(rot, s.pos)
            rot = mul(rot, s.rot)
            if s.col is None:
                continue
            x = q[:, s.col]
            if rot.ndim == 2:
                rot = np.repeat(rot[:, :, None], n, axis=2)
                pos = np.repeat(pos[:, None], n, axis=1)
            if s.kind == "prismatic":
                pos = pos + mul(rot, s.axis) * x
                continue
            rot = turn(rot, s.axis, x)
        if rot.ndim == 2:
            return np.tile(pos, (n, 1)), np.tile(rot, (n, 1, 1))
        return pos.T.copy(), np.ascontiguousarray(rot.transpose(2, 0, 1))

    pos, rot = by_rows(q, fk)
    return pos, rot


def _made_up_chain() -> Chain:
    """A slide, a tilted axis, a reversed coordinate axis, fixed joints in between."""
    tilt = np.array([0.3, -0.5, 0.8])
    return Chain("tip", (
        _Step(_rpy([0.1, 0.0, 0.4]), np.array([0.0, 0.0, 0.3]), "fixed", np.array([1.0, 0, 0]),
              None),
        _Step(_rpy([0.0, 0.2, 0.0]), np.array([0.1, 0.0, 0.2]), "revolute",
              tilt / np.linalg.norm(tilt), 0),
        _Step(_rpy([np.pi / 2, 0.0, 0.0]), np.array([0.0, 0.2, 0.0]), "prismatic",
              np.array([0.0, 1.0, 0.0]), 1),
        _Step(_rpy([0.0, 0.0, 0.0]), np.array([0.05, 0.0, 0.1]), "revolute",
              np.array([0.0, -1.0, 0.0]), 2),
        _Step(_rpy([-np.pi / 2, 0.3, 0.0]), np.array([0.0, 0.0, 0.1]), "fixed",
              np.array([1.0, 0, 0]), None),
    ))


def _chains() -> list[tuple[str, Chain]]:
    out = [("made-up", _made_up_chain())]
    for robot in ROBOTS:
        arm = load_arm(robot)
        path = urdf_path(robot, visuals=False, package_dirs=())[0]
        out.append((robot, urdf_chain(path, arm.spec.ee_frame, arm.joint_names)))
    return out


@pytest.mark.parametrize(("name", "chain"), _chains(), ids=lambda v: v if isinstance(v, str)
                         else "")
def test_rotations_by_columns_give_what_rotations_by_rows_give(name, chain):
    rng = np.random.default_rng(11)
    n = 1 + max((s.col for s in chain.steps if s.col is not None), default=0)
    for size in SIZES:
        q = rng.uniform(-3.0, 3.0, (size, n))
        want_pos, want_rot = _by_rows_rotations(chain, q)
        pos, rot = chain_fk(chain, q)
        assert np.array_equal(pos, want_pos) and np.array_equal(rot, want_rot), (name, size)
        pos, cols = columns_fk(chain, q[:, :])
        assert cols.shape == (3, 3, size)
        assert np.array_equal(pos, want_pos)
        assert np.array_equal(cols, want_rot.transpose(2, 1, 0)), (name, size)


def test_a_chain_without_a_moving_joint_is_its_constant_pose_at_every_row():
    chain = Chain("tip", tuple(s for s in _made_up_chain().steps if s.col is None))
    q = np.zeros((4, 3))
    pos, rot = chain_fk(chain, q)
    want_pos, want_rot = _by_rows_rotations(chain, q)
    assert np.array_equal(pos, want_pos) and np.array_equal(rot, want_rot)
