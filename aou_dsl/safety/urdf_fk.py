"""The replay's own forward kinematics: the robot's URDF read directly and evaluated for
every sample at once with numpy.

It shares nothing with the compiler's kinematics (Pinocchio), so comparing the two at
every sample checks the compiler's robot model; the replay compares it in turn with
PyBullet's link poses wherever PyBullet is put in a configuration.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ..core.codes import R402
from ..core.diagnostics import AouError, Span, diag
from ..core.memo import cached, file_digest

__all__ = ["Chain", "chain_fk", "columns_fk", "urdf_chain"]


@dataclass(frozen=True)
class _Step:
    """One joint of the chain: its constant origin, then its motion (``col`` is the
    column of ``q`` that drives it, None for a joint held at zero or fixed)."""

    rot: np.ndarray  # (3, 3) origin rotation in the parent frame
    pos: np.ndarray  # (3,) origin position in the parent frame
    kind: str  # "revolute" (continuous too), "prismatic" or "fixed"
    axis: np.ndarray  # (3,) unit axis in the joint frame
    col: int | None


@dataclass(frozen=True)
class Chain:
    """The joints from the URDF's root link to one link, in order."""

    link: str
    steps: tuple[_Step, ...]


def _rpy(rpy: list[float]) -> np.ndarray:
    """URDF fixed-axis roll, pitch, yaw -> rotation matrix (Rz(yaw) Ry(pitch) Rx(roll))."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _floats(text: str | None, default: str) -> list[float]:
    return [float(v) for v in (text or default).split()]


@cached(maxsize=16)
def _model(urdf: str, digest: str) -> tuple[frozenset[str], dict[str, tuple[str, ET.Element]]]:
    """The link names, and ``link:<child>`` and ``joint:<name>`` -> (joint name, joint
    element)."""
    root = ET.parse(urdf).getroot()
    joints: dict[str, tuple[str, ET.Element]] = {}
    for j in root.iter("joint"):
        child = j.find("child")
        if child is None or j.get("name") is None:
            continue
        joints["link:" + child.get("link", "")] = (j.get("name", ""), j)
        joints["joint:" + j.get("name", "")] = (j.get("name", ""), j)
    return frozenset(el.get("name", "") for el in root.iter("link")), joints


def urdf_chain(urdf: str, frame: str, columns: tuple[str, ...]) -> Chain:
    """The chain from the root to ``frame`` (a link, or a joint: its child link).
    Joints named in ``columns`` move with their column; other joints stay at zero.
    Made once per file (its content), frame and columns (a replay asks for it every
    time).

    Raises:
        AouError: R402 when the URDF has no such link or joint.
    """
    return _chain(urdf, file_digest(urdf), frame, columns)


@cached(maxsize=64)
def _chain(urdf: str, digest: str, frame: str, columns: tuple[str, ...]) -> Chain:
    links, joints = _model(urdf, digest)
    link = frame
    if frame not in links and "joint:" + frame in joints:  # a link's name wins, as in Pinocchio
        link = joints["joint:" + frame][1].find("child").get("link", "")  # type: ignore[union-attr]
    if link not in links:
        raise AouError(diag(R402, f"the robot file has no link or joint `{frame}`",
                            Span.whole_file(urdf)))
    steps = []
    current = link
    while "link:" + current in joints:
        name, j = joints["link:" + current]
        origin = j.find("origin")
        xyz = _floats(origin.get("xyz") if origin is not None else None, "0 0 0")
        rpy = _floats(origin.get("rpy") if origin is not None else None, "0 0 0")
        axis_el = j.find("axis")
        axis = np.array(_floats(axis_el.get("xyz") if axis_el is not None else None, "1 0 0"))
        kind = j.get("type", "fixed")
        kind = "revolute" if kind == "continuous" else kind
        if kind not in ("revolute", "prismatic"):
            kind = "fixed"
        col = columns.index(name) if name in columns and kind != "fixed" else None
        norm = float(np.linalg.norm(axis))
        steps.append(_Step(_rpy(rpy), np.array(xyz), kind, axis / norm if norm else axis, col))
        current = j.find("parent").get("link", "")  # type: ignore[union-attr]
    return Chain(link, tuple(reversed(steps)))


def _skew(u: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


# A stack of rotations is held by columns: ``cols[k, i, n]`` is ``R_n[i, k]``, so that
# ``cols[k]``, column k of every rotation, is one contiguous block. The products make the
# very BLAS calls numpy made when the stack was held by rows (``rot[i, k, n]``), on the
# same numbers: ``R @ v`` one matrix-vector product over the 3N (column, row, sample)
# entries (by rows, a transposed copy of the stack; by columns, the stack itself), and
# ``R @ m`` a matrix product of N columns per row of the rotations, read with a stride.
# BLAS rounds a product's last columns through another kernel, so these shapes are kept
# (tests/unit/safety/test_urdf_fk_columns.py holds the two layouts equal to the bit).


def _turn(cols: np.ndarray, axis: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``R_n @ Rot(axis, x[n])`` for every n, by columns; ``cols`` (3, 3, N) is reused
    when the axis is a coordinate axis."""
    k = int(np.argmax(np.abs(axis)))
    if abs(axis[k]) == 1.0:  # a coordinate axis: two columns turn in their plane
        x = x * axis[k]
        c, s = np.cos(x), np.sin(x)
        ci, cj = cols[(k + 1) % 3], cols[(k + 2) % 3]
        new_i = c * ci
        turn = s * cj
        new_i += turn  # c ci + s cj
        np.multiply(s, ci, out=turn)
        np.multiply(c, cj, out=cj)
        cj -= turn  # c cj - s ci
        ci[...] = new_i
        return cols
    # Rodrigues: R Rot(u, x) = R + sin x (R K) + (1 - cos x) (R K^2).
    kk = _skew(axis)
    rk = _times(cols, kk)
    return cols + np.sin(x) * rk + (1.0 - np.cos(x)) * _times(rk, kk)


