"""The argument parser of ``aouc``: every command and option, and the checked number types.

Every numeric option is checked here, before any work: a value that is not a finite
number in its range is a usage error (exit 2) with a message that names the range.
"""

from __future__ import annotations

import argparse
import sys

from ..core.memo import cached
from ..version import __version__
from .actions_args import dmp_parser, live_parser, study_parser
from .argtypes import (
    HEIGHT,
    LENGTH,
    RATE,
    UNIT_RANGE,
    force_option,
    frame_size,
    int_in,
    number,
    point,
)

__all__ = ["EXIT_ERRORS", "EXIT_INCONCLUSIVE", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_USAGE",
           "build_parser", "exit_for", "number", "scene_kw", "shared_parser", "usage_error"]

EXIT_OK = 0
EXIT_ERRORS = 1
EXIT_USAGE = 2
#: ``measure --against``: nothing failed, but the noise leaves a descriptor undecided.
EXIT_INCONCLUSIVE = 3
#: Interrupted (Ctrl-C): 128 + SIGINT, as shells report it.
EXIT_INTERRUPTED = 130


def exit_for(diags) -> int:
    """2 when the input could not be read or written (I codes), else 1."""
    from ..core.rules import category

    return EXIT_USAGE if any(category(d.code).is_usage for d in diags) else EXIT_ERRORS


def scene_kw(args: argparse.Namespace) -> dict:
    """The scene's target and table as the command line gives them."""
    return {"target_size": args.target_size,
            "table_height": None if args.no_table else args.table_height}


