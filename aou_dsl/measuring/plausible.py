"""Units of a recording: the ones given are applied, and the values are judged against
the robot, so that a wrong unit is refused (R404) instead of measured into nonsense.

- Angles are judged by the joint limits: values outside them that would be inside read
  as degrees look like degrees; a unit given that leaves a joint beyond its limits at
  every sample contradicts the robot.
- Times are judged by the clock and by the joint velocity limits: a clock slower than
  :data:`SLOWEST_STEP` looks like milliseconds; joints that move, read on the time unit
  given, many times faster than their velocity limits (:data:`FASTEST`) are read on too
  small a time unit (seconds read as milliseconds).

The reverse of the last, milliseconds read as seconds, makes the motion a thousand times
slower, and a slow motion is no contradiction: an arm may move slowly, or hardly at all,
and 10 kHz in milliseconds reads as 10 Hz, a rate loggers use. Only the clock gives it
away: a logger of up to 5 kHz in milliseconds has steps of 0.2 ms or more, read as
seconds slower than :data:`SLOWEST_STEP`. A faster one read as seconds is not refused.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.diagnostics import AouError, Span, diag
from ..core.trajectory import Trajectory
from .locate import Where
from .signal import joint_noise

__all__ = ["ANGLE_UNITS", "BEYOND", "FASTEST", "SLOWEST_STEP", "TIME_UNITS", "check_units"]

ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
#: A clock slower than this [s per sample] is taken for milliseconds read as seconds.
SLOWEST_STEP = 0.2
#: How far [rad] beyond its limits a joint may sit throughout under a unit given.
BEYOND = math.radians(1.0)
#: A joint whose typical speed while it moves is this many times its velocity limit is
#: read on a wrong time unit (an arm moves within its limits; a misread unit is off by
#: 1000).
FASTEST = 10.0
#: Samples per window over which speeds are read (noise averages out over a window).
_WINDOW = 8
#: Fewest moving windows a joint needs to be judged by its speed.
_MOVING = 5


def check_units(rec: Trajectory, angle_unit: str | None, time_unit: str | None,
                trusted: bool, where: Where | None = None) -> Trajectory:
    """Convert the units given. R404 for values that look like degrees or milliseconds
    when none is given, for an angle unit that puts a joint outside its limits
    throughout, and for times that make the joints move far faster than they can.
    ``where``: where each sample is in its file (for the spans)."""
    from ..robot.load import load_arm

    where = where or Where(rec.path or "<recording>")
    for unit, table, what in ((angle_unit, ANGLE_UNITS, "angle"),
                              (time_unit, TIME_UNITS, "time")):
        if unit is not None and unit not in table:
            raise AouError(diag("R404", f"unknown {what} unit `{unit}`: expected one of "
                                f"{', '.join(table)}", Span.whole_file(where.path)))
    wrong = [f"--{flag} {unit}" for flag, unit, right in
             (("angle-unit", angle_unit, "rad"), ("time-unit", time_unit, "s"))
             if unit not in (None, right)]
    arm = load_arm(rec.robot, rec.ee_frame)
    if trusted and wrong and _as_written(rec, arm, where):
        raise AouError(diag("R404", f"aou wrote this file, in radians and seconds: "
                            f"{' and '.join(wrong)} would misread it", Span.whole_file(
                                where.path), hint="leave the units out for files aou wrote"))
    t = np.asarray(rec.t, float) * TIME_UNITS[time_unit or "s"]
    if time_unit is None and not trusted:  # aou writes slow clocks too (--rate 1)
        _plausible_clock(t, where)
    q = np.asarray(rec.q, float).copy()
    for j in _revolute(arm):
        name = arm.joint_names[j]
        if name not in rec.joint_names:
            continue
        col = rec.joint_names.index(name)
        limits = (float(arm.lower[j]), float(arm.upper[j]))
        if angle_unit is not None:
            q[:, col] *= ANGLE_UNITS[angle_unit]
            _obeyed_limits(q[:, col], name, limits, angle_unit, where)
        else:  # aou's own files too: an edited one may no longer be in radians
            _plausible_angles(q[:, col], name, limits, where)
    _plausible_speeds(rec, arm, t, q, time_unit, where)
    return rec.with_(t=t, q=q)


def _revolute(arm: Any) -> list[int]:
    return [j for j in range(len(arm.joint_names))
            if arm.model.joints[j + 1].shortname().startswith("JointModelR")]


def _as_written(rec: Trajectory, arm: Any, where: Where) -> bool:
    """Whether the file's angles are plausible in radians as they stand."""
    try:
        for j in _revolute(arm):
            if arm.joint_names[j] in rec.joint_names:
                col = np.asarray(rec.q, float)[:, rec.joint_names.index(arm.joint_names[j])]
                _plausible_angles(col, arm.joint_names[j],
                                  (float(arm.lower[j]), float(arm.upper[j])), where)
    except AouError:
        return False
    return True


def _plausible_clock(t: np.ndarray, where: Where) -> None:
    """R404 when samples come slower than :data:`SLOWEST_STEP` (milliseconds as seconds)."""
    step = np.diff(t)
    if len(step) and float(np.median(step)) >= SLOWEST_STEP:
        i = int(np.argmax(step >= SLOWEST_STEP)) + 1
        raise AouError(diag("R404", f"the times look like milliseconds: one sample every "
                            f"{float(np.median(step)):g} s ({where.label(i)} has t={t[i]:g} "
                            f"after t={t[i - 1]:g})", where.span(i, "t"),
                            hint="give --time-unit ms, or --time-unit s if the clock really "
                            "is that slow", **where.fields(i)))


