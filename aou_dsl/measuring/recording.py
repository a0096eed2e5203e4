"""Reading joint trajectories: aou's JSON, CSV and NPZ, or a recording of a real arm, as a
:class:`~aou_dsl.trajectory.Trajectory`.

What measuring needs is times, joint positions by joint name, the robot, its
end-effector frame and the goal. The compiler's timeline and declared values are read
only for plots and replays, never for measuring, so recordings of real arms measure
the same way as compiled trajectories.

Every format aou writes reads back with its robot, frame and goal: the JSON and the NPZ
carry them in the document, the CSV in comment lines before its header
(``# robot: NAME``, ``# ee_frame: F``, ``# goal: X,Y,Z``). Options given to
:func:`read_recording` override the file. A recording whose units look wrong (angles in
degrees, times in milliseconds) is refused unless the unit is given.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import zipfile
from typing import Any

import numpy as np

from ..diagnostics import AouError, Severity, Span, diag
from ..files import read_bytes, read_text
from ..trajectory import Trajectory
from .document import Header, read_header

__all__ = ["ANGLE_UNITS", "TIME_UNITS", "read_csv", "read_json", "read_npz",
           "read_recording"]

ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
#: A clock slower than this [s per sample] is taken for milliseconds read as seconds.
SLOWEST_STEP = 0.2
#: How far [rad] beyond its limits a joint may sit throughout under a unit given.
BEYOND = math.radians(1.0)


def _bad(path: str, message: str, hint: str | None = None, **fields) -> AouError:
    return AouError(diag("R401", message, Span.whole_file(path), hint=hint, **fields))


def _check_arrays(path: str, t: np.ndarray, q: np.ndarray, names: tuple[str, ...],
                  rows: list[int] | None = None) -> None:
    """Shapes, finite values and distinct names; ``rows`` gives each sample's line in a
    text file (for the messages)."""
    where = (lambda i: f"row {rows[i]}") if rows else (lambda i: f"sample {i}")
    if t.ndim != 1 or len(t) < 3:
        raise _bad(path, f"a trajectory needs at least 3 samples, found {t.size}")
    if q.shape != (len(t), len(names)):
        raise _bad(path, f"`q` has shape {q.shape}; expected ({len(t)}, {len(names)}) "
                   "(one row per time, one column per joint name)")
    if len(set(names)) != len(names):
        raise _bad(path, "a joint name appears twice among the columns")
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        raise _bad(path, f"{where(i)}: the time is not a finite number", sample=i)
    bad_rows = ~np.isfinite(q).all(axis=1)
    if bad_rows.any():
        i = int(np.argmax(bad_rows))
        j = names[int(np.argmax(~np.isfinite(q[i])))]
        raise _bad(path, f"{where(i)} (t={t[i]:g}): joint `{j}` is not a finite number",
                   sample=i, joint=j)


def _check_clock(path: str, t: np.ndarray, rows: list[int] | None = None) -> None:
    step = np.diff(t)
    if (step <= 0).any():
        i = int(np.argmax(step <= 0)) + 1
        at = f"row {rows[i]}" if rows else f"sample {i}"
        raise _bad(path, f"time must increase strictly: {at} has t={t[i]:g} after "
                   f"t={t[i - 1]:g}", sample=i)


def _optional(doc: dict, q: np.ndarray) -> dict:
    """The velocities, accelerations and episodes a compiled file carries, when sound."""
    out: dict = {}
    try:
        qd = np.asarray(doc.get("qd") if doc.get("qd") is not None else [], dtype=float)
        qdd = np.asarray(doc.get("qdd") if doc.get("qdd") is not None else [], dtype=float)
        if qd.shape == q.shape and qdd.shape == q.shape:
            out["qd"], out["qdd"] = qd, qdd
        out["episodes"] = tuple((str(e["kind"]), float(e["t_start"]), float(e["t_end"]))
                                for e in doc.get("episodes") or ())
    except (TypeError, ValueError, KeyError):
        return {}  # malformed extras: measure from q alone
    return out


def _from_document(path: str, doc: dict, header: Header, t: Any, q: Any) -> Trajectory:
    """A trajectory from a document of the trajectory format, its validated header and
    its arrays."""
    names = tuple(header.joint_names)
    try:
        t = np.asarray(t, dtype=float)
        rows = list(q)
        for i, row in enumerate(rows):
            if len(row) != len(names):
                raise _bad(path, f"sample {i} has {len(row)} values; `joint_names` has "
                           f"{len(names)}", sample=i)
        q = np.asarray(rows, dtype=float).reshape(len(rows), len(names))
    except (TypeError, ValueError) as exc:
        raise _bad(path, f"malformed trajectory: {exc}") from None
    _check_arrays(path, t, q, names)
    title = header.behaviour or os.path.splitext(os.path.basename(path))[0]
    return Trajectory(t, q, names, header.robot, header.ee_frame, header.goal_position,
                      path=path, title=title, **_optional(doc, q))


def read_json(path: str, text: str, own_goal: bool = True) -> Trajectory:
    """An ``aou-trajectory/1`` document (the goal may be missing; ``own_goal`` False:
    not read, one given replaces it)."""
    return _json(path, text, own_goal)[0]


def read_npz(path: str, data: bytes, own_goal: bool = True) -> Trajectory:
    """aou's NPZ: ``t.npy``, ``q.npy`` (and ``qd``, ``qdd``) with ``header.json``."""
    return _npz(path, data, own_goal)[0]


