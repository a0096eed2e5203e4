"""The output rule of ``aouc compile``, for every file it may write, before any work."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..core.read_set import ReadSet

if TYPE_CHECKING:
    from ..driver.builder import BuildResult
    from ..driver.delivery import Outputs

__all__ = ["guard_outputs", "put_output", "where_built"]


def guard_outputs(args: argparse.Namespace, inputs: list[tuple[str, str | None]],
                  reads: Sequence[str]) -> tuple[list[str | None], str, ReadSet]:
    """Where each input's trajectory goes (None each with ``--no-output``) and in which
    format, after every output (``-o``'s files, ``--write-fitted``, ``--tracked``,
    ``--sarif``) is checked against the files the command reads and against each other; and those
    files as a :class:`~aou_dsl.core.read_set.ReadSet`, indexed once, so that the rule
    of each output (here, and again when it is written) is a look-up, not a pass over
    every input.

    Raises:
        AouError: I502 (or I506) naming the clash (``-o`` naming an input is refused as
            that before its format is read), I504 for ``--tracked`` without ``--track``.
    """
    from ..compiler.output import FOLDER_FORMATS, FORMATS, output_paths
    from ..core.files import check_format, guard_output

    reads = ReadSet(reads)
    if args.output and reads.clash(args.output) is not None:
        # an input first, whatever its extension: `-o x.aou` is refused as the file the
        # command reads (the real reason), not as an unknown format
        guard_output(args.output, reads)
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
    if getattr(args, "tracked", None):  # needs --track; never onto what -o writes
        from .track_cmd import guard_tracked

        guard_tracked(args, reads, written)
        written.append(args.tracked)
    if args.sarif:
        guard_output(args.sarif, [*reads, *written], flag="--sarif")
    return dests, fmt, reads


def where_built(args: argparse.Namespace, dests: list[str | None], fmt: str, reads: ReadSet
                ) -> Outputs | None:
    """The outputs a batch may write as it builds (each document by the process that
    built it, named here in input order by :func:`put_output`): files of a byte format,
    unless ``--track`` changes the result first. None: the command writes every output
    itself."""
    from ..compiler.output import FOLDER_FORMATS
    from ..driver.delivery import Outputs

    if args.no_output or fmt in FOLDER_FORMATS or getattr(args, "track", None):
        return None
    return Outputs(tuple(dests), fmt, reads)


def put_output(dest: str | None, res: BuildResult, fmt: str, reads: ReadSet) -> None:
    """``res``'s document at ``dest`` (nothing with ``--no-output``): the file the
    process that built it wrote, named, or else written here.

    Raises:
        AouError: I502 when it cannot be written.
    """
    from .dmp_cmd import write_compiled

    if dest is None:
        return
    if res.staged is not None:
        from ..driver.delivery import name

        name(dest, res, reads)
    else:
        write_compiled(dest, res, fmt, inputs=reads)
