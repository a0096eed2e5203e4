"""``aouc robot``: what aou knows or derives of an arm, and a robot file that pins it."""

from __future__ import annotations

import argparse

from .cli_args import EXIT_OK, EXIT_USAGE
from .report import format_json

__all__ = ["cmd_robot"]


def cmd_robot(args: argparse.Namespace) -> int:
    from .robots import ROBOTS

    if args.list or args.robot is None:
        if args.robot is None and not args.list:
            print("aouc robot: give a robot name or path, or --list")
            return EXIT_USAGE
        for name, spec in ROBOTS.items():
            print(f"{name:14s} {len(spec.arm_joints)} joints, end-effector {spec.ee_frame}")
        return EXIT_OK
    from .arms import describe_robot

    doc, text = describe_robot(args.robot)
    if args.format == "json":
        print(format_json(doc))
    elif args.format == "toml":
        print(doc["toml"], end="" if doc["toml"].endswith("\n") else "\n")
    else:
        print(text)
    return EXIT_OK
