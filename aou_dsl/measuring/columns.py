"""Recordings whose columns are not named as the robot names its joints: ``--map
joint3=panda_joint3,...`` or a mapping file, so that a user need not edit the file.

A mapping names a file's column on the left and the robot's joint on the right. A
mapping file holds one ``column=joint`` per line (``#`` starts a comment; commas may
also separate pairs). Both are untrusted text: a malformed pair, a column named twice,
two columns mapped onto one joint, or a column the file does not have is R401 with
where it is.
"""

from __future__ import annotations

import os
from collections.abc import Mapping

from ..core.codes import I501, R401
from ..core.diagnostics import AouError, Span, diag
from ..core.trajectory import Trajectory

__all__ = ["MAX_MAP_BYTES", "column_map", "renamed"]

#: Largest mapping file read [bytes] (a robot has tens of joints).
MAX_MAP_BYTES = 64 * 1024


def _pairs(text: str, where: str, line_of: dict[int, int] | None = None
           ) -> dict[str, str]:
    out: dict[str, str] = {}
    targets: dict[str, str] = {}
    for n, raw in enumerate(text.splitlines(), 1):
        body = raw.split("#", 1)[0]
        for item in body.split(","):
            item = item.strip()
            if not item:
                continue
            span = (Span.point(where, n, 1) if line_of is None else
                    Span.whole_file(where))
            col, eq, joint = (s.strip() for s in item.partition("="))
            if not eq or not col or not joint or "=" in joint:
                raise AouError(diag(R401, f"a column mapping is `column=joint`, found "
                                    f"`{item}`", span,
                                    hint="e.g. --map joint3=panda_joint3,joint4=panda_joint4"))
            if col in out:
                raise AouError(diag(R401, f"column `{col}` is mapped twice", span))
            if joint in targets:
                raise AouError(diag(R401, f"columns `{targets[joint]}` and `{col}` are both "
                                    f"mapped onto joint `{joint}`", span))
            out[col] = joint
            targets[joint] = col
    if not out:
        raise AouError(diag(R401, "the column mapping maps nothing", Span.whole_file(where),
                            hint="give column=joint pairs"))
    return out


def column_map(spec: str) -> dict[str, str]:
    """The mapping ``--map`` gives: ``column=joint`` pairs separated by commas, or the
    path of a mapping file (a value without ``=``)."""
    if "=" in spec or (not os.path.isfile(spec) and (":" in spec or "," in spec)):
        return _pairs(spec, "<command line>", {})  # pairs (a malformed one is R401)
    if not os.path.isfile(spec):
        raise AouError(diag(I501, f"cannot read the column mapping `{spec}`: no such file "
                            "(give column=joint pairs, or a mapping file)",
                            Span.whole_file(spec)))
    if os.path.getsize(spec) > MAX_MAP_BYTES:
        raise AouError(diag(I501, f"the column mapping `{spec}` is larger than "
                            f"{MAX_MAP_BYTES // 1024} KB: no mapping file is",
                            Span.whole_file(spec)))
    try:
        with open(spec, "rb") as f:
            text = f.read().decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as e:
        raise AouError(diag(I501, f"cannot read the column mapping `{spec}`: {e}",
                            Span.whole_file(spec))) from None
    return _pairs(text, spec)


def renamed(rec: Trajectory, mapping: Mapping[str, str]) -> Trajectory:
    """``rec`` with its columns renamed by ``mapping`` (a file's column -> the robot's
    joint). A column the mapping names that the file lacks, or a renamed column that
    collides with one the file already has, is R401."""
    names = list(rec.joint_names)
    missing = [c for c in mapping if c not in names]
    if missing:
        raise AouError(diag(R401, f"the column mapping names column"
                            f"{'s' if len(missing) > 1 else ''} "
                            f"{', '.join(f'`{c}`' for c in missing)} that `{rec.path}` does "
                            f"not have; it has {', '.join(names)}",
                            Span.whole_file(rec.path)))
    new = [mapping.get(n, n) for n in names]
    kept = [n for n in names if n not in mapping]
    clash = sorted({j for j in mapping.values() if j in kept})
    if clash:
        raise AouError(diag(R401, f"the column mapping renames a column to "
                            f"{', '.join(f'`{j}`' for j in clash)}, which `{rec.path}` "
                            "already has", Span.whole_file(rec.path)))
    return rec.with_(joint_names=tuple(new))
