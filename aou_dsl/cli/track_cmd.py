"""``--track`` of ``aouc check`` and ``aouc compile``: the plan tracked through the arm's
servos in each mode (:mod:`aou_dsl.safety.track_report`), printed as a table, its
diagnostics (C322, C323), and with ``--tracked FILE`` the tracked motion of the chosen
mode written as a recording ``aouc measure`` reads."""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from collections.abc import Iterator, Sequence
from typing import IO

import numpy as np

from ..core.diagnostics import AouError, Diagnostic, Span
from ..version import __version__

__all__ = ["check_tracking", "compile_tracked", "format_tracking", "guard_tracked",
           "nothing_to_track", "run_tracking", "tracked_document"]


def guard_tracked(args: argparse.Namespace, reads: Sequence[str],
                  written: Sequence[str] = ()) -> None:
    """``--tracked FILE`` before any work: refused without ``--track`` (nothing would be
    tracked, so nothing written: a silent exit 0 would leave the user waiting for a
    file), else the output rule of ``-o`` against the files the command ``reads`` and
    the ``written`` outputs, its hint naming ``--tracked``.

    Raises:
        AouError: I504 without ``--track``; I502 naming the clash.
    """
    from ..core.codes import I504
    from ..core.diagnostics import diag
    from ..core.files import apart_from, guard_output

    dest = getattr(args, "tracked", None)
    if not dest:
        return
    if not getattr(args, "track", False):
        raise AouError(diag(I504, f"--tracked {dest} needs --track: without it nothing is "
                            "tracked, so nothing would be written",
                            Span.whole_file("<command line>"),
                            hint="add --track, or leave out --tracked"))
    guard_output(dest, reads, flag="--tracked")
    apart_from(dest, written, "the tracked motion", "--tracked")


@contextlib.contextmanager
def nothing_to_track(args: argparse.Namespace) -> Iterator[None]:
    """Around the compile of ``aouc check FILE.aou --track``: when the arm refuses the
    file, the motion as declared is tracked as a what-if where only the arm's limits
    refuse it (:mod:`.track_whatif`); else there is no motion to track. Say which
    before its errors, and what gives one: the
    command with ``--fit`` when every error is one the fit changes (a value the arm
    cannot give), else that the errors must be mended first (``--fit`` would refuse
    too). Errors that are not the arm's refusal (the file's own, a missing file) speak
    for themselves."""
    try:
        yield
    except AouError as err:
        if getattr(args, "track", False) and args.path.endswith(".aou"):
            from .track_whatif import what_if_tracking

            shown = what_if_tracking(args, list(err.diagnostics), format_tracking)
            note = _refusal_note(args, err.diagnostics, what_if=shown)
            if note:
                print(note, file=sys.stderr)
        raise


def _refusal_note(args: argparse.Namespace, diagnostics, what_if: bool = False
                  ) -> str | None:
    import shlex

    from ..core.diagnostics import Severity
    from ..fit.plan import FITTED

    errors = [d for d in diagnostics if d.severity is Severity.ERROR]
    if not errors or not any(d.code.startswith("C") for d in errors):
        return None
    head = ("aouc check --track: the tracking above is a what-if, the arm refuses the "
            "behaviour as written" if what_if else
            "aouc check --track: nothing to track, the arm refuses the behaviour as written")
    other = sorted({d.code for d in errors if d.code not in FITTED})
    if other:
        return (f"{head} (below), and --fit cannot change what {', '.join(other)} "
                "refuses: mend that first")
    refused = _fit_refusal(args)
    if refused is not None:
        return (f"{head} (below), and --fit cannot keep the behaviour's look on this arm "
                f"either: {refused.code} {refused.message}")
    robot = f" --robot {shlex.quote(args.robot)}" if getattr(args, "robot", None) else ""
    servo = f" --servo {args.servo}" if getattr(args, "servo", "position") != "position" \
        else ""
    lines = sorted({d.span.line for d in errors})
    return (f"{head} (below). --fit changes the values it cannot give (line"
            f"{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))}) and tracks the "
            f"fitted motion: aouc check {shlex.quote(args.path)}{robot} --fit --track{servo}")


def _fit_refusal(args: argparse.Namespace) -> Diagnostic | None:
    """The first error of ``--fit`` on the same file and arm, or None when the fit gives
    a motion: the note points to ``--fit --track`` only where that command tracks."""
    from ..core.diagnostics import Severity
    from ..driver.builder import build_file
    from ..fit.plan import FITTED

    res = build_file(args.path, robot=getattr(args, "robot", None), check=False, fit=True)
    if res.ok:
        return None
    errors = [d for d in res.diagnostics if d.severity is Severity.ERROR]
    # the fit's own reason first: the arm's refusal (a FITTED code) is already printed
    return next((d for d in errors if d.code not in FITTED), errors[0] if errors else None)


