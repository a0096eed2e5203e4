"""Reading joint trajectories: aou's JSON, CSV and NPZ, or a recording of a real arm, as a
:class:`~aou_dsl.core.trajectory.Trajectory`.

What measuring needs is times, joint positions by joint name, the robot, its
end-effector frame and the goal. The compiler's timeline and declared values are read
only for plots and replays, never for measuring, so recordings of real arms measure
the same way as compiled trajectories.

Every format aou writes reads back with its robot, frame and goal: the JSON and the NPZ
carry them in the document, the CSV in comment lines before its header
(``# robot: NAME``, ``# ee_frame: F``, ``# goal: X,Y,Z``). Options given to
:func:`read_recording` override the file. A recording whose units look wrong (angles in
degrees, times in milliseconds) is refused unless the unit is given, and so is a unit
given that contradicts the robot (:mod:`.plausible`). A file of another extension is
read by its content; ROS bags and YAML, which aou writes for ROS, are not read back.
Errors point at the row, the sample or the header field where they are (:mod:`.locate`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..core.codes import I501, R401, R405
from ..core.diagnostics import AouError, Severity, Span, diag
from ..core.files import decode
from ..core.inputs import input_limit, max_samples, read_input, too_many_samples
from ..core.trajectory import Trajectory
from .bounded import MAX_JOINT_VALUE, csv_table, npz_members, numbers, parse_json
from .document import Header, read_header
from .locate import Where, json_span
from .plausible import ANGLE_UNITS, TIME_UNITS, check_units

__all__ = ["ANGLE_UNITS", "FORMATS", "TIME_UNITS", "read_csv", "read_json", "read_npz",
           "read_recording"]

#: The trajectory formats read, by extension.
FORMATS = ("json", "csv", "npz")


def _bad(path: str, message: str, hint: str | None = None, span: Span | None = None,
         **fields) -> AouError:
    return AouError(diag(R401, message, span or Span.whole_file(path), hint=hint, **fields))


def _check_arrays(t: np.ndarray, q: np.ndarray, names: tuple[str, ...], where: Where
                  ) -> None:
    """Shapes, finite values and distinct names; ``where`` places each sample in its
    file (for the messages and spans)."""
    path = where.path
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
        raise _bad(path, f"{where.label(i)}: the time is not a finite number",
                   span=where.span(i, "t"), sample=i)
    bad_rows = ~(np.isfinite(q) & (np.abs(q) <= MAX_JOINT_VALUE)).all(axis=1)
    if bad_rows.any():
        i = int(np.argmax(bad_rows))
        k = int(np.argmax(~(np.isfinite(q[i]) & (np.abs(q[i]) <= MAX_JOINT_VALUE))))
        what = "not a finite number" if not np.isfinite(q[i, k]) else \
            f"{q[i, k]:g}, beyond any joint position (at most {MAX_JOINT_VALUE:g})"
        raise _bad(path, f"{where.label(i)} (t={t[i]:g}): joint `{names[k]}` is {what}",
                   span=where.span(i, "q", k), sample=i, joint=names[k])


def _check_clock(t: np.ndarray, where: Where) -> None:
    step = np.diff(t)
    if (step <= 0).any():
        i = int(np.argmax(step <= 0)) + 1
        raise _bad(where.path, f"time must increase strictly: {where.label(i)} has "
                   f"t={t[i]:g} after t={t[i - 1]:g}", span=where.span(i, "t"), sample=i)


def _optional(doc: dict, q: np.ndarray) -> dict:
    """The velocities, accelerations and episodes a compiled file carries, when sound."""
    out: dict = {}
    try:
        qd = np.asarray(doc.get("qd") if doc.get("qd") is not None else [], dtype=float)
        qdd = np.asarray(doc.get("qdd") if doc.get("qdd") is not None else [], dtype=float)
        if qd.shape == q.shape and qdd.shape == q.shape:
            out["qd"], out["qdd"] = qd, qdd
        episodes = doc.get("episodes") or ()
        if len(episodes) > MAX_EPISODES:
            return {}  # no compiled file has so many: measure from q alone
        out["episodes"] = tuple((str(e["kind"]), float(e["t_start"]), float(e["t_end"]))
                                for e in episodes)
    except (TypeError, ValueError, KeyError):
        return {}  # malformed extras: measure from q alone
    return out


#: Most episodes a trajectory's ``episodes`` list is read with (lint allows 1000).
MAX_EPISODES = 1000


def _number_at(values: Any, where: Where, key: str, i: int) -> AouError:
    """R401 at the first value of row (or time) ``i`` onwards that is not a number."""
    for k in range(i, len(values)):
        row = values[k] if key == "q" else [values[k]]
        if not isinstance(row, list | tuple):
            return _bad(where.path, f"{where.label(k)} of `q` is not a list of joint values",
                        span=where.span(k, key), sample=k)
        for j, v in enumerate(row):
            if numbers([v]) is None or isinstance(v, list | tuple):
                what = f"joint column {j}" if key == "q" else "the time"
                return _bad(where.path, f"{where.label(k)}: {what} is {json.dumps(v)[:40]}, "
                            "not a number", span=where.span(k, key, j if key == "q" else None),
                            sample=k)
    return _bad(where.path, f"malformed `{key}`")


def _from_document(doc: dict, header: Header, t: Any, q: Any, where: Where) -> Trajectory:
    """A trajectory from a document of the trajectory format, its validated header and
    its arrays; ``where`` places its samples in the file."""
    path, names = where.path, tuple(header.joint_names)
    rows = list(q)
    for i, row in enumerate(rows):
        if not hasattr(row, "__len__"):
            raise _number_at(rows, where, "q", i)
        if len(row) != len(names):
            raise _bad(path, f"{where.label(i)} has {len(row)} values; `joint_names` has "
                       f"{len(names)}", span=where.span(i), sample=i)
    if len(rows) > max_samples():
        raise too_many_samples(path, len(rows))
    t_values, q_values = numbers(t), numbers(rows)
    if t_values is None:
        raise _number_at(list(t) if isinstance(t, list | np.ndarray) else [t], where, "t", 0)
    if q_values is None:
        raise _number_at(rows, where, "q", 0)
    if q_values.ndim != 2:
        raise _bad(path, f"`q` has shape {q_values.shape}; expected ({len(rows)}, "
                   f"{len(names)}): one list of joint values per time")
    t, q = t_values, q_values
    _check_arrays(t, q, names, where)
    title = header.behaviour or os.path.splitext(os.path.basename(path))[0]
    return Trajectory(t, q, names, header.robot, header.ee_frame, header.goal_position,
                      path=path, title=title, ee_definition=header.frame_definition,
                      **_optional(doc, q))


def read_json(path: str, text: str, own_goal: bool = True) -> Trajectory:
    """An ``aou-trajectory/1`` document (the goal may be missing; ``own_goal`` False:
    not read, one given replaces it)."""
    return _json(path, text, own_goal)[0]


def read_npz(path: str, data: bytes, own_goal: bool = True) -> Trajectory:
    """aou's NPZ: ``t.npy``, ``q.npy`` (and ``qd``, ``qdd``) with ``header.json``."""
    return _npz(path, data, own_goal)[0]