def _within(col: np.ndarray, lo: float, hi: float, slack: float | None = None) -> np.ndarray:
    """Which values lie in [lo, hi] widened by ``slack`` (default a tenth of the range:
    an offset is not a unit problem); +-2 turns for a joint without finite limits."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = -4 * math.pi, 4 * math.pi
    slack = 0.1 * (hi - lo) if slack is None else slack
    return (col >= lo - slack) & (col <= hi + slack)


def _plausible_angles(col: np.ndarray, name: str, limits: tuple[float, float],
                      where: Where) -> None:
    """R404 when a joint's values leave its limits and read as degrees they would not."""
    inside = _within(col, *limits)
    if inside.all() or not _within(np.radians(col), *limits).all():
        return
    i = int(np.argmin(inside))
    raise AouError(diag(
        "R404", f"joint `{name}` reads {col[i]:g} at {where.label(i)}, outside its limits "
        f"[{limits[0]:.3g}, {limits[1]:.3g}] rad: the angles look like degrees",
        where.span(i), hint="give --angle-unit deg, or --angle-unit rad if they really are "
        "radians", joint=name, **where.fields(i)))


def _obeyed_limits(col: np.ndarray, name: str, limits: tuple[float, float], unit: str,
                   where: Where) -> None:
    """R404 when the angle unit given leaves every sample of a joint beyond its limits
    (by :data:`BEYOND`): the unit contradicts the robot."""
    lo, hi = limits
    if not (math.isfinite(lo) and math.isfinite(hi)) or _within(col, lo, hi, BEYOND).any():
        return
    other = "rad" if unit == "deg" else "deg"
    fits = _within(col / ANGLE_UNITS[unit] * ANGLE_UNITS[other], lo, hi).all()
    raise AouError(diag(
        "R404", f"with --angle-unit {unit}, joint `{name}` reads {col[0]:.4g} rad at "
        f"{where.label(0)} and every one of its {len(col)} samples lies outside its limits "
        f"[{lo:.3g}, {hi:.3g}] rad: the unit given contradicts the robot's limits",
        where.span(0), hint=f"the values fit the limits in {other}: give --angle-unit "
        f"{other}" if fits else "check the unit, and that the recording is of this robot "
        "(--robot)", joint=name, unit=unit, **where.fields(0)))


def moving_speed(t: np.ndarray, col: np.ndarray) -> tuple[float, int] | None:
    """A joint's speed while it moves fast, and a sample where it moves so: over windows
    of :data:`_WINDOW` samples whose displacement stands out of the joint's noise, the
    speed a tenth of them reach (at least :data:`_MOVING` of them: a few glitches cannot
    set it). None when the joint moves in fewer than :data:`_MOVING` windows."""
    noise = float(joint_noise(t, col[:, None]).effective[0])  # white noise and rounding
    at = np.arange(0, len(t), _WINDOW)
    dq, dt = np.abs(np.diff(col[at])), np.diff(t[at])
    moving = (dq > max(6 * math.sqrt(2) * noise, 1e-5)) & (dt > 0)
    n = int(moving.sum())
    if n < _MOVING:
        return None
    speed = dq[moving] / dt[moving]
    reached = float(np.sort(speed)[n - max(_MOVING, n // 10)])
    return reached, int(at[:-1][moving][int(np.argmax(speed >= reached))])


def _plausible_speeds(rec: Trajectory, arm: Any, t: np.ndarray, q: np.ndarray,
                      time_unit: str | None, where: Where) -> None:
    """R404 when a joint, on the time unit given (seconds by default), moves more than
    :data:`FASTEST` times faster than its velocity limit."""
    worst: tuple[float, str, float, float, int] | None = None
    revolute = _revolute(arm)
    for j, name in enumerate(arm.joint_names):
        limit = float(arm.vmax[j])
        if name not in rec.joint_names or not (math.isfinite(limit) and limit > 0):
            continue
        col = q[:, rec.joint_names.index(name)]
        if not (math.isfinite(arm.lower[j]) and arm.upper[j] - arm.lower[j] < 2 * math.pi):
            col = np.unwrap(col)  # a joint that turns without end may be logged wrapped
        read = moving_speed(t, col)
        if read is not None and (worst is None or read[0] / limit > worst[0]):
            worst = (read[0] / limit, name, read[0], limit, read[1])
    if worst is None or worst[0] <= FASTEST:
        return
    ratio, name, speed, limit, i = worst
    per = "rad/s" if arm.joint_names.index(name) in revolute else "m/s"
    if time_unit == "ms":
        given, why = "with --time-unit ms, ", "the times look like seconds"
        hint = (f"leave out --time-unit ms (or give --time-unit s): read in seconds, the "
                f"joint moves at {speed * 1e-3:.3g} {per}")
    else:
        given, why = "", "the times or the angles are not in the units they are read in"
        hint = ("check the units: times in seconds (--time-unit ms for milliseconds), "
                "angles in radians (--angle-unit deg for degrees), and the robot (--robot)")
    raise AouError(diag(
        "R404", f"{given}joint `{name}` moves at {speed:.3g} {per} around {where.label(i)}, "
        f"{ratio:.0f} times its velocity limit of {limit:.3g} {per}: {why}",
        where.span(i, "t"), hint=hint, joint=name, unit=time_unit or "s",
        **where.fields(i)))
