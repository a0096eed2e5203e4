"""Track every shipped behaviour on every built-in arm that has a servo table, in each
servo mode its controller offers, and write the figures into docs/checks.md (one row per
arm and behaviour) and docs/robots.md (one row per arm), between the markers.

    python tools/track_table.py            # rewrite both tables
    python tools/track_table.py --check    # exit 1 if a page differs from a new run
    python tools/track_table.py --stdout   # print both tables only

Each behaviour is compiled for the arm (``build_file``); one the arm refuses as written
is fitted (``--fit``) and its row says what the fit changed. The plan is tracked by
:func:`aou_dsl.safety.track_report.track_modes` as ``aouc check --track`` tracks it, and
each cell says what that mode's tracked motion reads as, how much of the shiver it shows,
every descriptor it loses (its share of the declared value) and its largest tracking
error. No timings, no machine paths: the same code gives the same tables.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from aou_dsl.safety.track_report import SHIVER

ROOT = Path(__file__).resolve().parent.parent
BEHAVIOURS = sorted((ROOT / "behaviours").glob("*.aou"))
CHECKS = ROOT / "docs" / "checks.md"
ROBOTS = ROOT / "docs" / "robots.md"
START = "<!-- track-table:start (written by tools/track_table.py; do not edit by hand) -->"
END = "<!-- track-table:end -->"
#: The change of the fit in a row's behaviour cell, by the statement's key.
KEYS = {"f": "shiver frequency", "for": "shiver duration", "a": "acceleration",
        "v": "tilt velocity", "length": "approach distance", "angle": "angle"}


#: Two arms without a servo table, tracked with the generic servo for comparison.
GENERIC = ("kinova", "z1")


def arms() -> list[str]:
    """The built-in arms that have a servo table, in the order ``aouc robot --list``
    gives them, then :data:`GENERIC`."""
    from aou_dsl.core.robot_specs import ROBOTS as BUILT_IN
    from aou_dsl.core.servo_specs import servo_table

    return [r for r in BUILT_IN if servo_table(r) is not None] + list(GENERIC)


def _arm(robot: str) -> str:
    return f"`{robot}`" + (" (generic servo)" if robot in GENERIC else "")


class Refused(str):
    """A behaviour the arm refuses even fitted: the refusal's code, as the row shows it.
    ``what_if``: where only the arm's limits refuse it, the report of its motion as
    declared tracked anyway, as ``aouc check --track`` prints it (else None)."""

    what_if = None


def track(path: Path, robot: str):
    """``path`` compiled for ``robot`` (fitted when the arm refuses it as written) and
    tracked in every mode: the :class:`~aou_dsl.safety.track_report.TrackReport`, or
    :class:`Refused` when the fit cannot keep the behaviour's look on this arm."""
    from aou_dsl.driver.builder import build_file
    from aou_dsl.driver.what_if import declared_motion, refused_by_limits
    from aou_dsl.lang.linter import lint_file, lint_source
    from aou_dsl.safety.track_report import track_modes

    res = build_file(str(path), robot=robot, check=False)
    written = None
    if not res.ok:
        first = res
        res = build_file(str(path), robot=robot, check=False, fit=True)
        if not res.ok:
            codes = sorted({d.code for d in res.diagnostics if str(d.severity) == "error"})
            refused = Refused(", ".join(codes))
            motion = declared_motion(str(path), robot) \
                if refused_by_limits(first.diagnostics) else None
            if motion is not None:
                refused.what_if = track_modes(motion, lint_file(str(path)))
            return refused
        written = lint_file(str(path))
    lint = (lint_source(res.fitted_source, str(path)) if res.fitted_source is not None
            else res.lint)
    fitted = tuple((res.header or {}).get("fitted") or ()) if written is not None else ()
    return track_modes(res.trajectory, lint, written=written, fitted=fitted)


def _pct(share: float) -> str:
    return f"{share * 100:.0f} %"


def _value(v, unit: str) -> str:
    return "absent" if v is None else f"{v:.3g}" + (f" {unit}" if unit else "")


def cell(report, mode: str) -> str:
    """One mode's figures: the state the tracked motion reads as, the shiver's share,
    each descriptor lost with its share, the largest tracking error."""
    import numpy as np

    if mode not in [r.mode for r in report.results]:
        return "not offered"
    r = report.result(mode)
    state = r.verdict.measured_cv.state.value
    declared = report.plan.declared_cv.state.value
    parts = [f"reads {state}" if state == declared else f"reads **{state}**"]
    for a in report.at_risk():
        measured, share, ok = a.shown[mode]
        if a.name == SHIVER or not ok:
            what = _pct(share) if share is not None else _value(measured, a.unit) + (
                " (declared absent)" if a.declared is None else "")
            parts.append(f"{'shiver' if a.name == SHIVER else a.name} {what}"
                         + (" kept" if ok else ""))
    err = float(np.degrees(r.tracked.error_max).max())
    parts.append(f"error {err:.2g} deg" if err >= 1e-3 else "error < 0.001 deg")
    return "; ".join(parts)


