"""Reading joint trajectories: aou's JSON or a CSV recording, as a
:class:`~aou_dsl.trajectory.Trajectory`.

What measuring needs is times, joint positions by joint name, the robot, its
end-effector frame and the goal. The compiler's timeline and declared values are read
only for plots and replays, never for measuring, so recordings of real arms measure
the same way as compiled trajectories.
"""

from __future__ import annotations

import csv
import json
import math
import os

import numpy as np

from ..diagnostics import AouError, Span, diag
from ..files import read_text
from ..trajectory import Trajectory

__all__ = ["read_csv", "read_json", "read_recording"]


def _bad(path: str, message: str, hint: str | None = None, **fields) -> AouError:
    return AouError(diag("R401", message, Span.whole_file(path), hint=hint, **fields))


def _check_arrays(path: str, t: np.ndarray, q: np.ndarray, names: tuple[str, ...]) -> None:
    if t.ndim != 1 or len(t) < 3:
        raise _bad(path, f"a trajectory needs at least 3 samples, found {t.size}")
    if q.shape != (len(t), len(names)):
        raise _bad(path, f"`q` has shape {q.shape}; expected ({len(t)}, {len(names)}) "
                   "(one row per time, one column per joint name)")
    bad = ~np.isfinite(t)
    if bad.any():
        raise _bad(path, f"time is not a finite number at sample {int(np.argmax(bad))}")
    rows = ~np.isfinite(q).all(axis=1)
    if rows.any():
        i = int(np.argmax(rows))
        j = names[int(np.argmax(~np.isfinite(q[i])))]
        raise _bad(path, f"joint `{j}` is not a finite number at sample {i} (t={t[i]:g}s)",
                   sample=i, joint=j)
    step = np.diff(t)
    if (step <= 0).any():
        i = int(np.argmax(step <= 0)) + 1
        raise _bad(path, f"time must increase strictly: sample {i} has t={t[i]:g}s after "
                   f"t={t[i - 1]:g}s", sample=i)
    if len(set(names)) != len(names):
        raise _bad(path, "a joint name appears twice among the columns")


def _optional(doc: dict, q: np.ndarray) -> dict:
    """The velocities, accelerations and episodes a compiled file carries, when sound."""
    out: dict = {}
    try:
        qd = np.asarray(doc.get("qd", []), dtype=float)
        qdd = np.asarray(doc.get("qdd", []), dtype=float)
        if qd.shape == q.shape and qdd.shape == q.shape:
            out["qd"], out["qdd"] = qd, qdd
        out["episodes"] = tuple((str(e["kind"]), float(e["t_start"]), float(e["t_end"]))
                                for e in doc.get("episodes") or ())
    except (TypeError, ValueError, KeyError):
        return {}  # malformed extras: measure from q alone
    return out


def read_json(path: str, text: str) -> Trajectory:
    """An ``aou-trajectory/1`` document."""
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise AouError(diag("R401", f"not valid JSON: {exc.msg}",
                            Span.point(path, exc.lineno, exc.colno))) from None
    if not isinstance(doc, dict):
        raise _bad(path, "a trajectory file is a JSON object")
    fmt = doc.get("format")
    if fmt != "aou-trajectory/1":
        raise _bad(path, f"expected format `aou-trajectory/1`, found {fmt!r}")
    missing = [k for k in ("robot", "joint_names", "goal", "t", "q") if k not in doc]
    if missing:
        raise _bad(path, f"missing key(s): {', '.join(missing)}")
    try:
        t = np.asarray(doc["t"], dtype=float)
        q = np.asarray(doc["q"], dtype=float)
        names = tuple(str(n) for n in doc["joint_names"])
        goal = tuple(float(x) for x in doc["goal"]["position"])
    except (TypeError, ValueError, KeyError) as exc:
        raise _bad(path, f"malformed trajectory: {exc}") from None
    if len(goal) != 3:
        raise _bad(path, "`goal.position` must have 3 coordinates")
    _check_arrays(path, t, q, names)
    title = str(doc.get("behaviour") or os.path.splitext(os.path.basename(path))[0])
    return Trajectory(t, q, names, str(doc["robot"]), doc.get("ee_frame"), goal,
                      path=path, title=title, **_optional(doc, q))


def read_csv(path: str, text: str, robot: str, goal: tuple[float, float, float] | None,
             ee_frame: str | None) -> Trajectory:
    """A CSV with a header row: ``t`` then one column per joint name."""
    rows = list(csv.reader(text.splitlines()))
    rows = [r for r in rows if r and not r[0].startswith("#")]
    if not rows:
        raise _bad(path, "the CSV file is empty")
    header = [h.strip() for h in rows[0]]
    if not header or header[0] != "t":
        raise _bad(path, f"the first column must be `t`, found `{header[0] if header else ''}`",
                   hint="a header row `t,joint_a,joint_b,...` names the columns")
    values = np.full((len(rows) - 1, len(header)), math.nan)
    for i, r in enumerate(rows[1:]):
        if len(r) != len(header):
            raise _bad(path, f"row {i + 2} has {len(r)} columns; the header has {len(header)}",
                       row=i + 2)
        for j, cell in enumerate(r):
            try:
                values[i, j] = float(cell)
            except ValueError:
                raise _bad(path, f"row {i + 2}, column `{header[j]}`: `{cell}` is not a "
                           "number", row=i + 2) from None
    if goal is None:
        from ..robots import ROBOTS

        spec = ROBOTS.get(robot)
        if spec is None:
            raise _bad(path, f"unknown robot `{robot}`")
        goal = spec.goal
    names = tuple(header[1:])
    _check_arrays(path, values[:, 0], values[:, 1:], names)
    title = os.path.splitext(os.path.basename(path))[0]
    return Trajectory(values[:, 0], values[:, 1:], names, robot, ee_frame, tuple(goal),
                      path=path, title=title)


def read_recording(path: str, *, robot: str | None = None,
                   goal: tuple[float, float, float] | None = None,
                   ee_frame: str | None = None) -> Trajectory:
    """Read a ``.json`` trajectory or a ``.csv`` recording (which needs ``robot``)."""
    text = read_text(path)
    if path.endswith(".csv"):
        if robot is None:
            raise AouError(diag("I501", "a CSV recording needs `--robot NAME`",
                                Span.whole_file(path)))
        return read_csv(path, text, robot, goal, ee_frame)
    rec = read_json(path, text)
    if goal is not None or ee_frame is not None or robot is not None:
        rec = rec.with_(robot=robot or rec.robot, ee_frame=ee_frame or rec.ee_frame,
                        goal=tuple(goal) if goal else rec.goal)
    return rec