class Parser(argparse.ArgumentParser):
    """argparse exits 2 on usage errors, as the contract wants; keep its message short."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"aouc: error: {message}\n")
        raise SystemExit(EXIT_USAGE)


def usage_error(command: str, message: str) -> int:
    """A usage error found after parsing (options that only make sense together): the
    command's usage line and ``aouc: error: message`` on stderr, as argparse prints its
    own; returns :data:`EXIT_USAGE`."""
    shared_parser()[1][command].print_usage(sys.stderr)
    sys.stderr.write(f"aouc: error: {message}\n")
    return EXIT_USAGE


ROBOT_HELP = ("robot: a built-in name (panda, ur5, xarm7, ...; `aouc robot --list`) or a "
              "path to a .urdf or a .toml robot description; overrides the file's `robot`")


def _robot(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robot", metavar="NAME|PATH", help=ROBOT_HELP)
    _package_dir(p)


def _package_dir(p: argparse.ArgumentParser) -> None:
    p.add_argument("--package-dir", action="append", default=[], metavar="DIR",
                   help="a folder holding ROS packages, searched first for the URDF's "
                   "package:// meshes (repeatable)")


def _controller(p: argparse.ArgumentParser) -> None:
    p.add_argument("--controller", choices=("franka", "ur"),
                   help="also check that motion generator's rate and published limits "
                   "(franka: 1 kHz FCI; ur: 500 Hz e-Series)")


def _collision(p: argparse.ArgumentParser) -> None:
    p.add_argument("--no-collision-check", action="store_true",
                   help="accept a robot without collision shapes (self-collision is then "
                   "not checked, and the output says so)")


def goal_point(text: str) -> tuple[float, float, float] | str:
    """argparse type of --goal: X,Y,Z in metres, or `final`."""
    return "final" if text.strip().lower() == "final" else point(text)


def _recording(p: argparse.ArgumentParser) -> None:
    _robot(p)
    p.add_argument("--angle-unit", choices=("rad", "deg"),
                   help="the joint columns of a recording are in this unit (default rad; "
                   "values that look like degrees are an error unless said)")
    p.add_argument("--time-unit", choices=("s", "ms"),
                   help="the t column of a recording is in this unit (default s)")
    p.add_argument("--ee-frame", help="end-effector frame (default: the robot's)")
    p.add_argument("--goal", metavar="X,Y,Z|final", type=goal_point,
                   help="goal position in metres, or `final`: the end-effector's last "
                   "position (for a recording without a goal)")


def _column_map(p: argparse.ArgumentParser) -> None:
    p.add_argument("--map", metavar="COL=JOINT,...|FILE",
                   help="a recording's columns named otherwise than the robot's joints: "
                   "column=joint pairs, or a file of them (one per line)")


def _fit(p: argparse.ArgumentParser) -> None:
    p.add_argument("--fit", action="store_true",
                   help="change what the arm cannot give (accelerations, shiver frequency, "
                   "tilt speed, a gaze angle or distance out of reach) to what it can, "
                   "keeping the state; each change a C314 warning")
    p.add_argument("--write-fitted", metavar="PATH.aou",
                   help="with --fit: write the fitted behaviour there (one input)")


def _track(p: argparse.ArgumentParser) -> None:
    p.add_argument("--track", action="store_true",
                   help="simulate the arm tracking the motion through its servos (MuJoCo; "
                   "the `track` extra) in each servo mode, and judge what it shows "
                   "(docs/checks.md)")
    p.add_argument("--servo", choices=("position", "feedforward", "torque"),
                   default="position",
                   help="with --track: how the trajectory is sent, the mode whose losses "
                   "are errors (position: plain set-points, the default; feedforward: "
                   "with velocities; torque: computed torque)")
    p.add_argument("--tracked", metavar="FILE",
                   help="with --track: write the tracked motion (--servo's) as a recording "
                   "(.json or .csv) that `aouc measure` reads")


def _scene(p: argparse.ArgumentParser) -> None:
    p.add_argument("--target-size", type=LENGTH, default=0.05, metavar="M",
                   help="edge of the target cube at the goal, in metres (default 0.05)")
    p.add_argument("--table-height", type=HEIGHT, default=0.0, metavar="M",
                   help="height of the table plane in the base frame (default 0)")
    p.add_argument("--no-table", action="store_true", help="no table plane")


def _render(p: argparse.ArgumentParser) -> None:
    p.add_argument("--fps", type=number(1.0, 240.0, what="frames per second"), default=30.0,
                   help="frames per second (default 30)")
    p.add_argument("--size", default=(640, 480), type=frame_size, metavar="WxH",
                   help="frame size (default 640x480)")
    p.add_argument("--camera-distance", type=number(0.05, 20.0, lo_open=True,
                                                    what="a distance in metres"),
                   default=1.2, metavar="M")
    p.add_argument("--camera-yaw", type=number(-360.0, 360.0, what="an angle in degrees"),
                   default=30.0, metavar="DEG")
    p.add_argument("--camera-pitch", type=number(-89.0, 89.0, what="an angle in degrees"),
                   default=-15.0, metavar="DEG")
    p.add_argument("--camera-target", metavar="X,Y,Z", type=point,
                   help="point looked at (default: halfway from the base to the goal)")


def _editor(sub, c: dict[str, argparse.ArgumentParser]) -> None:
    """``aouc fmt`` and ``aouc server``."""
    c["fmt"] = fmt = sub.add_parser("fmt", help="lay .aou files out canonically, comments kept")
    fmt.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    fmt.add_argument("--check", action="store_true",
                     help="write nothing; exit 1 when a file would change")
    fmt.add_argument("--diff", action="store_true",
                     help="write nothing; print the changes, exit 1 when there are some")
    c["server"] = srv = sub.add_parser(
        "server", help="the language server for editors, on stdio (needs the `lsp` extra)")
    _robot(srv)


def _commands(sub) -> dict[str, argparse.ArgumentParser]:
    c = {}
    c["lint"] = lint = sub.add_parser(
        "lint", help="check .aou files against the language and the C-V model")
    lint.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    lint.add_argument("--format", choices=("text", "json", "github", "sarif"), default="text",
                      help="github: annotations; sarif: a SARIF 2.1.0 log for code "
                      "scanning (docs/ci.md)")
    lint.add_argument("--strict", action="store_true", help="warnings fail too (exit 1)")
    c["explain"] = ex = sub.add_parser("explain", help="show the timeline a file compiles to")
    ex.add_argument("path", metavar="FILE")
    c["compile"] = comp = sub.add_parser(
        "compile", help="compile .aou files into joint trajectories")
    comp.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    comp.add_argument("-o", "--output", metavar="FILE|DIR",
                      help="output file, or folder (files found in a folder keep their "
                      "path below it; default: the current folder)")
    comp.add_argument("--format", choices=("json", "csv", "npz", "mcap", "yaml", "dmp"),
                      help="output format (default: from -o's extension, else json); mcap: "
                      "a ROS 2 bag (a folder) with one JointTrajectory, yaml: the same "
                      "message as YAML (docs/ros2.md); dmp: a folder of DMPs (docs/dmp.md)")
    comp.add_argument("--csv-derivatives", action="store_true",
                      help="with --format csv: after the positions, a velocity and an "
                      "acceleration column per joint (qd_JOINT, qdd_JOINT), for a "
                      "controller that reads them (docs/ros2.md)")
    comp.add_argument("--rate", type=RATE, metavar="HZ", help="sample rate in Hz (default 250)")
    _robot(comp)
    comp.add_argument("-j", "--jobs", type=int_in(0, 256), default=1, metavar="N",
                      help="build N files at once in warm worker processes (0: one per "
                      "core); output identical to --jobs 1, in input order")
    comp.add_argument("--cluster", metavar="ADDRESS",
                      help="build on a Dask cluster, e.g. tcp://host:8786 (needs the "
                      "`cluster` extra; docs/speed.md)")
    comp.add_argument("--no-check", action="store_true",
                      help="skip the safety checks (recorded in the output)")
    comp.add_argument("--no-output", action="store_true",
                      help="build and check, write no trajectory (a CI or pre-commit "
                      "check; not with -o)")
    comp.add_argument("--changed-since", metavar="REF",
                      help="build only the files among PATH that changed since the git "
                      "revision REF, or are new (docs/ci.md)")
    comp.add_argument("--sarif", metavar="FILE",
                      help="also write every diagnostic of the batch as a SARIF 2.1.0 log "
                      "(docs/ci.md)")
    _collision(comp)
    _controller(comp)
    _scene(comp)
    _fit(comp)
    _track(comp)
    c["check"] = chk = sub.add_parser(
        "check", help="replay a behaviour or trajectory in PyBullet and report every check")
    chk.add_argument("path", metavar="FILE", help="a .aou file or a trajectory file")
    chk.add_argument("--format", choices=("text", "json", "sarif"), default="text",
                     help="sarif: the compile's refusals and the failed checks as a SARIF "
                     "2.1.0 log (docs/ci.md)")
    _fit(chk)
    chk.add_argument("--no-dynamic", action="store_true",
                     help="kinematic checks only (skip the physics replay)")
    _collision(chk)
    _controller(chk)
    _recording(chk)
    _column_map(chk)
    _scene(chk)
    _track(chk)
    c["plot"] = plot = sub.add_parser(
        "plot", help="velocity profile of a behaviour or trajectory, or the C-V map (--cv)")
    plot.add_argument("paths", nargs="+", metavar="FILE")
    plot.add_argument("-o", "--output", required=True, metavar="X.png|X.svg")
    plot.add_argument("--cv", action="store_true",
                      help="plot the C-V plane with each behaviour's inferred point")
    _recording(plot)
    _column_map(plot)
    c["render"] = render = sub.add_parser("render", help="render a video of a behaviour")
    render.add_argument("path", nargs="?", metavar="FILE")
    render.add_argument("-o", "--output", required=True, metavar="X.mp4|X.gif")
    render.add_argument("--side-by-side", nargs=2, metavar=("A", "B"),
                        help="render two behaviours next to each other")
    _render(render)
    _recording(render)
    _scene(render)
    c["variants"] = var = sub.add_parser(
        "variants", help="write a pair of files that differ in one descriptor (study Part B)")
    var.add_argument("path", metavar="FILE")
    var.add_argument("--vary", required=True, metavar="NAME=LOW,HIGH",
                     help="descriptor and its two values, in the descriptor's unit")
    var.add_argument("-o", "--output", metavar="DIR", help="folder (default: here)")
    var.add_argument("--render", metavar="X.mp4|X.gif", help="also render the pair")
    force_option(var)
    _render(var)
    _scene(var)
    c["measure"] = meas = sub.add_parser(
        "measure", help="measure the eleven descriptors of a trajectory")
    meas.add_argument("path", metavar="FILE", help="a trajectory .json/.npz, or a .csv")
    _recording(meas)
    _column_map(meas)
    meas.add_argument("--against", metavar="FILE.aou",
                      help="judge the motion against this behaviour: each descriptor "
                      "declared vs measured with its tolerance and the measured value's "
                      "95 %% interval; exit 1 when one is outside, 3 when none is but one "
                      "is inconclusive. A recording without a robot takes the file's")
    meas.add_argument("--format", choices=("table", "json", "github"), default="table",
                      help="github: annotations (with --against)")
    c["robot"] = rob = sub.add_parser(
        "robot", help="show what aou knows or derives of a robot (frames, limits, posture)")
    rob.add_argument("robot", nargs="?", metavar="NAME|PATH",
                     help="a built-in name, or a .urdf or .toml path")
    rob.add_argument("--list", action="store_true", help="list the built-in robots")
    rob.add_argument("--format", choices=("text", "json", "toml"), default="text",
                     help="toml: a robot description pinning every value")
    rob.add_argument("-o", "--output", metavar="FILE",
                     help="write to FILE instead of standard output (e.g. -o arm.toml)")
    force_option(rob)
    _package_dir(rob)
    c["synth"] = syn = sub.add_parser(
        "synth", help="write a .aou file for a state, or a point of the C-V plane, at an "
        "intensity")
    which = syn.add_mutually_exclusive_group(required=True)
    which.add_argument("--state", choices=("confident", "curious", "hesitant", "fearful",
                                           "inactive"))
    which.add_argument("--C", type=UNIT_RANGE, dest="C", metavar="C",
                       help="commitment in [-1, 1] (with --V)")
    syn.add_argument("--V", type=UNIT_RANGE, dest="V", metavar="V",
                     help="vigilance in [-1, 1] (with --C)")
    syn.add_argument("--intensity", type=number(0.0, 1.0, what="an intensity"), default=0.5,
                     metavar="I", help="in [0, 1]; 0.5 gives the study's stimulus")
    _robot(syn)
    syn.add_argument("--no-verify", action="store_true",
                     help="skip the compile that fits the values to the arm")
    syn.add_argument("-o", "--output", metavar="FILE.aou",
                     help="output file (default: standard output)")
    force_option(syn)
    c["studio"] = stu = sub.add_parser(
        "studio", help="see a behaviour in 3D in the browser and shape it live (`studio` extra)")
    stu.add_argument("path", metavar="FILE", help="a .aou file, a recording with --robot, or "
                     "a scenario (.toml) whose perception loop plays live")
    stu.add_argument("--port", type=int_in(1, 65535), default=8080, metavar="P",
                     help="port to serve on (default 8080; the next free one when taken)")
    stu.add_argument("--host", default="127.0.0.1", metavar="H",
                     help="address to bind (default 127.0.0.1: this machine only)")
    stu.add_argument("--compare", metavar="OTHER.aou",
                     help="show a second behaviour, ghosted, on the same clock")
    stu.add_argument("--fit", action="store_true",
                     help="build as `aouc compile --fit` does (the fitted values shown in the "
                     "page; Save writes the sliders' values)")
    stu.add_argument("--track", action="store_true",
                     help="draw, ghosted beside the plan, the arm as its servos track it "
                     "(MuJoCo; the `track` extra)")
    stu.add_argument("--servo", choices=("position", "feedforward", "torque"),
                     default="position",
                     help="with --track: how the motion is sent to the servos (default "
                     "position set-points)")
    stu.add_argument("--perception", choices=("geometric", "camera"), default=None,
                     help="with a scenario: what sees the target, the geometric model "
                     "(default) or the rendered camera with its tag detector")
    _robot(stu)
    _editor(sub, c)
    c["dmp"] = dmp_parser(sub)
    c["live"] = live_parser(sub)
    c["study"] = study_parser(sub)
    c["rules"] = rules = sub.add_parser("rules", help="list the diagnostic codes, or explain some")
    rules.add_argument("codes", nargs="*", metavar="CODE")
    rules.add_argument("--format", choices=("text", "json"), default="text")
    return c


def build_parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The parser and its sub-parsers by command name."""
    p = Parser(prog="aouc", description="aou: expressive robot-arm motion from .aou files.")
    p.add_argument("--version", action="version", version=f"aouc {__version__}")
    p.add_argument("--debug", action="store_true",
                   help="show the traceback of an internal error")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    return p, _commands(sub)


@cached(maxsize=1)
def shared_parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """:func:`build_parser`'s parser, made once per process: it depends on nothing but
    this code, parsing leaves it as it was (an appending option copies its default
    list before it appends), and making it (some 1,800 options) costs each command of a
    process that runs several (a benchmark, a test) about 5 ms."""
    return build_parser()
