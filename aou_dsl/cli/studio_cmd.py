"""``aouc studio``: the command's side of the live studio (:mod:`aou_dsl.studio`)."""

from __future__ import annotations

import argparse
import importlib.util

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
    if args.track and recording:
        return usage_error("studio", "--track simulates the servos following a plan: a "
                           "recording is already what an arm did")
    if args.track and args.compare:
        return usage_error("studio", "--track and --compare each draw the second arm: "
                           "give one")
    if args.track and importlib.util.find_spec("mujoco") is None:  # a fixed name
        return usage_error("studio", "--track needs the track extra (mujoco is missing): "
                           "pip install '.[track]' in aou's folder")
    return serve(args.path, robot=args.robot, host=args.host, port=args.port,
                 compare=args.compare, package_dirs=package_dirs(args.package_dir),
                 fit=args.fit, track=args.servo if args.track else None)


def _scenario(args: argparse.Namespace) -> int:
    """``aouc studio SCENARIO.toml``: the perception loop played live."""
    import sys

    from ..studio import serve
    from .args import EXIT_USAGE
    from .live_cmd import _missing

    for flag, given in (("--fit", args.fit), ("--compare", args.compare),
                        ("--track", args.track), ("--package-dir", args.package_dir)):
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
