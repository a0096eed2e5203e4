"""What CI asks of ``aouc``: a check's findings as SARIF, the files a change touched, the
batch's findings written as SARIF (docs/ci.md)."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence

from ..core.diagnostics import AouError, Diagnostic, Severity, Span
from ..core.rules import category
from .args import EXIT_ERRORS, EXIT_OK, EXIT_USAGE

__all__ = ["check_sarif", "keep_changed", "no_output_misused", "robot_refusals", "write_sarif"]


def robot_refusals(args: argparse.Namespace, tr) -> list[Diagnostic]:
    """What the arm itself is refused for (a robot file whose meshes collide at rest...)."""
    from ..robot import robot_diagnostics

    named = Span.whole_file("<command line>" if args.robot else args.path)  # the robot
    return robot_diagnostics(tr.robot, collision_check=not args.no_collision_check,
                             span=named, package_dirs=tr.package_dirs)


def check_sarif(args: argparse.Namespace, read_kw: dict, scene_kw: dict,
                failed_checks: Callable[[str, object], list[Diagnostic]]) -> int:
    """``aouc check --format sarif``: the compile's refusals, the arm's and the failed
    checks (``failed_checks(path, report)``) as one SARIF log on standard output,
    whatever the outcome; the exit status as ever."""
    from ..api import check, read_trajectory
    from .sarif import format_sarif

    if args.fit or args.write_fitted:
        print("aouc check: --format sarif does not go with --fit or --write-fitted (a fit "
              "reports a changed text, not findings in the file)", file=sys.stderr)
        return EXIT_USAGE
    found: list[Diagnostic] = []
    try:
        tr = read_trajectory(args.path, **read_kw)
        found += robot_refusals(args, tr)
        if not any(d.severity == Severity.ERROR for d in found):
            found += failed_checks(args.path, check(
                tr, dynamic=not args.no_dynamic, controller=args.controller, **scene_kw))
    except AouError as err:  # refused: the compile's diagnostics are the findings
        found += err.diagnostics
    usage = any(category(d.code).is_usage for d in found)
    sys.stdout.write(format_sarif(found, successful=not usage))
    if usage:
        return EXIT_USAGE
    return EXIT_ERRORS if any(d.severity == Severity.ERROR for d in found) else EXIT_OK


def no_output_misused(args: argparse.Namespace) -> bool:
    """``--no-output`` given with an option that writes (said on standard error)."""
    if args.no_output and (args.output or args.format or args.write_fitted):
        print("aouc compile: --no-output writes nothing, so it takes no -o, --format or "
              "--write-fitted", file=sys.stderr)
        return True
    return False


def keep_changed(inputs: list[tuple[str, str | None]], ref: str,
                 ) -> list[tuple[str, str | None]]:
    """The inputs that changed since the git revision ``ref`` (``--changed-since``)."""
    from .changed import changed_since

    changed = changed_since(ref)
    kept = [i for i in inputs if os.path.realpath(i[0]) in changed]
    n = len(kept)
    print(f"aouc compile: {n} file{'s' * (n != 1)} of {len(inputs)} changed since {ref}",
          file=sys.stderr)
    return kept


def write_sarif(path: str, found: list[Diagnostic], reads: Sequence[str]) -> int:
    """``--sarif FILE``: the batch's diagnostics as a SARIF log, written whole, never over
    an input (I502); the exit status of the writing."""
    from ..core.files import write_atomic
    from .report import print_diagnostics
    from .sarif import format_sarif

    usage = any(category(d.code).is_usage for d in found)
    try:
        write_atomic(path, format_sarif(found, successful=not usage).encode(), inputs=reads)
    except AouError as err:
        print_diagnostics(err.diagnostics)
        return EXIT_USAGE
    return EXIT_OK
