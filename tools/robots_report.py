"""Compile the shipped behaviours on every built-in arm and write what happened into
docs/robots.md (the part between the report markers; the rest of the page is prose).

    python tools/robots_report.py            # rewrite the report in docs/robots.md
    python tools/robots_report.py --check    # exit 1 if the page differs from a new run
    python tools/robots_report.py --stdout   # print the report only

Each behaviour goes through ``aou_dsl.driver.builder.build_file(path, robot=NAME)``: lint, compile,
the safety replay, the measurement. Per arm and behaviour the report says whether it
compiled, whether the checks passed, whether the measured descriptors equal the
declared ones, and for what does not fit, the limit that binds and what the user can
change. The output has no timings and no machine paths, so it is reproducible.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # every_arm.py, beside this
from every_arm import every_arm  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "robots.md"
BEHAVIOURS = sorted((ROOT / "behaviours").glob("*.aou"))
START = "<!-- report:start (written by tools/robots_report.py; do not edit by hand) -->"
END = "<!-- report:end -->"


def _limit(arm, joint: str | None) -> str:
    if joint is None or joint not in arm.joint_names:
        return ""
    return f"{arm.amax[arm.joint_names.index(joint)]:g} rad/s^2"


def _advice(d, arm) -> tuple[str, str]:
    """(the binding limit, what the user can change) for one diagnostic."""
    f = d.fields
    if d.code == "C308":
        limit = f.get("limit", "acceleration")
        fits = (f"shiver at most {f['max_frequency']:g} Hz at this amplitude (or a smaller "
                "amplitude at 2.5 Hz)" if f.get("max_frequency") else
                "no shiver that still looks like one (see --fit)" if f.get("look")
                else "a smaller shiver")
        return (f"{f['joint']} {limit}" + (f" ({_limit(arm, f['joint'])})"
                                           if limit == "acceleration" else ""),
                f"{fits}, or pin a higher `joint_{'accel' if limit == 'acceleration' else limit}`"
                " in a robot description if the controller allows it")
    if d.code == "C304":
        joint = f.get("joint")
        limit = f"{joint} acceleration ({_limit(arm, joint)})" if joint in arm.joint_names \
            else "the speed cap"
        return (limit, f"declare at most {math.floor(f['achieved'] * 100) / 100:g} "
                       "(the arm's peak here), or move the goal (`goal`, `from`)")
    if d.code == "C309":
        return (f"{f.get('joint')} {f.get('limit', 'velocity and acceleration')}",
                f"at most {f['max_velocity']:g} deg/s" if f.get("max_velocity")
                else "a smaller or slower tilt")
    if d.code in ("C301", "C302", "C303"):
        joint = f.get("joint")
        within = "; ".join(f"`{r['statement']}` at line {r['line']}" for r in f.get("reach", ()))
        return (f"{joint} position limit" if joint else "the workspace",
                (f"{within} (within reach), or " if within else "")
                + "move the goal (`goal`) or the start direction (`from`), or shorten the motion")
    if d.code == "C306":
        return (f"{f.get('check')} check", "move the goal or the start direction")
    if d.code == "C311":
        return ("joint jerk", "smoother motion (lower accelerations), or pin `joint_jerk`")
    return (d.code, d.message)


def _row(path: Path, robot: str) -> tuple[str, bool, list[str]]:
    """A table row for one behaviour on one arm, whether all is well, and notes."""
    from aou_dsl.driver.builder import build_file
    from aou_dsl.robot.load import load_arm

    arm = load_arm(robot)
    res = build_file(str(path), robot=robot)
    compiled = res.compiled is not None and res.compiled.trajectory is not None
    ran = bool(res.checks)
    checks = all(c.ok for c in res.checks) if ran else False
    mismatch = [d for d in res.diagnostics if d.code == "C310"]
    measured = res.measured is not None and not mismatch
    problems = [d for d in res.diagnostics if d.code[0] == "C" and d.code not in ("C310",
                                                                                  "C313")]
    notes, binding = [], []
    for d in problems:
        limit, change = _advice(d, arm)
        binding.append(f"{d.code}: {limit}")
        notes.append(f"{path.stem}: {d.code} {d.message}. Change: {change}.")
    if mismatch:
        binding.append("C310: " + ", ".join(d.fields.get("descriptor", "?") for d in mismatch))
        notes += [f"{path.stem}: C310 {d.message}." for d in mismatch]

    def mark(ok: bool, done: bool = True) -> str:
        return "yes" if ok else ("no" if done else "-")

    ok = compiled and checks and measured and not problems
    fit = "-" if ok else _fitted(path, robot, notes)
    row = (f"| {path.stem} | {mark(compiled)} | {mark(checks, ran)} | "
           f"{mark(measured, res.measured is not None)} | {'; '.join(binding) or ''} | "
           f"{fit} |")
    return row, ok, notes


def _fitted(path: Path, robot: str, notes: list[str]) -> str:
    """``yes`` when ``--fit`` makes the behaviour compile, pass the checks and measure as
    its fitted file declares, in the same state; the changes go to ``notes``."""
    from aou_dsl.driver.builder import build_file

    res = build_file(str(path), robot=robot, fit=True)
    changes = [d for d in res.diagnostics if d.code == "C314"]
    same = res.measured is not None and res.lint.cv is not None and \
        res.measured.cv.state == res.lint.cv.state
    good = res.ok and same and not any(d.code == "C310" for d in res.diagnostics)
    look = [d for d in res.diagnostics if d.code == "C315"]
    said = "; ".join(d.message for d in changes) or "nothing fitted"
    if look:  # refused rather than change the kind of motion a person sees
        notes.append(f"{path.stem} with --fit: refused, C315 {look[0].message}.")
        return "refused (C315)"
    notes.append(f"{path.stem} with --fit: {said}.")
    return "yes" if good else "no"


def _arm_section(robot: str) -> tuple[list[str], int, list[str]]:
    from aou_dsl.robot.load import load_robot

    r = load_robot(robot)
    spec = r.spec
    lines = [f"### {robot}", "",
             f"URDF `{spec.urdf}`; end-effector `{spec.ee_link or spec.ee_frame}` "
             f"(forward {spec.forward}), shiver joint `{spec.shiver_joint}`. "
             f"Acceleration limits: {spec.source('joint_accel')}.", "",
             "| behaviour | compiled | checks passed | measured = declared | binding | "
             "with --fit |",
             "|---|---|---|---|---|---|"]
    notes, passing, failing = [], 0, []
    for path in BEHAVIOURS:
        row, ok, more = _row(path, robot)
        lines.append(row)
        notes += more
        passing += ok
        if not ok:
            failing.append(f"{path.stem} ({row.split('|')[-3].strip()})")
    if notes:
        lines += ["", *[f"- {n}" for n in notes]]
    return lines + [""], passing, failing


def report() -> str:
    """The report: a summary table, then one section per arm."""
    from aou_dsl.core.robot_specs import ROBOTS

    sections, summary = [], []
    all_pass, all_fit, status = 0, 0, {}
    for robot in ROBOTS:
        lines, passing, failing = _arm_section(robot)
        sections += lines
        fits = sum(row.endswith("| yes |") for row in lines if row.startswith("| ")
                   and not row.startswith("| behaviour"))
        all_pass += passing == len(BEHAVIOURS)
        all_fit += passing + fits == len(BEHAVIOURS)
        status[robot] = (f"built in: {passing} of {len(BEHAVIOURS)} as declared, "
                         f"{passing + fits} of {len(BEHAVIOURS)} with --fit")
        summary.append(f"| {robot} | {passing} of {len(BEHAVIOURS)} | "
                       f"{passing + fits} of {len(BEHAVIOURS)} | {'; '.join(failing)} |")
    head = [START, "", f"{all_pass} of {len(ROBOTS)} arms compile all {len(BEHAVIOURS)} "
            "shipped behaviours, pass the checks and measure as declared; "
            f"{all_fit} of {len(ROBOTS)} do with --fit (the fitted values stated below"
            + ("; where no fit keeps what a person sees, --fit refuses with C315, the reason"
               " stated below" if "| refused (C315) |" in "\n".join(sections) else "")
            + ").",
            "", "| arm | as declared | as declared or with --fit | the others (binding) |",
            "|---|---|---|---|", *summary, ""]
    return "\n".join(head + every_arm(status) + sections + [END]) + "\n"


def page(text: str, new_report: str, start: str = START, end: str = END) -> str:
    """``text`` with what lies between the markers ``start`` and ``end`` (the report's,
    by default) replaced by ``new_report``, which holds them (appended when the page has
    none). tools/track_table.py writes its tables with it too."""
    if start in text and end in text:
        before = text[:text.index(start)]
        after = text[text.index(end) + len(end):].lstrip("\n")
        return before + new_report + ("\n" + after if after else "")
    return text.rstrip("\n") + "\n\n" + new_report


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="compare; exit 1 when it differs")
    p.add_argument("--stdout", action="store_true", help="print the report only")
    args = p.parse_args(argv)
    new = report()
    if args.stdout:
        sys.stdout.write(new)
        return 0
    old = PAGE.read_text(encoding="utf-8") if PAGE.exists() else ""
    text = page(old, new)
    if args.check:
        if text != old:
            print(f"{PAGE} is out of date: run python tools/robots_report.py", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
