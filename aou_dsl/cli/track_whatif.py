"""``aouc check FILE.aou --track`` where the arm's limits refuse the file: the motion as
declared (:mod:`aou_dsl.driver.what_if`) tracked through the arm's servos in each mode,
printed as the same table as a tracked plan under words saying it is a what-if. The
servos' force limits hold in the simulation; the file still fails (its refusals are
printed, the exit is theirs), and no ``--tracked`` recording is written of it."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from ..core.codes import C323
from ..core.diagnostics import Diagnostic, Span

if TYPE_CHECKING:
    from ..safety.track_report import TrackReport

__all__ = ["WHAT_IF", "what_if_tracking"]

#: The first words of the what-if's report.
WHAT_IF = "what if"


def what_if_tracking(args: argparse.Namespace, diagnostics: list[Diagnostic],
                     format_tracking: Callable[[TrackReport], str]) -> bool:
    """Print the what-if report (as ``format_tracking`` writes a tracked plan's) when
    every error of ``diagnostics`` is a refusal of the arm's velocity, acceleration or
    jerk limits and the motion as declared can be planned with them lifted; text
    output only. Whether it was printed."""
    from ..driver.what_if import LIMIT_REFUSALS, declared_motion, refused_by_limits
    from ..lang.linter import lint_file
    from .report import print_diagnostics

    if args.format == "json" or not refused_by_limits(diagnostics):
        return False
    tr = declared_motion(args.path, getattr(args, "robot", None),
                         tuple(getattr(args, "package_dir", None) or ()))
    if tr is None:
        return False
    from ..safety.track_report import track_modes

    report = track_modes(tr, lint_file(args.path), selected=args.servo)
    codes = ", ".join(sorted({d.code for d in diagnostics if d.code in LIMIT_REFUSALS}))
    print(f"{WHAT_IF}: the arm's limits refuse this motion ({codes}, below); tracked as "
          "declared, planned without the arm's velocity, acceleration and jerk limits, "
          "it is what the servos would show if the controller were sent it anyway (their "
          "force limits hold). The file still fails.", file=sys.stdout)
    print(format_tracking(report), file=sys.stdout)
    sys.stdout.flush()
    # what is said of the arm (no servo table of its own), not of the what-if's motion
    # (its descriptors under tracking are in the table, and the file fails already)
    where = Span.whole_file("<command line>" if getattr(args, "robot", None)
                            else args.path)
    print_diagnostics([d for d in report.diagnostics(where) if d.code == C323])
    return True
