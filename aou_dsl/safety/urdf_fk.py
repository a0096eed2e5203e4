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

__all__ = ["Chain", "chain_fk", "rows_chain_fk", "urdf_chain"]


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


def _rotate(rot: np.ndarray, axis: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``rot[:, :, i] @ Rot(axis, x[i])`` for every i; ``rot`` (3, 3, N), component-major
    so that every operation runs on contiguous rows."""
    k = int(np.argmax(np.abs(axis)))
    if abs(axis[k]) == 1.0:  # a coordinate axis: two columns turn in their plane
        x = x * axis[k]
        c, s = np.cos(x), np.sin(x)
        i, j = (k + 1) % 3, (k + 2) % 3
        out = rot.copy()
        out[:, i] = c * rot[:, i] + s * rot[:, j]
        out[:, j] = c * rot[:, j] - s * rot[:, i]
        return out
    # Rodrigues: R Rot(u, x) = R + sin x (R K) + (1 - cos x) (R K^2).
    kk = _skew(axis)
    rk = _mul(rot, kk)
    return rot + np.sin(x) * rk + (1.0 - np.cos(x)) * _mul(rk, kk)


def _mul(rot: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``rot @ m`` for one rotation (3, 3) or a stack (3, 3, N), ``m`` constant (3, 3) or
    (3,); a stack gives (3, 3, N) or (3, N)."""
    if rot.ndim == 2:
        return rot @ m
    if m.ndim == 2:
        return np.matmul(m.T, rot)  # out[i, j] = sum_k m[k, j] rot[i, k]
    return np.tensordot(m, rot, axes=([0], [1]))  # out[i] = sum_k m[k] rot[i, k]


def chain_fk(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses of the chain's link for every row of ``q`` (N, n): positions (N, 3) and
    rotations (N, 3, 3) in the root link's frame."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    n = len(q)
    rot = np.eye(3)  # a constant until the first moving joint, then (3, 3, N)
    pos = np.zeros(3)  # then (3, N)
    for s in chain.steps:
        pos = pos + _mul(rot, s.pos)
        rot = _mul(rot, s.rot)
        if s.col is None:
            continue
        x = q[:, s.col]
        if rot.ndim == 2:
            rot = np.repeat(rot[:, :, None], n, axis=2)
            pos = np.repeat(pos[:, None], n, axis=1)
        if s.kind == "prismatic":
            pos = pos + _mul(rot, s.axis) * x
            continue
        rot = _rotate(rot, s.axis, x)
    if rot.ndim == 2:
        return np.tile(pos, (n, 1)), np.tile(rot, (n, 1, 1))
    return pos.T.copy(), np.ascontiguousarray(rot.transpose(2, 0, 1))


def rows_chain_fk(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`chain_fk` of the rows of ``q`` (N, n), each row's values those of any batch
    of two rows or more holding it (:func:`~aou_dsl.robot.rows.by_rows`)."""
    from ..robot.rows import by_rows

    pos, rot = by_rows(np.asarray(q, dtype=float), lambda rows: chain_fk(chain, rows))
    return pos, rot
