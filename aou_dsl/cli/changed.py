"""``--changed-since REF``: the behaviours that changed since a git revision.

CI compiles only what a change touched: the files that differ between ``REF`` and the
working tree (committed, staged or not), and the new files git does not ignore. git is
asked with an argument list, never through a shell, and only for names.
"""

from __future__ import annotations

import os
import subprocess

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag

__all__ = ["changed_since"]

#: How long git may take to list the changes [s].
GIT_SECONDS = 60


def _git(args: list[str], ref: str) -> list[str]:
    where = Span.whole_file("<command line>")
    try:
        out = subprocess.run(["git", *args], capture_output=True, timeout=GIT_SECONDS,
                             check=False, stdin=subprocess.DEVNULL)
    except FileNotFoundError:
        raise AouError(diag(I504, "--changed-since needs git, and no `git` command was "
                            "found", where)) from None
    except subprocess.TimeoutExpired:
        raise AouError(diag(I504, f"--changed-since {ref}: git did not answer in "
                            f"{GIT_SECONDS} s", where)) from None
    if out.returncode != 0:
        said = out.stderr.decode("utf-8", "replace").strip().splitlines()
        raise AouError(diag(I504, f"--changed-since {ref}: git cannot compare with it"
                            + (f" ({said[0]})" if said else ""), where,
                            hint="give a revision of this repository, e.g. origin/main or "
                            "HEAD~1, from inside its work tree"))
    return [p for p in out.stdout.decode("utf-8", "surrogateescape").split("\0") if p]


def changed_since(ref: str) -> set[str]:
    """The real paths of the files that changed since ``ref`` or are new and not ignored.

    Raises:
        AouError: I504 when git is missing, is not in a work tree, or does not know
            ``ref``.
    """
    if ref.startswith("-"):  # never an option to git
        raise AouError(diag(I504, f"--changed-since {ref}: a revision does not start with "
                            "`-`", Span.whole_file("<command line>")))
    top = _git(["rev-parse", "--show-toplevel"], ref)[0].strip()
    names = _git(["diff", "--name-only", "-z", "--no-renames", ref, "--"], ref)
    names += _git(["ls-files", "-z", "--others", "--exclude-standard", "--full-name"], ref)
    return {os.path.realpath(os.path.join(top, n)) for n in names}