def _json(path: str, text: str, own_goal: bool) -> tuple[Trajectory, Header]:
    text = text.removeprefix("\ufeff")
    doc = parse_json(path, text)
    header = read_header(path, doc, own_goal=own_goal, text=text)
    missing = [k for k in ("t", "q") if k not in doc]
    if missing:
        raise _bad(path, f"missing key(s): {', '.join(missing)}")
    where = Where(path, text=text)
    for key in ("t", "q"):
        if not isinstance(doc[key], list):
            raise _bad(path, f"`{key}` must be a list of {'times' if key == 't' else 'rows'}",
                       span=json_span(path, text, (key,)))
    rec = _from_document(doc, header, doc["t"], doc["q"], where)
    _check_clock(rec.t, where)
    return rec, header


def _npz(path: str, data: bytes, own_goal: bool) -> tuple[Trajectory, Header]:
    doc, arrays = npz_members(path, data, input_limit("recording"))
    if "t" not in arrays or "q" not in arrays:
        raise _bad(path, "not an aou NPZ trajectory: `t.npy` or `q.npy` is missing")
    header = read_header(path, doc, own_goal=own_goal)
    doc = {**doc, **{k: v for k, v in arrays.items() if k in ("qd", "qdd")}}
    q = arrays["q"]
    if q.ndim != 2:
        raise _bad(path, f"`q` has shape {q.shape}; expected (samples, joints)")
    where = Where(path)
    rec = _from_document(doc, header, arrays["t"], q, where)
    _check_clock(rec.t, where)
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