_SHORT = {"position": "position", "feedforward": "feedforward", "torque": "torque"}




def _v(v) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def _change(c: dict) -> str:
    """One change of the fit in words: ``shiver frequency 2.5Hz -> 1.1Hz``."""
    what = c.get("descriptor") or {"f": "shiver frequency", "for": "shiver duration",
                                   "a": "acceleration", "v": "tilt velocity",
                                   "length": "approach distance",
                                   "angle": "angle"}.get(c.get("key", ""), c.get("key", ""))
    unit = c.get("unit") or ""
    was = f"{c['declared']}{unit}" if c.get("declared") not in (None, "") else "the default"
    return f"{what} {was} -> {c.get('fitted')}{unit} (line {c.get('line')})"


def _share(v, share: float | None, ok: bool) -> str:
    text = f"{share:.0%}" if share is not None else _v(v)
    return text + ("*" if ok else " ")


def _at_risk_lines(report) -> list[str]:
    """What each mode shows of each descriptor at risk, as a share of the declared
    value, and the modes that keep it."""
    rows = report.at_risk()
    if not rows:
        return ["  no descriptor is at risk: every mode shows what the plan shows"]
    lines = ["  what the arm shows of each descriptor at risk (share of the declared value; "
             "* within tolerance):"]
    decls = []
    for a in rows:
        decl = _v(a.declared) + (f" {a.unit}" if a.unit else "")
        decls.append(decl + (f" (written {_v(a.written)})" if a.written != a.declared
                             else ""))
    width = max(len("declared"), *map(len, decls))
    head = "".join(f" {m:>12s}" for m in (r.mode for r in report.results))
    lines.append(f"  {'descriptor':24s} {'declared':>{width}s}{head}  kept by")
    for a, decl in zip(rows, decls, strict=True):
        cells = "".join(f" {_share(*a.shown[r.mode]):>12s}" for r in report.results)
        lines.append(f"  {a.name:24s} {decl:>{width}s}{cells}  "
                     + (", ".join(a.keeps) if a.keeps else "no mode"))
    return lines


def format_tracking(report) -> str:
    """The report as text: the servo, the fit's changes (a fitted behaviour), each
    mode's tracking error, every descriptor declared beside what each mode gives, what
    each mode shows of the descriptors at risk, and what becomes of the shiver. No
    timing: the same plan gives the same text."""
    from ..safety.track_report import MODE_WORDS, SHIVER

    s = report.servo
    lines = [f"tracked through the servos of {report.robot} at {s.rate:g} Hz "
             f"({s.source}), {report.duration:.2f} s of motion"]
    if report.fitted:
        lines.append("  fitted to the arm before tracking (the arm refuses the file as "
                     "written): " + "; ".join(_change(c) for c in report.fitted)
                     + ". What follows is the fitted motion, judged against the fitted text.")
    if "feedforward" in [r.mode for r in report.results] and not any(s.kv):
        lines.append("  this servo table has no velocity gain (kv 0 on every joint): the "
                     "velocity feed-forward sends changes nothing in the simulation, so "
                     "feedforward reads as position; a drive with a velocity loop differs")
    lines.append(f"  {'mode':12s} max tracking error per joint [deg]")
    for r in report.results:
        k = r.tracked
        err = " ".join(f"{x:.3g}" for x in np.degrees(k.error_max))
        mark = " (chosen)" if r.mode == report.selected else ""
        if r.mode not in s.modes:
            mark += " (not offered by the arm's controller)"
        lines.append(f"  {r.mode:12s} {err}{mark}")
    if report.plan is not None:
        head = "".join(f" {_SHORT[r.mode]:>13s}" for r in report.results)
        lines.append(f"  {'descriptor':24s} {'declared':>9s} {'tolerance':>10s} {'plan':>9s}"
                     f"{head}")
        for i, w in enumerate(report.plan.rows):
            tol = "-" if w.tolerance is None else (
                "exact" if w.tolerance == 0 else f"+-{w.tolerance:.3g}")
            cells = ""
            for r in report.results:
                x = r.verdict.rows[i]
                cells += f" {_v(x.measured):>8s} {'pass' if x.ok else 'FAIL'}"
            lines.append(f"  {w.name:24s} {_v(w.declared):>9s} {tol:>10s} "
                         f"{_v(w.measured):>9s}{cells}  {w.unit}")
        for r in report.results:
            n = sum(x.ok for x in r.verdict.rows)
            cv = r.verdict.measured_cv
            lines.append(f"  {r.mode}: {n} of {len(r.verdict.rows)} descriptors within "
                         f"tolerance; reads as {cv.state.value} (C={cv.C:+.2f} "
                         f"V={cv.V:+.2f})")
        lines += _at_risk_lines(report)
        shiver = next((a for a in report.at_risk() if a.name == SHIVER), None)
        if shiver is not None:
            parts = [f"{(shiver.shown[r.mode][1] or 0.0):.0%} under {MODE_WORDS[r.mode]}"
                     for r in report.results]
            what = f"{_v(shiver.declared)} deg declared"
            if shiver.written != shiver.declared:
                what += f", {_v(shiver.written)} deg written"
            freq = [c for c in report.fitted if c.get("key") == "f"]
            if freq:
                what += (f"; fitted from {freq[0]['declared']} Hz to {freq[0]['fitted']} Hz: "
                         "a slower shiver than the file's")
            keep = shiver.keeps
            lines.append(f"  the shiver ({what}): the arm shows "
                         + "; ".join(parts) + ". "
                         + (f"Kept by: {', '.join(keep)}." if keep
                            else "No servo mode of this arm keeps it."))
    return "\n".join(lines)