def _json(path: str, text: str, own_goal: bool) -> tuple[Trajectory, Header]:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise AouError(diag("R401", f"not valid JSON: {exc.msg}",
                            Span.point(path, exc.lineno, exc.colno))) from None
    header = read_header(path, doc, own_goal=own_goal)
    missing = [k for k in ("t", "q") if k not in doc]
    if missing:
        raise _bad(path, f"missing key(s): {', '.join(missing)}")
    if not isinstance(doc["q"], list):
        raise _bad(path, "`q` must be a list of rows")
    rec = _from_document(path, doc, header, doc["t"], doc["q"])
    _check_clock(path, rec.t)
    return rec, header


def _npz(path: str, data: bytes, own_goal: bool) -> tuple[Trajectory, Header]:
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            doc = json.loads(zf.read("header.json"))
            arrays = {}
            for key in ("t", "q", "qd", "qdd"):
                if f"{key}.npy" in zf.namelist():
                    arrays[key] = np.lib.format.read_array(io.BytesIO(zf.read(f"{key}.npy")),
                                                           allow_pickle=False)
    except (zipfile.BadZipFile, KeyError, ValueError, OSError) as exc:
        raise _bad(path, f"not an aou NPZ trajectory: {exc}",
                   hint="an NPZ of aou holds t.npy, q.npy and header.json") from None
    if "t" not in arrays or "q" not in arrays:
        raise _bad(path, "not an aou NPZ trajectory: `t.npy` or `q.npy` is missing")
    header = read_header(path, doc, own_goal=own_goal)
    doc = {**doc, **{k: v for k, v in arrays.items() if k in ("qd", "qdd")}}
    q = arrays["q"]
    if q.ndim != 2:
        raise _bad(path, f"`q` has shape {q.shape}; expected (samples, joints)")
    rec = _from_document(path, doc, header, arrays["t"], q)
    _check_clock(path, rec.t)
    return rec, header


def _comments(lines: list[str]) -> dict[str, str]:
    """``# key: value`` lines before the header."""
    out = {}
    for line in lines:
        body = line.lstrip("#").strip()
        if ":" in body:
            key, value = body.split(":", 1)
            out[key.strip().lower()] = value.strip()
    return out


def _csv_values(path: str, rows: list[tuple[int, list[str]]], header: list[str]
                ) -> np.ndarray:
    values = np.full((len(rows), len(header)), math.nan)
    for i, (line, r) in enumerate(rows):
        if len(r) != len(header):
            raise _bad(path, f"row {line} has {len(r)} columns; the header has "
                       f"{len(header)}", row=line)
        for j, cell in enumerate(r):
            try:
                values[i, j] = float(cell)
            except ValueError:
                raise _bad(path, f"row {line}, column `{header[j]}`: `{cell}` is not a "
                           "number", row=line) from None
    return values