def _csv_goal(path: str, text: str, lines: list[str]) -> tuple[float, float, float]:
    """The ``# goal: X,Y,Z`` comment: three finite numbers within the goal's bound."""
    from .document import MAX_GOAL

    line = next((k + 1 for k, ln in enumerate(lines) if ln.lstrip("#").strip().lower()
                 .startswith("goal")), 1)
    try:
        xyz = tuple(float(x) for x in text.split(","))
    except ValueError:
        xyz = ()
    if len(xyz) != 3 or not all(abs(v) <= MAX_GOAL for v in xyz):  # NaN fails too
        raise _bad(path, f"the `# goal:` comment must be X,Y,Z: three finite numbers in "
                   f"metres, each within {MAX_GOAL:g} m of the base; found `{text}`",
                   span=Span.point(path, line, 1), hint="write e.g. `# goal: 0.55,0,0.25`, "
                   "or leave the line out and give --goal")
    return xyz  # type: ignore[return-value]


def _read_csv(path: str, text: str, robot: str | None,
              goal: tuple[float, float, float] | None, ee_frame: str | None
              ) -> tuple[Trajectory, Where, bool]:
    """:func:`read_csv` without the clock check; also where each sample is in the file
    and whether aou wrote the file."""
    lines = text.removeprefix("\ufeff").splitlines()
    notes = _comments([ln for ln in lines if ln.startswith("#")])
    (header_line, header), at, values = csv_table(path, lines)
    if header[0] != "t":
        raise _bad(path, f"the first column must be `t`, found `{header[0]}`",
                   hint="a header row `t,joint_a,joint_b,...` names the columns",
                   span=Span.point(path, header_line, 1))
    robot = robot or notes.get("robot")
    if not robot:
        raise AouError(diag(I501, f"cannot read `{path}` as a recording without its robot: "
                            "the CSV does not say which robot made it (no `# robot:` line)",
                            Span.whole_file(path), hint="give --robot NAME|PATH"))
    if goal is None and "goal" in notes:
        goal = _csv_goal(path, notes["goal"], lines)
    ee = ee_frame or (notes.get("ee_frame") if notes.get("ee_frame") not in (None, "None")
                      else None)
    names = tuple(header[1:])
    where = Where(path, lines=at.tolist())
    _check_arrays(values[:, 0], values[:, 1:], names, where)
    title = os.path.splitext(os.path.basename(path))[0]
    rec = Trajectory(values[:, 0], values[:, 1:], names, robot, ee,
                     tuple(goal) if goal is not None else None, path=path, title=title)
    return rec, where, "aou-trajectory/1" in notes.get("format", "")


def read_csv(path: str, text: str, robot: str | None = None,
             goal: tuple[float, float, float] | None = None,
             ee_frame: str | None = None) -> Trajectory:
    """A CSV with a header row ``t,JOINT,...``, after optional ``# key: value`` comment
    lines (aou writes ``robot``, ``ee_frame`` and ``goal`` there). ``robot``, ``goal``
    and ``ee_frame`` override the comments."""
    rec, where, _ = _read_csv(path, text, robot, goal, ee_frame)
    _check_clock(rec.t, where)
    return rec


#: Files aou writes, or meets beside its own, but does not read as trajectories.
_NOT_READ = {".mcap": "a ROS 2 bag", ".db3": "a ROS 2 bag", ".bag": "a ROS bag",
             ".yaml": "YAML", ".yml": "YAML"}


def _unread(path: str, what: str) -> AouError:
    """I501: ``path`` (``what`` it is) is in none of :data:`FORMATS`."""
    bag = "bag" in what or what == "YAML"
    return AouError(diag(
        I501, f"cannot read `{path}`: it is {what}, not a trajectory aou reads; aou "
        "reads trajectories from JSON, CSV and NPZ files (and compiles `.aou` files)",
        Span.whole_file(path), hint=(
            "aou writes ROS 2 bags and YAML for ROS (--format mcap|yaml) but does not read "
            "them back: measure the same trajectory as JSON, CSV or NPZ (aouc compile "
            "--format json), or export the recorded joint states to a CSV" if bag else
            "a CSV recording starts with a header row `t,JOINT,JOINT,...`; a JSON "
            "trajectory is an object with `format`, `robot`, `joint_names`, `t` and `q`")))


def _sniff(data: bytes) -> str | None:
    """The format of a file of no known extension, by its first bytes: a zip (NPZ), a
    JSON object, or a CSV whose header's first column is ``t``; None for none."""
    if data.startswith(b"PK\x03\x04"):
        return "npz"
    head = data[:4096].decode("utf-8-sig", "ignore").lstrip()
    if head.startswith("{"):
        return "json"
    for line in head.splitlines():
        if line.strip() and not line.startswith("#"):
            return "csv" if "," in line and line.split(",")[0].strip() == "t" else None
    return None