def _times(cols: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``R_n @ m`` for every n, by columns, ``m`` a constant (3, 3)."""
    out = np.empty_like(cols)
    # out[j, i] = sum_k m[k, j] cols[k, i]: per row i, m.T @ (rows k of the columns)
    np.matmul(m.T, cols.transpose(1, 0, 2), out=out.transpose(1, 0, 2))
    return out


def _apply(cols: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R_n @ v`` for every n, (3, N), ``v`` a constant (3,)."""
    n = cols.shape[2]
    return np.dot(v.reshape(1, 3), cols.reshape(3, 3 * n)).reshape(3, n)


def columns_fk(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses of the chain's link for every row of ``q`` (N, n): positions (N, 3) and the
    rotations by columns, (3, 3, N) (``cols[k, i, n]`` is ``R_n[i, k]``), in the root
    link's frame; each row's values those of any batch of two rows or more holding it
    (one row alone is computed as two, as :func:`~aou_dsl.robot.rows.by_rows` does)."""
    q = np.ascontiguousarray(np.atleast_2d(np.asarray(q, dtype=float)))
    if len(q) == 1:
        two = columns_fk(chain, np.vstack([q, q]))
        return two[0][:1].copy(), two[1][:, :, :1].copy()
    n = len(q)
    rot = np.eye(3)  # a constant until the first moving joint
    pos = np.zeros(3)
    cols: np.ndarray | None = None  # then the rotations by columns (3, 3, N), pos (3, N)
    for s in chain.steps:
        if cols is None:
            pos = pos + rot @ s.pos
            rot = rot @ s.rot
            if s.col is None:
                continue
            cols = np.repeat(rot.T[:, :, None], n, axis=2)
            pos = np.repeat(pos[:, None], n, axis=1)
        else:
            pos = pos + _apply(cols, s.pos)
            cols = _times(cols, s.rot)
            if s.col is None:
                continue
        x = q[:, s.col]
        if s.kind == "prismatic":
            pos = pos + _apply(cols, s.axis) * x
            continue
        cols = _turn(cols, s.axis, x)
    if cols is None:
        return np.tile(pos, (n, 1)), np.repeat(rot.T[:, :, None], n, axis=2)
    return pos.T.copy(), cols


def chain_fk(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses of the chain's link for every row of ``q`` (N, n): positions (N, 3) and
    rotations (N, 3, 3) in the root link's frame."""
    pos, cols = columns_fk(chain, q)
    return pos, np.ascontiguousarray(cols.transpose(2, 1, 0))
