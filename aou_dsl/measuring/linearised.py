"""The copies' forward kinematics (:mod:`.uncertainty`), to first order about the
recording's own: each copy differs from the recording by noise, and the hand moves with
it by the Jacobian times that difference."""

from __future__ import annotations

import numpy as np

__all__ = ["JACOBIAN_STEP", "Linearised"]


class Linearised:
    """The forward kinematics of the copies, to first order about the recording's own.

    A copy differs from the recording by noise of 1e-4 to 1e-3 rad (the smoothed base
    by what its filter took out, each copy by that and its fresh noise); the hand's
    pose moves with it by the Jacobian times that difference, and the terms this leaves
    out are of the noise squared (about 1e-6 m on an arm half a metre long, a thousandth
    of what the noise itself moves the hand). The recording's own poses on each clock
    (``"grid"`` or ``"raw"``) are its measurement's (kept by the samples' bytes, so not
    computed again); the Jacobian is computed at every :data:`JACOBIAN_STEP`-th sample
    and interpolated linearly between (over a few milliseconds it changes by far less
    than the noise changes it). Without the recording's samples (``about`` None), the
    first call on each clock is the point expanded about, computed exactly. A rotation
    turns by the angular part, ``exp(W) R ~ (I + W + W^2/2) R``. An arm with joints
    other than revolute and prismatic, or a clock of another length, is computed exactly
    every time."""

    def __init__(self, arm, about: dict[str, np.ndarray] | None = None) -> None:
        self.arm = arm
        self.about = about or {}
        # Per clock: the expansion point's joints, hand positions and rotations, and the
        # Jacobian's linear and angular parts joint by joint, (n, 3, N) each (each axis
        # a row of samples: the sums below run along them).
        self.at: dict[str, tuple[np.ndarray, ...]] = {}

    def __call__(self, q: np.ndarray, clock: str) -> tuple[np.ndarray, np.ndarray]:
        from ..robot.batch_fk import batch_fk

        about = self.at.get(clock)
        if about is None:
            q0 = self.about.get(clock)
            first = q0 is None
            got = _expansion(self.arm, q if q0 is None else q0, exact_rows=first)
            if got is None:
                return batch_fk(self.arm, q)
            # The rotations laid out by rows, once: a product of a stack of 3x3 matrices
            # copies each operand that is not, every time (the same numbers either way).
            about = self.at[clock] = (*got[:2], np.ascontiguousarray(got[2]), *got[3:])
            if first:
                return got[1], got[2]
        if about[0].shape != q.shape:
            return batch_fk(self.arm, q)
        q0, pos0, rot0, lin, ang = about
        dq = q - q0
        pos, w = pos0.T.copy(), np.zeros((3, len(q)))
        term = np.empty_like(pos)
        for j in range(dq.shape[1]):
            step = np.ascontiguousarray(dq[:, j])
            pos += np.multiply(lin[j], step, out=term)
            w += np.multiply(ang[j], step, out=term)
        return np.ascontiguousarray(pos.T), np.matmul(_turn(w.T), rot0)


#: The copies' Jacobian is computed at every this many samples, and interpolated.
JACOBIAN_STEP = 8


def _expansion(arm, q: np.ndarray, exact_rows: bool) -> tuple[np.ndarray, ...] | None:
    """The point the copies' kinematics are expanded about: ``q`` (N, n), its hand
    positions and rotations (``exact_rows``: computed here; else the measurement's own,
    kept by the samples' bytes) and the Jacobian's linear and angular parts, (n, 3, N)
    each, from every :data:`JACOBIAN_STEP`-th row. None for an arm whose joints are not
    all revolute or prismatic."""
    from ..robot.batch_fk import batch_fk_jacobian, rows_fk

    q = np.array(q, float)
    n = len(q)
    if exact_rows or n < 2 * JACOBIAN_STEP:
        got = batch_fk_jacobian(arm, q)
        if got is None:
            return None
        pos, rot, jac = got
    else:
        knots = np.unique(np.append(np.arange(0, n, JACOBIAN_STEP), n - 1))
        got = batch_fk_jacobian(arm, q[knots])
        if got is None:
            return None
        rows = np.arange(n, dtype=float)
        parts = np.empty((2, q.shape[1], 3, n))  # linear, angular; joint; axis; sample
        for r in range(6):
            for j in range(q.shape[1]):
                parts[r // 3, j, r % 3] = np.interp(rows, knots, got[2][:, r, j])
        pos, rot = rows_fk(arm, q)
        return q, pos, rot, parts[0], parts[1]
    return (q, pos, rot, np.ascontiguousarray(jac[:, :3].transpose(2, 1, 0)),
            np.ascontiguousarray(jac[:, 3:].transpose(2, 1, 0)))


def _turn(w: np.ndarray) -> np.ndarray:
    """``exp(W) ~ I + W + W^2 / 2`` for ``W`` the skew matrix of each row of ``w`` (N, 3),
    (N, 3, 3); ``W^2 = w w^T - |w|^2 I``."""
    x, y, z = w[:, 0], w[:, 1], w[:, 2]
    m = np.empty((len(w), 3, 3))
    m[:, 0, 0] = 1.0 - 0.5 * (y * y + z * z)
    m[:, 1, 1] = 1.0 - 0.5 * (x * x + z * z)
    m[:, 2, 2] = 1.0 - 0.5 * (x * x + y * y)
    m[:, 0, 1], m[:, 1, 0] = 0.5 * x * y - z, 0.5 * x * y + z
    m[:, 0, 2], m[:, 2, 0] = 0.5 * x * z + y, 0.5 * x * z - y
    m[:, 1, 2], m[:, 2, 1] = 0.5 * y * z - x, 0.5 * y * z + x
    return m