def _format(path: str) -> tuple[str, bytes]:
    """The format of ``path`` (by its extension, else by its content) and its bytes.

    Raises:
        AouError: I501 for a folder, a ROS bag or YAML, or content of no format read.
    """
    ext = os.path.splitext(path)[1].lower()
    if os.path.isdir(path):
        bag = os.path.exists(os.path.join(path, "metadata.yaml"))
        raise _unread(path, "a ROS 2 bag (a folder)" if bag else "a folder")
    if ext in _NOT_READ:
        raise _unread(path, _NOT_READ[ext])
    data = read_input(path, "recording")
    if ext.lstrip(".") in FORMATS:
        return ext.lstrip("."), data
    fmt = _sniff(data)
    if fmt is None:
        raise _unread(path, f"a `{ext}` file" if ext else "a file without an extension")
    return fmt, data


def final_goal(rec: Trajectory) -> tuple[float, float, float]:
    """The end-effector's position at the last sample: the goal of ``goal="final"``."""
    from ..robot.batch_fk import batch_fk
    from ..robot.load import load_arm

    arm = load_arm(rec.robot, rec.ee_frame, rec.package_dirs, rec.ee_definition)
    cols = rec.columns(arm.joint_names)
    pos, _ = batch_fk(arm, np.asarray(rec.q, float)[-1:, cols])
    return (float(pos[0, 0]), float(pos[0, 1]), float(pos[0, 2]))


def _other_arm(rec: Trajectory, robot: str, package_dirs: tuple[str, ...]) -> bool:
    """Whether ``robot`` moves joints the recording lacks (it is another arm)."""
    from ..robot.load import load_robot

    return not set(load_robot(robot, package_dirs).spec.arm_joints) <= set(rec.joint_names)


def read_recording(path: str, *, robot: str | None = None,
                   goal: tuple[float, float, float] | str | None = None,
                   ee_frame: str | None = None, angle_unit: str | None = None,
                   time_unit: str | None = None,
                   package_dirs: tuple[str, ...] = (),
                   columns: Mapping[str, str] | None = None) -> Trajectory:
    """Read a ``.json`` or ``.npz`` trajectory or a ``.csv`` recording (a file of another
    extension by its content: a JSON object, a zip, or a CSV whose header starts with
    ``t``).

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
            is refused too, and so are times on which the joints move more than ten times
            faster than their velocity limits (seconds read as milliseconds).
        package_dirs: folders of the robot's ``package://`` meshes, kept with the motion.
        columns: the file's columns renamed to the robot's joints (``--map``,
            :mod:`.columns`), before anything is judged.

    Raises:
        AouError: I501 when the file cannot be read or is in a format aou does not read
            (a ROS 2 bag, a YAML message, any text that is no trajectory); R401 for a
            malformed trajectory
            (with the row or sample); R404 for implausible units.
    """
    fmt, data = _format(path)
    text = "" if fmt == "npz" else decode(data, path)
    if fmt == "csv":
        rec, where, trusted = _read_csv(path, text, robot,
                                        None if isinstance(goal, str) else goal, ee_frame)
    else:
        rec, header = (_npz(path, data, goal is None) if fmt == "npz"
                       else _json(path, text, goal is None))
        trusted = header.generator.startswith("aouc")
        where = Where(path, text=text if fmt == "json" else None)
    if columns:
        from .columns import renamed

        rec = renamed(rec, columns)
    changes: dict[str, Any] = {k: v for k, v in (("robot", robot), ("ee_frame", ee_frame),
                                                 ("package_dirs", tuple(package_dirs))) if v}
    if robot and robot != rec.robot and not ee_frame and _other_arm(rec, robot, package_dirs):
        changes["ee_frame"] = None  # the file's frame is its own arm's: say the joints first
    if goal is not None and not isinstance(goal, str):
        changes["goal"] = tuple(float(x) for x in goal)
    rec = rec.with_(**changes) if changes else rec
    _check_clock(rec.t, where)  # before the units are judged: they divide by the steps
    rec = check_units(rec, angle_unit, time_unit, trusted, where)
    _check_clock(rec.t, where)
    if isinstance(goal, str):
        if goal != "final":
            raise AouError(diag(R405, f"unknown goal `{goal}`: give X,Y,Z or `final`",
                                Span.whole_file(path), severity=Severity.ERROR))
        rec = rec.with_(goal=final_goal(rec))
    return rec