def _read_csv(path: str, text: str, robot: str | None,
              goal: tuple[float, float, float] | None, ee_frame: str | None
              ) -> tuple[Trajectory, list[int], bool]:
    """:func:`read_csv` without the clock check; also each sample's line in the file and
    whether aou wrote the file."""
    lines = text.splitlines()
    notes = _comments([ln for ln in lines if ln.startswith("#")])
    rows = [(k + 1, r) for k, r in enumerate(csv.reader(lines)) if r and not r[0].startswith("#")]
    if not rows:
        raise _bad(path, "the CSV file is empty")
    header = [h.strip() for h in rows[0][1]]
    if header[0] != "t":
        raise _bad(path, f"the first column must be `t`, found `{header[0]}`",
                   hint="a header row `t,joint_a,joint_b,...` names the columns")
    values = _csv_values(path, rows[1:], header)
    robot = robot or notes.get("robot")
    if not robot:
        raise AouError(diag("I501", f"cannot read `{path}` as a recording without its robot: "
                            "the CSV does not say which robot made it (no `# robot:` line)",
                            Span.whole_file(path), hint="give --robot NAME|PATH"))
    if goal is None and notes.get("goal"):
        try:
            goal = tuple(float(x) for x in notes["goal"].split(","))  # type: ignore[assignment]
        except ValueError:
            raise _bad(path, f"the `# goal:` comment must be X,Y,Z, found "
                       f"`{notes['goal']}`") from None
    ee = ee_frame or (notes.get("ee_frame") if notes.get("ee_frame") not in (None, "None")
                      else None)
    names = tuple(header[1:])
    line_of = [line for line, _ in rows[1:]]
    _check_arrays(path, values[:, 0], values[:, 1:], names, line_of)
    title = os.path.splitext(os.path.basename(path))[0]
    rec = Trajectory(values[:, 0], values[:, 1:], names, robot, ee,
                     tuple(goal) if goal is not None else None, path=path, title=title)
    return rec, line_of, "aou-trajectory/1" in notes.get("format", "")


def read_csv(path: str, text: str, robot: str | None = None,
             goal: tuple[float, float, float] | None = None,
             ee_frame: str | None = None) -> Trajectory:
    """A CSV with a header row ``t,JOINT,...``, after optional ``# key: value`` comment
    lines (aou writes ``robot``, ``ee_frame`` and ``goal`` there). ``robot``, ``goal``
    and ``ee_frame`` override the comments."""
    rec, rows, _ = _read_csv(path, text, robot, goal, ee_frame)
    _check_clock(path, rec.t, rows)
    return rec


def _at(rec: Trajectory, rows: list[int] | None, i: int) -> tuple[str, Span, dict]:
    """Sample ``i``: its row in a text file (the span points there), else its index."""
    if rows:
        return f"row {rows[i]}", Span.point(rec.path, rows[i], 1), {"sample": i, "row": rows[i]}
    return f"sample {i}", Span.whole_file(rec.path), {"sample": i}


