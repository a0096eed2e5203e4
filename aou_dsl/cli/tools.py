"""``aouc robot`` (what aou knows or derives of an arm) and ``aouc synth`` (a behaviour
file for a state or a point of the C-V plane, fitted to the arm)."""

from __future__ import annotations

import argparse
import sys

from ..core.codes import V109
from ..core.diagnostics import RULES, AouError, Diagnostic, Span, diag
from ..version import __version__
from .args import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, usage_error
from .report import format_json, format_text

__all__ = ["cmd_robot", "cmd_rules", "cmd_synth", "plugin_lines"]


#: Names people call the built-in arms by: ``aouc robot franka`` suggests ``panda``.
ALIASES = {"franka": "panda", "franka_panda": "panda", "fr3": "panda", "emika": "panda",
           "panda_arm": "panda", "xarm": "xarm7", "ufactory": "xarm7", "gen3": "kinova",
           "kinova_gen3": "kinova", "unitree": "z1", "ur": "ur5", "ur5e": "ur5",
           "ur3e": "ur3", "ur10e": "ur10"}


def _with_alias(err: AouError, robot: str) -> AouError:
    """V109 for an unknown robot, with a did-you-mean from :data:`ALIASES` when the
    spelling gave none."""
    from dataclasses import replace

    alias = ALIASES.get(robot.lower().replace("-", "_").replace(" ", "_"))
    if alias is None:
        return err
    return AouError([replace(d, hint=f"did you mean `{alias}`?") if d.code == V109
                     and not d.hint else d for d in err.diagnostics])


def _missing_meshes(robot: str, dirs: tuple[str, ...]) -> list[Diagnostic]:
    """V109 when meshes the checks load cannot be found: said here, not first at the
    compile (and how to compile without them)."""
    from ..robot.load import load_robot
    from ..robot.urdf import scene_xml

    r = load_robot(robot, dirs)
    _, missing = scene_xml(r.urdf, r.package_dirs, r.gaze, visuals=False)
    if not missing:
        return []
    return [diag(V109, f"robot `{robot}`: {len(missing)} mesh file(s) of its collision "
                 f"shapes not found, first `{missing[0]}`: the safety checks cannot load it",
                 Span.whole_file(r.urdf.path),
                 hint="give the folder of the package (or one holding it) with "
                 "--package-dir, or in ROS_PACKAGE_PATH, or `package_dirs` in a robot "
                 "description; or compile with --no-check (the checks are then skipped, "
                 "and the output says so)")]


def cmd_robot(args: argparse.Namespace) -> int:
    from ..core.robot_specs import ROBOTS

    if args.list or args.robot is None:
        if args.robot is None and not args.list:
            return usage_error("robot", "give a robot name or path, or --list")
        for name, spec in ROBOTS.items():
            print(f"{name:14s} {len(spec.arm_joints)} joints, end-effector {spec.ee_frame}")
        _print_plugins()
        return EXIT_OK
    from ..core.files import check_output, write_atomic
    from ..core.options import package_dirs
    from ..robot import describe_robot
    from ..robot.files_read import robot_files

    reads = robot_files(args.robot, args.package_dir)
    if args.output:
        check_output(args.output, reads=reads, force=args.force)
    try:
        doc, text = describe_robot(args.robot, package_dirs(args.package_dir))
    except AouError as err:
        raise _with_alias(err, args.robot) from None
    missing = _missing_meshes(args.robot, package_dirs(args.package_dir))
    if args.format == "json":
        out = format_json({"generator": f"aouc {__version__}", **doc} if args.output
                          else doc)
    else:
        out = doc["toml"] if args.format == "toml" else text
        if args.output:  # aou's mark: `robot -o` may replace this file again
            out = f"# written by `aouc robot {args.robot}`\n{out}"
    out = out if out.endswith("\n") else out + "\n"
    if args.output:
        write_atomic(args.output, out.encode(), inputs=reads)
        print(f"{args.robot} -> {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(out)
    for d in missing:
        print(format_text(d), file=sys.stderr)
    return EXIT_ERRORS if missing else EXIT_OK


def cmd_synth(args: argparse.Namespace) -> int:
    """``aouc synth``: a behaviour file for a state or a C-V point, fitted to the arm."""

    from ..core.files import check_output, write_atomic
    from ..robot.files_read import robot_files
    from ..synth.synthesis import synthesize

    if args.V is not None and args.C is None:  # argparse requires --state or --C
        return usage_error("synth", "--V goes with --C (a point of the C-V plane), not "
                           "with --state")
    if args.C is not None and args.V is None:
        return usage_error("synth", "a point of the C-V plane needs --V too")
    reads = robot_files(args.robot, args.package_dir) if args.robot else []
    if args.output is not None:
        check_output(args.output, ("aou",), reads=reads, force=args.force)
    text = synthesize(args.state, C=args.C, V=args.V, intensity=args.intensity,
                      robot=args.robot, verify=not args.no_verify)
    if args.output is None:
        sys.stdout.write(text)
        return EXIT_OK
    write_atomic(args.output, text.encode(), inputs=reads)
    print(f"wrote {args.output}", file=sys.stderr)
    return EXIT_OK


def plugin_lines() -> list[str]:
    """The installed plugins' primitive kinds in words: each one loaded (its keyword, its
    distribution and the layers it gives parts for), then each that cannot be used as it
    is, with its code and why. Empty when none is installed (or ``AOU_NO_PLUGINS=1``)."""
    from ..core.plugins import GROUP, LAYERS, plugins
    from ..lang.descriptors import descriptor_problems
    from ..lang.primitives import BUILTIN_KINDS, KINDS, plugin_problems

    problems = (*plugin_problems(), *descriptor_problems())
    used = [p for p in plugins() if p.name not in BUILTIN_KINDS and KINDS.get(p.name) is
            p.part("kind")]
    if not used and not problems:
        return []
    out = [f"plugins (entry point group {GROUP}): {len(used)} loaded"]
    for p in used:
        parts = ", ".join(layer for layer in LAYERS if p.part(layer) is not None)
        out.append(f"  {p.name:<14} {p.source:<28} gives: {parts}")
    if problems:
        out.append(f"plugins that cannot be used as they are: {len(problems)}")
        out += [f"  {p.code} {p.name:<14} {p.source:<28} {p.why}" for p in problems]
    return out


def _print_plugins() -> None:
    lines = plugin_lines()
    if lines:
        print("\n" + "\n".join(lines))


def cmd_rules(args: argparse.Namespace) -> int:
    """``aouc rules [CODE...]``: the registry, or some of its rules in full."""
    wanted = [c.upper() for c in args.codes]
    unknown = [c for c in wanted if c not in RULES]
    if unknown:
        print(f"aouc: unknown rule code(s): {', '.join(unknown)}; `aouc rules` lists them",
              file=sys.stderr)
        return EXIT_USAGE
    rules = [RULES[c] for c in wanted] if wanted else list(RULES.values())
    if args.format == "json":
        print(format_json([{"code": r.code, "name": r.name, "severity": str(r.severity),
                            "what": r.what, "why": r.why, "example": r.example}
                           for r in rules]))
        return EXIT_OK
    for r in rules:
        if wanted:
            print(f"{r.code} {r.name} [{r.severity}]\n  what: {r.what}\n  why: {r.why}\n"
                  f"  example:\n" + "\n".join(f"    {ln}" for ln in r.example.splitlines()))
        else:
            print(f"{r.code}  {r.name:<28} {r.severity:<8} {r.what}")
    if not wanted or any(r.name.startswith("plugin-") for r in rules):
        _print_plugins()
    return EXIT_OK