def tracked_document(report, mode: str) -> dict:
    """The tracked motion of ``mode`` as an ``aou-trajectory/1`` recording (positions
    only, as a logged arm gives them), with what tracked it."""
    tr = report.result(mode).tracked.trajectory
    return {"format": "aou-trajectory/1", "generator": f"aouc {__version__}",
            "robot": tr.robot, "ee_frame": tr.ee_frame, "joint_names": list(tr.joint_names),
            **({"goal": {"position": [float(x) for x in tr.goal]}} if tr.goal is not None
               else {}),
            "tracked": {"servo_mode": mode, "rate_hz": report.servo.rate,
                        "servo_source": report.servo.source},
            "t": [float(x) for x in tr.t], "q": tr.q.tolist()}


def run_tracking(args: argparse.Namespace, tr, behaviour, *, reads: Sequence[str],
                 out: IO[str] | None, written=None, fitted=()
                 ) -> tuple[list[Diagnostic], dict | None]:
    """Track ``tr`` (judged against ``behaviour``, a lint or None), print the report on
    ``out`` (None: not printed; it is returned as JSON), write ``--tracked``. For a
    fitted behaviour, ``written`` is the lint of the file as written and ``fitted`` the
    fit's changes (the report shows both beside the fitted values).

    Returns:
        the diagnostics (C322, C323) and the report as JSON.

    Raises:
        AouError: what tracking or writing raises.
    """
    from ..compiler.output import encode
    from ..core.files import guard_output, write_atomic
    from ..safety.track_report import track_modes

    dest = getattr(args, "tracked", None)
    if dest:  # checked before any work (guard_tracked); again here, as it is written
        guard_output(dest, reads, flag="--tracked")
    report = track_modes(tr, behaviour, selected=args.servo, written=written, fitted=fitted)
    robot_span = Span.whole_file("<command line>" if getattr(args, "robot", None)
                                 else tr.path)
    diags = report.diagnostics(robot_span)
    if out is not None:
        print(format_tracking(report), file=out)
    if dest:
        doc = tracked_document(report, args.servo)
        fmt = "csv" if dest.lower().endswith(".csv") and "goal" in doc else "json"
        data = encode(doc, "csv") if fmt == "csv" else (json.dumps(doc) + "\n").encode()
        write_atomic(dest, data, inputs=reads)
    return diags, report.to_json()



def check_tracking(args: argparse.Namespace, tr, reads: Sequence[str]
                   ) -> tuple[list[Diagnostic], dict | None]:
    """``aouc check --track``: a ``.aou`` file's motion judged against it, a trajectory
    file's tracking error alone; the report on standard output (text) or returned (JSON).

    Raises:
        AouError: what cannot be tracked or written (the command's exit says which).
    """
    from ..lang.linter import lint_file

    behaviour = lint_file(args.path) if args.path.endswith(".aou") else None
    return run_tracking(args, tr, behaviour, reads=reads,
                        out=None if args.format == "json" else sys.stdout)


def compile_tracked(args: argparse.Namespace, res, reads: Sequence[str]):
    """``compile --track``: the report on standard error, its warnings (C322, C323); a
    file whose tracking cannot be simulated fails (nothing written)."""
    from dataclasses import replace

    from ..core.diagnostics import Severity
    from .report import print_diagnostics

    written = None
    if getattr(res, "fitted_source", None) is not None:  # --fit: the file's values too
        from ..core.files import read_text
        from ..lang.linter import lint_source

        try:
            written = lint_source(read_text(res.path), res.path)
        except AouError:  # the file went away since: the fitted values alone
            written = None
    try:
        more, _ = run_tracking(args, res.trajectory, res.lint, reads=reads, out=sys.stderr,
                               written=written,
                               fitted=tuple((res.header or {}).get("fitted") or ()))
    except AouError as err:
        more = list(err.diagnostics)
    print_diagnostics(more, sources={res.lint.path: res.lint.source or ""})
    if any(d.severity == Severity.ERROR for d in more):
        return replace(res, diagnostics=[*res.diagnostics, *more])  # ok: False
    return res
