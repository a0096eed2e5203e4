"""``aouc robot`` (what aou knows or derives of an arm) and ``aouc synth`` (a behaviour
file for a state or a point of the C-V plane, fitted to the arm)."""

from __future__ import annotations

import argparse
import sys

from .args import EXIT_OK, usage_error
from .report import format_json

__all__ = ["cmd_robot", "cmd_synth"]


def cmd_robot(args: argparse.Namespace) -> int:
    from ..core.robot_specs import ROBOTS

    if args.list or args.robot is None:
        if args.robot is None and not args.list:
            return usage_error("robot", "give a robot name or path, or --list")
        for name, spec in ROBOTS.items():
            print(f"{name:14s} {len(spec.arm_joints)} joints, end-effector {spec.ee_frame}")
        return EXIT_OK
    from ..core.files import check_output, write_atomic
    from ..robot import describe_robot

    if args.output:
        check_output(args.output)
    doc, text = describe_robot(args.robot)
    if args.format == "json":
        out = format_json(doc)
    elif args.format == "toml":
        out = doc["toml"]
    else:
        out = text
    out = out if out.endswith("\n") else out + "\n"
    if args.output:
        write_atomic(args.output, out.encode(), inputs=[args.robot])
        print(f"{args.robot} -> {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(out)
    return EXIT_OK


def cmd_synth(args: argparse.Namespace) -> int:
    """``aouc synth``: a behaviour file for a state or a C-V point, fitted to the arm."""

    from ..core.files import check_output, write_atomic
    from ..synth.synthesis import synthesize

    if args.V is not None and args.C is None:  # argparse requires --state or --C
        return usage_error("synth", "--V goes with --C (a point of the C-V plane), not "
                           "with --state")
    if args.C is not None and args.V is None:
        return usage_error("synth", "a point of the C-V plane needs --V too")
    if args.output is not None:
        check_output(args.output, ("aou",))
    text = synthesize(args.state, C=args.C, V=args.V, intensity=args.intensity,
                      robot=args.robot, verify=not args.no_verify)
    if args.output is None:
        sys.stdout.write(text)
        return EXIT_OK
    write_atomic(args.output, text.encode())
    print(f"wrote {args.output}", file=sys.stderr)
    return EXIT_OK