def behaviour_cell(path: Path, report) -> str:
    """The behaviour, its declared state, and what the fit changed (a fitted row)."""
    name = path.stem
    state = report.plan.declared_cv.state.value
    text = name if name == state else f"{name} ({state})"
    if report.fitted:
        changes = ", ".join(
            f"{c.get('descriptor') or KEYS.get(c['key'], c['key'])} {c['declared']} -> "
            f"{c['fitted']}{' ' + c['unit'] if c.get('unit') else ''}"
            for c in report.fitted)
        text += f", fitted ({changes})"
    return text


def row(path: Path, robot: str, report=None) -> str:
    """The docs/checks.md row of one behaviour on one arm."""
    from aou_dsl.core.servo_specs import MODES

    report = report or track(path, robot)
    if isinstance(report, Refused):
        head = f"| {_arm(robot)} | {path.stem}, refused even fitted ({report})"
        if report.what_if is None:
            return head + " | " + " | ".join("not tracked" for _ in MODES) + " |"
        return (f"{head}; what-if, tracked as declared | "
                + " | ".join(cell(report.what_if, m) for m in MODES) + " |")
    return (f"| {_arm(robot)} | {behaviour_cell(path, report)} | "
            + " | ".join(cell(report, m) for m in MODES) + " |")


def arm_row(robot: str, reports: dict) -> str:
    """The docs/robots.md row of one arm: per mode, the behaviours whose tracked motion
    keeps its declared state, the descriptors lost, and the fearful shiver's share."""
    from collections import Counter

    from aou_dsl.core.servo_specs import MODES

    refused = sorted(f"{p.stem} ({r})" for p, r in reports.items() if isinstance(r, Refused))
    what_if = {p: r.what_if for p, r in reports.items()
               if isinstance(r, Refused) and r.what_if is not None}
    reports = {p: r for p, r in reports.items() if not isinstance(r, Refused)}
    table = next(iter(reports.values())).servo
    cells = []
    for mode in MODES:
        if mode not in table.modes:
            cells.append("not offered")
            continue
        kept = 0
        lost: Counter[str] = Counter()
        shiver = []
        for path, rep in reports.items():
            r = rep.result(mode)
            kept += r.verdict.measured_cv.state == rep.plan.declared_cv.state
            lost.update(a.name for a in rep.at_risk() if not a.shown[mode][2])
            shiver += [f"{path.stem}'s shiver {_pct(a.shown[mode][1])}"
                       for a in rep.at_risk()
                       if a.name == SHIVER and a.shown[mode][1] is not None]
        for path, rep in what_if.items():  # refused: its motion as declared, a what-if
            shiver += [f"{path.stem}'s shiver {_pct(a.shown[mode][1])} (what-if)"
                       for a in rep.at_risk()
                       if a.name == SHIVER and a.shown[mode][1] is not None]
        what = ", ".join(f"{n} in {k}" for n, k in sorted(lost.items(),
                                                          key=lambda x: (-x[1], x[0])))
        cells.append(f"state kept in {kept} of {len(reports)}"
                     + (f"; {', '.join(shiver)}" if shiver else "")
                     + (f"; lost: {what}" if what else "; nothing lost"))
    arm = _arm(robot) + (f"; refused even fitted: {', '.join(refused)}" if refused else "")
    return f"| {arm} | {table.rate:g} Hz | " + " | ".join(cells) + " |"


def tables() -> tuple[str, str]:
    """(the docs/checks.md table, the docs/robots.md table), each between the markers."""
    from aou_dsl.core.servo_specs import MODES

    head = "| arm | behaviour | " + " | ".join(f"`{m}`" for m in MODES) + " |"
    rule = "|---|---|" + "---|" * len(MODES)
    checks = [START, "", head, rule]
    robots = [START, "", "| arm | controller | " + " | ".join(f"`{m}`" for m in MODES)
              + " |", "|---|---|" + "---|" * len(MODES)]
    for robot in arms():
        reports = {p: track(p, robot) for p in BEHAVIOURS}
        checks += [row(p, robot, rep) for p, rep in reports.items()]
        robots.append(arm_row(robot, reports))
    return ("\n".join([*checks, "", END]) + "\n", "\n".join([*robots, "", END]) + "\n")


def page(text: str, table: str) -> str:
    """``text`` with its table replaced by ``table`` (appended when it has none)."""
    from robots_report import page as between_markers  # this folder, as the script runs

    return between_markers(text, table, START, END)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="compare; exit 1 when one differs")
    p.add_argument("--stdout", action="store_true", help="print the tables only")
    args = p.parse_args(argv)
    new = dict(zip((CHECKS, ROBOTS), tables(), strict=True))
    if args.stdout:
        for table in new.values():
            sys.stdout.write(table + "\n")
        return 0
    stale = 0
    for path, table in new.items():
        old = path.read_text(encoding="utf-8")
        text = page(old, table)
        if args.check:
            if text != old:
                print(f"{path} is out of date: run python tools/track_table.py",
                      file=sys.stderr)
                stale = 1
        else:
            path.write_text(text, encoding="utf-8")
    return stale


if __name__ == "__main__":
    sys.exit(main())
