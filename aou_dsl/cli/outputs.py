"""The output rule of ``aouc compile``, for every file it may write, before any work."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from ..core.read_set import ReadSet

__all__ = ["guard_outputs"]


def guard_outputs(args: argparse.Namespace, inputs: list[tuple[str, str | None]],
                  reads: Sequence[str]) -> tuple[list[str | None], str, ReadSet]:
    """Where each input's trajectory goes (None each with ``--no-output``) and in which
    format, after every output (``-o``'s files, ``--write-fitted``, ``--sarif``) is
    checked against the files the command reads and against each other; and those
    files as a :class:`~aou_dsl.core.read_set.ReadSet`, indexed once, so that the rule
    of each output (here, and again when it is written) is a look-up, not a pass over
    every input.

    Raises:
        AouError: I502 (or I506) naming the clash.
    """
    from ..compiler.output import FOLDER_FORMATS, FORMATS, output_paths
    from ..core.files import check_format, guard_output

    reads = ReadSet(reads)
    if args.no_output:
        dests: list[str | None] = [None] * len(inputs)
        fmt = "json"
    else:
        paths, fmt = output_paths(inputs, args.output, args.format)
        dests = list(paths)
    check_format(args.output, args.format, FORMATS)  # --format csv -o x.json
    written = [d for d in dests if d]
    for to in written:
        guard_output(to, reads, bag=fmt in FOLDER_FORMATS)
    if args.write_fitted:  # the same rule, and never onto what -o writes
        from .fitted import check_fitted_output

        check_fitted_output(args.write_fitted, reads, written)
        written.append(args.write_fitted)
    if args.sarif:
        guard_output(args.sarif, [*reads, *written])
    return dests, fmt, reads
