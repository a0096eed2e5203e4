"""``aouc studio``: the command's side of the live studio (:mod:`aou_dsl.studio`)."""

from __future__ import annotations

import argparse

from .args import usage_error

__all__ = ["cmd_studio"]


def cmd_studio(args: argparse.Namespace) -> int:
    """Serve the studio of ``args.path`` until Ctrl-C; the exit status."""
    from ..core.options import package_dirs
    from ..studio import serve

    scenario = args.path.endswith(".toml")
    if scenario:
        return _scenario(args)
    if args.perception:
        return usage_error("studio", "--perception goes with a scenario (.toml)")
    recording = not args.path.endswith(".aou")
    if recording and args.fit:
        return usage_error("studio", "--fit shapes a .aou file: a recording is played as "
                           "it was measured")
    if args.compare and not args.compare.endswith(".aou"):
        return usage_error("studio", f"--compare takes a .aou file, found {args.compare}")
    return serve(args.path, robot=args.robot, host=args.host, port=args.port,
                 compare=args.compare, package_dirs=package_dirs(args.package_dir),
                 fit=args.fit)


def _scenario(args: argparse.Namespace) -> int:
    """``aouc studio SCENARIO.toml``: the perception loop played live."""
    import sys

    from ..studio import serve
    from .args import EXIT_USAGE
    from .live_cmd import _missing

    for flag, given in (("--fit", args.fit), ("--compare", args.compare),
                        ("--package-dir", args.package_dir)):
        if given:
            return usage_error("studio", f"{flag} shapes a .aou file: a scenario plays "
                               "the loop of `aouc live`")
    kind = args.perception or "geometric"
    missing = _missing(kind == "camera", False)
    if missing:
        print(f"aouc: this needs the {missing[0]} extra ({missing[1]} is missing): "
              f"pip install '.[{missing[0]}]' in aou's folder (the one with pyproject.toml)",
              file=sys.stderr)
        return EXIT_USAGE
    return serve(args.path, robot=args.robot, host=args.host, port=args.port,
                 perception=kind)