def _check_units(rec: Trajectory, angle_unit: str | None, time_unit: str | None,
                 trusted: bool, rows: list[int] | None = None) -> Trajectory:
    """Convert the units given. R404 for values that look like degrees or milliseconds
    when none is given, and for an angle unit that puts a joint outside its limits
    throughout. ``rows``: each sample's line in a text file."""
    from ..kinematics import load_arm

    for unit, table, what in ((angle_unit, ANGLE_UNITS, "angle"),
                              (time_unit, TIME_UNITS, "time")):
        if unit is not None and unit not in table:
            raise AouError(diag("R404", f"unknown {what} unit `{unit}`: expected one of "
                                f"{', '.join(table)}", Span.whole_file(rec.path)))
    wrong = [f"--{flag} {unit}" for flag, unit, right in
             (("angle-unit", angle_unit, "rad"), ("time-unit", time_unit, "s"))
             if unit not in (None, right)]
    arm = load_arm(rec.robot, rec.ee_frame)
    if trusted and wrong and _as_written(rec, arm, rows):
        raise AouError(diag("R404", f"aou wrote this file, in radians and seconds: "
                            f"{' and '.join(wrong)} would misread it", Span.whole_file(
                                rec.path), hint="leave the units out for files aou wrote"))
    t = np.asarray(rec.t, float) * TIME_UNITS[time_unit or "s"]
    if time_unit is None and not trusted:  # aou writes slow clocks too (--rate 1)
        _plausible_clock(rec, t, rows)
    q = np.asarray(rec.q, float).copy()
    for j in _revolute(arm):
        name = arm.joint_names[j]
        if name not in rec.joint_names:
            continue
        col = rec.joint_names.index(name)
        limits = (float(arm.lower[j]), float(arm.upper[j]))
        if angle_unit is not None:
            q[:, col] *= ANGLE_UNITS[angle_unit]
            _obeyed_limits(rec, q[:, col], name, limits, angle_unit, rows)
        else:  # aou's own files too: an edited one may no longer be in radians
            _plausible_angles(rec, q[:, col], name, limits, rows)
    return rec.with_(t=t, q=q)


def _revolute(arm: Any) -> list[int]:
    return [j for j in range(len(arm.joint_names))
            if arm.model.joints[j + 1].shortname().startswith("JointModelR")]


def _as_written(rec: Trajectory, arm: Any, rows: list[int] | None) -> bool:
    """Whether the file's angles are plausible in radians as they stand."""
    try:
        for j in _revolute(arm):
            if arm.joint_names[j] in rec.joint_names:
                col = np.asarray(rec.q, float)[:, rec.joint_names.index(arm.joint_names[j])]
                _plausible_angles(rec, col, arm.joint_names[j],
                                  (float(arm.lower[j]), float(arm.upper[j])), rows)
    except AouError:
        return False
    return True


def _plausible_clock(rec: Trajectory, t: np.ndarray, rows: list[int] | None) -> None:
    """R404 when samples come slower than :data:`SLOWEST_STEP` (milliseconds as seconds)."""
    step = np.diff(t)
    if len(step) and float(np.median(step)) >= SLOWEST_STEP:
        i = int(np.argmax(step >= SLOWEST_STEP)) + 1
        at, span, fields = _at(rec, rows, i)
        raise AouError(diag("R404", f"the times look like milliseconds: one sample every "
                            f"{float(np.median(step)):g} s ({at} has t={t[i]:g} after "
                            f"t={t[i - 1]:g})", span, hint="give --time-unit ms, or "
                            "--time-unit s if the clock really is that slow", **fields))


def _within(col: np.ndarray, lo: float, hi: float, slack: float | None = None) -> np.ndarray:
    """Which values lie in [lo, hi] widened by ``slack`` (default a tenth of the range:
    an offset is not a unit problem); +-2 turns for a joint without finite limits."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = -4 * math.pi, 4 * math.pi
    slack = 0.1 * (hi - lo) if slack is None else slack
    return (col >= lo - slack) & (col <= hi + slack)


def _plausible_angles(rec: Trajectory, col: np.ndarray, name: str,
                      limits: tuple[float, float], rows: list[int] | None) -> None:
    """R404 when a joint's values leave its limits and read as degrees they would not."""
    inside = _within(col, *limits)
    if inside.all() or not _within(np.radians(col), *limits).all():
        return
    i = int(np.argmin(inside))
    at, span, fields = _at(rec, rows, i)
    raise AouError(diag(
        "R404", f"joint `{name}` reads {col[i]:g} at {at}, outside its limits "
        f"[{limits[0]:.3g}, {limits[1]:.3g}] rad: the angles look like degrees", span,
        hint="give --angle-unit deg, or --angle-unit rad if they really are radians",
        joint=name, **fields))


