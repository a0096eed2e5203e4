"""``aouc studio``: the command's side of the live studio (:mod:`aou_dsl.studio`)."""

from __future__ import annotations

import argparse

from .args import usage_error

__all__ = ["cmd_studio"]


def cmd_studio(args: argparse.Namespace) -> int:
    """Serve the studio of ``args.path`` until Ctrl-C; the exit status."""
    from ..core.options import package_dirs
    from ..studio import serve

    recording = not args.path.endswith(".aou")
    if recording and args.fit:
        return usage_error("studio", "--fit shapes a .aou file: a recording is played as "
                           "it was measured")
    if args.compare and not args.compare.endswith(".aou"):
        return usage_error("studio", f"--compare takes a .aou file, found {args.compare}")
    return serve(args.path, robot=args.robot, host=args.host, port=args.port,
                 compare=args.compare, package_dirs=package_dirs(args.package_dir),
                 fit=args.fit)
