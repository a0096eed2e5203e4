"""Formatting diagnostics for people and machines: text (with caret), JSON, GitHub."""

from __future__ import annotations

import json
import math
import sys

from ..core.diagnostics import Diagnostic
from ..core.memo import cached

__all__ = [
    "print_diagnostics",
    "format_check",
    "format_github",
    "format_json",
    "format_measured",
    "format_suppressed",
    "format_text",
    "format_timeline",
]


#: The most characters of a source line an excerpt shows.
EXCERPT = 120
@cached(maxsize=2)
def _lines(source: str) -> list[str]:
    """The lines of ``source``, split once however many diagnostics point into it."""
    return source.splitlines()


def _source_excerpt(d: Diagnostic, source: str | None, original: str | None = None
                    ) -> list[str]:
    """The line of ``source`` at ``d`` with a caret. When ``source`` is a fitted text
    and ``original`` the file's, a line the fit changed is said to be the fitted text,
    with the file's own line beside it: it is not what the file says."""
    if not source or d.span.line < 1:
        return []
    lines = _lines(source)
    if d.span.line > len(lines):
        return []
    note = []
    if original is not None:
        was = _lines(original)
        was_line = was[d.span.line - 1] if d.span.line <= len(was) else ""
        if was_line != lines[d.span.line - 1]:
            note = [f"     = the line as fitted, above; the file's line {d.span.line} says "
                    f"`{was_line.strip()[:EXCERPT]}`"]
    text = lines[d.span.line - 1].expandtabs(1)
    width = (d.span.end_col - d.span.col) if d.span.end_line == d.span.line else len(text)
    width = max(1, min(width, len(text) - d.span.col + 2, EXCERPT))
    col = d.span.col
    if len(text) > EXCERPT:  # a long line (a JSON file given as .aou): the part around col
        start = max(0, min(col - 1 - EXCERPT // 4, len(text) - EXCERPT))
        text = ("..." if start else "") + text[start:start + EXCERPT] + (
            "..." if start + EXCERPT < len(text) else "")
        col -= start - (3 if start else 0)
    gutter = f"{d.span.line:>4} | "
    return [gutter + text, " " * (len(gutter) - 2) + "| " + " " * (col - 1) + "^" * width,
            *note]


def format_text(d: Diagnostic, source: str | None = None, original: str | None = None
                ) -> str:
    """``path:line:col: CODE [severity] message``, the source line with a caret, the hint.
    ``original``: the file's text when ``source`` is its fitted text (``--fit``)."""
    out = [f"{d.span}: {d.code} [{d.severity}] {d.message}"]
    out += _source_excerpt(d, source, original)
    if d.hint:
        out.append(f"     = hint: {d.hint}")
    return "\n".join(out)


def format_suppressed(path: str, suppressed: dict) -> str | None:
    """The line saying how many diagnostics of a file were not shown (None: all were)."""
    n = sum(suppressed.values())
    if not n:
        return None
    from ..lang.linter import MAX_DIAGNOSTICS

    parts = ", ".join(f"{v} {k}{'s' * (v != 1)}" for k, v in suppressed.items() if v)
    return (f"{path}: {n} more diagnostic{'s' * (n != 1)} not shown ({parts}); at most "
            f"{MAX_DIAGNOSTICS} are kept per file, the most severe first")


def format_github(d: Diagnostic) -> str:
    """A GitHub Actions workflow command, shown as an annotation on the pull request."""
    level = {"error": "error", "warning": "warning", "note": "notice"}[str(d.severity)]
    msg = d.message + (f" ({d.hint})" if d.hint else "")
    msg = msg.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    return (f"::{level} file={d.span.path},line={d.span.line},col={d.span.col},"
            f"endLine={d.span.end_line},endColumn={d.span.end_col},"
            f"title={d.code} {d.rule.name}::{msg}")


def format_json(payload: object) -> str:
    return json.dumps(payload, indent=2, sort_keys=False)


def _along(e) -> str:
    return f"distance {e.start.d:.3f} -> {e.end.d:.3f} m (a={e.a:g} m/s^2)"


def _bearing(e) -> str:
    a0, a1 = (e.start.h, e.end.h) if e.plane == "horizontal" else (e.start.v, e.end.v)
    return (f"{e.plane} bearing {math.degrees(a0):+.1f} -> {math.degrees(a1):+.1f} "
            f"deg at {e.start.d:.3f} m")


def _roll(e) -> str:
    return f"roll {math.degrees(e.start.roll):+.1f} -> {math.degrees(e.end.roll):+.1f} deg"


def _oscillation(e) -> str:
    return f"shiver {math.degrees(e.amplitude):g} deg peak to peak at {e.f:g} Hz"


def _hold(e) -> str:
    return f"hold at {e.start.d:.3f} m"


def _generic(e) -> str:
    """A plugin kind's episode: where it goes, and the values it shows (its kind's
    ``episode_values``), each as the kind names it."""
    from ..lang.primitives import KINDS

    what = (f"distance {e.start.d:.3f} -> {e.end.d:.3f} m" if e.moving
            else f"at {e.start.d:.3f} m")
    try:
        shown = KINDS[e.kind].episode_values(e)
    except Exception:  # a plugin's kind may fail in any way: show where it goes only
        shown = {}
    values = ", ".join(f"{k}={v:.4g}" for k, v in shown.items() if isinstance(v, int | float))
    return f"{what} ({values})" if values else what


@cached(maxsize=1)
def _what_moves() -> dict:
    """What ``aouc explain`` says moves in an episode, by kind (the built-ins; a plugin's
    kind is described by :func:`_generic`)."""
    from ..lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

    return {APPROACH: _along, RETREAT: _along, GAZE: _bearing, TILT: _roll,
            SHIVER: _oscillation, PAUSE: _hold}


def format_timeline(behaviour, cv, timeline) -> str:
    """``aouc explain``: the behaviour, its C-V point, and one line per episode."""
    b = behaviour
    declared = f"declared {b.state}" if b.state else "no state declared"
    w = max([9, *(len(e.kind) + 1 for e in timeline.episodes)])  # a plugin's longer name
    lines = [f"behaviour {b.name} ({declared}; {b.form} form) on {b.settings.robot}",
             f"C-V point: C={cv.C:+.2f} V={cv.V:+.2f} -> {cv.state}; laid out as "
             f"{timeline.state}",
             f"{'#':>3}  {'episode':<{w}}{'start':>8}{'dur':>8}  what moves"]
    t = 0.0
    for i, e in enumerate(timeline.episodes, 1):
        what = _what_moves().get(e.kind, _generic)(e)
        lines.append(f"{i:>3}  {e.kind:<{w}}{t:>7.2f}s{e.duration:>7.2f}s  {what}  "
                     f"(line {e.span.line})")
        t += e.duration
    lines.append(f"planned duration {t:.2f} s (moving episodes at the declared limits; "
                 "`aouc compile` may slow them to the joint limits)")
    return "\n".join(lines)


def format_check(path: str, robot: str, t, report) -> str:
    """``aouc check``: each check, pass or fail, its worst sample; clearances; agreement."""
    lines = [f"{path}: {robot}, {t[-1] - t[0]:.2f} s, {len(t)} samples"]
    for c in report.checks:
        mark = "pass" if c.ok else "FAIL"
        where = "" if c.time is None else f" worst at t={c.time:.3f}s"
        who = f" {c.joint}" if c.joint else ""
        val = "" if c.value is None else f" value {c.value:.4g}"
        lim = "" if c.limit is None else f" limit {c.limit:.4g}"
        lines.append(f"  {mark}  {c.name:<21}{where}{who}{val}{lim}  ({c.detail})")
    # A check that could not run (no goal, no target) is n/a, as its clearance below.
    lines += [f"  n/a   {c.name:<21} ({c.detail})" for c in report.not_run]
    lines.append("  clearances: " + ", ".join(
        f"{k} {'n/a' if v is None else f'{v * 1000:.1f} mm'}"
        for k, v in report.clearances.items()))
    ag = report.agreement
    lines.append(f"  PyBullet vs Pinocchio end-effector: {ag['position_mm']:.2e} mm, "
                 f"{ag['rotation_deg']:.2e} deg")
    if report.dynamic:
        d = report.dynamic
        lines.append(f"  dynamic replay at {d['physics_rate_hz']:.0f} Hz: tracking max "
                     f"{d['tracking_max_rad']:.2e} rad, RMS {d['tracking_rms_rad']:.2e} rad; "
                     f"peak torque {d['torque_max_ratio'] * 100:.0f} % of the effort limit "
                     "(inverse dynamics)")
    return "\n".join(lines)


def _interval(value, spread, noisy: bool = False) -> str:
    """A descriptor's 95 % interval beside its value: ``+- x`` around a value (``+0.1
    -0.02`` when lopsided), ``4..6`` for a count or a presence the noise can flip,
    ``exact`` for a value read without noise, ``in every copy`` for a count every
    re-noised copy of a ``noisy`` recording reads alike."""
    if spread is None:
        return ""
    lo, hi = spread.low, spread.high
    if value is None and spread.stable:
        return ""
    if value is None or isinstance(value, int) and not isinstance(value, bool):
        if lo == hi and spread.stable:  # read alike by every copy of a noisy recording
            return "in every copy" if noisy else "exact"

        def v(x) -> str:
            return "absent" if x is None else (f"{x:.4g}" if isinstance(x, float) else str(x))
        return f"({v(lo)}..{v(hi)})"
    if lo is None or hi is None:
        return "(unstable)"
    return about(value, lo, hi) or "exact"


def about(value: float, low: float, high: float) -> str:
    """The interval ``low..high`` about ``value``: ``+- x`` when its two sides are within
    a tenth of each other, else ``+up -down``; empty for none at all."""
    up, down = high - value, value - low
    if up <= 0 and down <= 0:
        return ""
    if abs(up - down) <= 0.1 * max(up, down):
        return f"+- {max(up, down):.2g}"
    return f"+{up:.2g} -{down:.2g}"


def _around(value: float, spread) -> str:
    """`` +- x`` (or `` +x -y``) after a value the noise leaves uncertain; nothing for an
    exact one or none known."""
    if spread is None or spread.low is None or spread.high is None or spread.sd is None:
        return ""
    text = _interval(value, spread)
    return "" if text == "exact" else f" {text}"


def cv_text(m) -> str:
    """The C-V point a measurement ``m`` infers, with its intervals, the states the
    re-noised copies read when they differ, and the values not to be trusted it was
    read from."""
    inf = m.inferred
    point = (f"C={m.cv.C:+.2f}{_around(m.cv.C, inf and inf.C)} "
             f"V={m.cv.V:+.2f}{_around(m.cv.V, inf and inf.V)} -> {m.cv.state}")
    if inf is not None and len(inf.states) > 1:  # the noise can flip the state
        point += f" (the re-noised copies read {', '.join(inf.states)})"
    untrusted = [k for k, v in (dict(m.descriptors) | m.extra).items()
                 if v is not None and k in m.uncertainty and not m.uncertainty[k].stable]
    if untrusted:  # a point read from a guess is a guess, however narrow its interval
        point += f"; read from values not to be trusted ({', '.join(untrusted)})"
    return point


def format_measured(path: str, robot: str, measured, missing: tuple[str, ...] = ()) -> str:
    """``aouc measure``: the eleven descriptors as a table, and the C-V point; ``missing``:
    the descriptors the point could not use (:func:`aou_dsl.lang.cv.missing_descriptors`)."""
    m = measured
    n = len(m.episodes)
    lines = [f"{path}: {robot}, {m.duration:.2f} s, {n} episode{'' if n == 1 else 's'}"]
    from ..lang.descriptors import REGISTRY
    from ..measuring.episodes import COMPUTED_NOISE
    from ..measuring.recognisers import extra_descriptors

    units = {k: d.unit for k, d in REGISTRY.items()}
    units |= {d.name: d.unit for d in extra_descriptors() if d.name in m.extra}
    untrusted = [k for k, v in (dict(m.descriptors) | m.extra).items()
                 if v is not None and k in m.uncertainty and not m.uncertainty[k].stable]
    for k, v in (dict(m.descriptors) | m.extra).items():  # the plugins' after the eleven
        val = "null" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))
        spread = _interval(v, m.uncertainty.get(k), m.noise > COMPUTED_NOISE)
        lines.append(f"  {k:<22} {val:>10} {spread:<14} "
                     f"{units.get(k, '')}{'  not to be trusted' if k in untrusted else ''}"
                     .rstrip())
    los, inf = m.line_of_sight, m.inferred
    if los is not None and len(los.angle):
        # The model assumes the hand looks at the goal throughout: how far it did not.
        lines.append(f"  line of sight off the goal: median {los.median:.3g}"
                     f"{_around(los.median, inf and inf.sight_median)} deg, "
                     f"max {los.max:.3g}{_around(los.max, inf and inf.sight_max)} deg")
    point = f"  C-V: {cv_text(m)}"
    if missing:  # no state named: a point without the gazes would mislead
        point = (f"  C-V: not placed: without a goal the gaze descriptors "
                 f"{', '.join(missing)} are unknown, and the point needs them (give "
                 f"--goal X,Y,Z, or --goal final); read without them, C={m.cv.C:+.2f} "
                 f"V={m.cv.V:+.2f}")
    lines.append(point)
    return "\n".join(lines)


def print_diagnostics(diags: list[Diagnostic], fmt: str = "text",
                 sources: dict[str, str] | None = None, stream=None,
                 originals: dict[str, str] | None = None) -> None:
    """Each diagnostic on ``stream`` (standard error), as text with its source line, or
    as a GitHub annotation. ``originals``: the files' own texts, where ``sources`` holds
    their fitted texts."""
    stream = stream or sys.stderr
    for d in diags:
        text = format_github(d) if fmt == "github" else format_text(
            d, (sources or {}).get(d.span.path), (originals or {}).get(d.span.path))
        print(text, file=stream)