def _obeyed_limits(rec: Trajectory, col: np.ndarray, name: str,
                   limits: tuple[float, float], unit: str, rows: list[int] | None) -> None:
    """R404 when the angle unit given leaves every sample of a joint beyond its limits
    (by :data:`BEYOND`): the unit contradicts the robot."""
    lo, hi = limits
    if not (math.isfinite(lo) and math.isfinite(hi)) or _within(col, lo, hi, BEYOND).any():
        return
    other = "rad" if unit == "deg" else "deg"
    fits = _within(col / ANGLE_UNITS[unit] * ANGLE_UNITS[other], lo, hi).all()
    at, span, fields = _at(rec, rows, 0)
    raise AouError(diag(
        "R404", f"with --angle-unit {unit}, joint `{name}` reads {col[0]:.4g} rad at {at} "
        f"and every one of its {len(col)} samples lies outside its limits [{lo:.3g}, "
        f"{hi:.3g}] rad: the unit given contradicts the robot's limits", span,
        hint=f"the values fit the limits in {other}: give --angle-unit {other}" if fits
        else "check the unit, and that the recording is of this robot (--robot)",
        joint=name, unit=unit, **fields))


def final_goal(rec: Trajectory) -> tuple[float, float, float]:
    """The end-effector's position at the last sample: the goal of ``goal="final"``."""
    from ..kinematics import load_arm
    from .fk import batch_fk

    arm = load_arm(rec.robot, rec.ee_frame)
    cols = rec.columns(arm.joint_names)
    pos, _ = batch_fk(arm, np.asarray(rec.q, float)[-1:, cols])
    return (float(pos[0, 0]), float(pos[0, 1]), float(pos[0, 2]))


def read_recording(path: str, *, robot: str | None = None,
                   goal: tuple[float, float, float] | str | None = None,
                   ee_frame: str | None = None, angle_unit: str | None = None,
                   time_unit: str | None = None) -> Trajectory:
    """Read a ``.json`` or ``.npz`` trajectory or a ``.csv`` recording.

    Args:
        robot, ee_frame: override the file's (a CSV without a ``# robot:`` line needs
            ``robot``); ``robot`` is a name or a robot file's path.
        goal: X, Y, Z [m] overriding the file's, or ``"final"``: the end-effector's
            position at the last sample (gaze angles are then bearings of that point).
            Without any goal, measuring warns (R405) and leaves the gazes unknown.
        angle_unit: ``"rad"`` or ``"deg"`` for the revolute joints; ``time_unit``:
            ``"s"`` or ``"ms"``. When not given, values that look like degrees or
            milliseconds are refused (R404), in files aou wrote too (they may have been
            edited); a unit on a file aou wrote whose values look right as they stand is
            refused. An angle unit that leaves a joint outside its limits at every sample
            is refused too.

    Raises:
        AouError: I501 when the file cannot be read; R401 for a malformed trajectory
            (with the row or sample); R404 for implausible units.
    """
    data = read_bytes(path) if path.endswith(".npz") else b""
    text = None if path.endswith(".npz") else read_text(path)
    rows = None
    if path.endswith(".csv"):
        rec, rows, trusted = _read_csv(path, text or "", robot,
                                       None if isinstance(goal, str) else goal, ee_frame)
    else:
        rec, header = (_npz(path, data, goal is None) if path.endswith(".npz")
                       else _json(path, text or "", goal is None))
        trusted = header.generator.startswith("aouc")
    changes: dict[str, Any] = {k: v for k, v in (("robot", robot), ("ee_frame", ee_frame))
                               if v}
    if goal is not None and not isinstance(goal, str):
        changes["goal"] = tuple(float(x) for x in goal)
    rec = rec.with_(**changes) if changes else rec
    rec = _check_units(rec, angle_unit, time_unit, trusted, rows)
    _check_clock(path, rec.t, rows)
    if isinstance(goal, str):
        if goal != "final":
            raise AouError(diag("R405", f"unknown goal `{goal}`: give X,Y,Z or `final`",
                                Span.whole_file(path), severity=Severity.ERROR))
        rec = rec.with_(goal=final_goal(rec))
    return rec
