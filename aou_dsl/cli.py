"""``aouc``: the command line. Thin: each command calls the library and formats records.

Exit codes (LANGUAGE.md): 0 no error, 1 the input has errors (or warnings under
``--strict``), 2 usage or I/O problems. A 2 is never hidden by a flag.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from . import __version__
from .diagnostics import RULES, Diagnostic, Severity
from .report import format_github, format_json, format_text

__all__ = ["EXIT_ERRORS", "EXIT_OK", "EXIT_USAGE", "main"]

EXIT_OK = 0
EXIT_ERRORS = 1
EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """argparse exits 2 on usage errors, as the contract wants; keep its message short."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"aouc: error: {message}\n")
        raise SystemExit(EXIT_USAGE)


def _print_diags(diags: list[Diagnostic], fmt: str, sources: dict[str, str] | None = None,
                 stream=None) -> None:
    stream = stream or sys.stdout
    for d in diags:
        if fmt == "github":
            print(format_github(d), file=stream)
        else:
            print(format_text(d, (sources or {}).get(d.span.path)), file=stream)


def _exit_for(diags: list[Diagnostic]) -> int:
    """2 when the input could not be read (I codes), else 1: the file has errors."""
    return EXIT_USAGE if any(d.code.startswith("I") for d in diags) else EXIT_ERRORS


# --- lint -------------------------------------------------------------------------------


def _cmd_lint(args: argparse.Namespace) -> int:
    from .lint import lint_paths, severity_counts

    results, problems = lint_paths(args.paths)
    counts = severity_counts(results)
    io_errors = bool(problems) or any(
        d.code.startswith("I") for r in results for d in r.diagnostics)
    if args.format == "json":
        print(format_json({
            "files": [r.to_json() for r in results],
            "problems": [d.to_json() for d in problems],
            "summary": {str(k): v for k, v in counts.items()},
        }))
    else:
        _print_diags(problems, args.format, stream=sys.stderr)
        for r in results:
            _print_diags(r.diagnostics, args.format, {r.path: r.source or ""})
        if args.format == "text":
            n = len(results)
            print(f"{n} file{'s' * (n != 1)} checked: {counts[Severity.ERROR]} errors, "
                  f"{counts[Severity.WARNING]} warnings, {counts[Severity.NOTE]} notes",
                  file=sys.stderr)
    if io_errors:
        return EXIT_USAGE
    if counts[Severity.ERROR] or (args.strict and counts[Severity.WARNING]):
        return EXIT_ERRORS
    return EXIT_OK


# --- rules ------------------------------------------------------------------------------


def _cmd_rules(args: argparse.Namespace) -> int:
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
    return EXIT_OK


# --- explain ----------------------------------------------------------------------------


def _cmd_explain(args: argparse.Namespace) -> int:
    from .compiler.layout import layout
    from .lint import lint_file
    from .report import format_timeline

    r = lint_file(args.path)
    if not r.ok or r.behaviour is None or r.cv is None:
        _print_diags(r.diagnostics, "text", {r.path: r.source or ""}, stream=sys.stderr)
        return _exit_for(r.diagnostics)
    print(format_timeline(r.behaviour, r.cv, layout(r.behaviour)))
    return EXIT_OK


# --- compile ----------------------------------------------------------------------------


def _format_from(output: str | None, many: bool) -> str:
    """The output format a single ``-o FILE`` implies by its extension; json otherwise."""
    import os

    if output and not many and not os.path.isdir(output):
        ext = os.path.splitext(output)[1].lstrip(".")
        if ext:
            return ext
    return "json"


def _output_path(src: str, out: str | None, fmt: str, many: bool) -> str:
    import os

    stem = os.path.splitext(os.path.basename(src))[0]
    if out is None:
        return f"{stem}.{fmt}"
    if many or out.endswith(os.sep) or os.path.isdir(out):
        return os.path.join(out, f"{stem}.{fmt}")
    return out


def _cmd_compile(args: argparse.Namespace) -> int:
    import os

    from .build import build_file
    from .compiler.output import encode, write_atomic
    from .diagnostics import AouError, has_errors
    from .lint import collect_files

    files, problems = collect_files(args.paths)
    _print_diags(problems, "text", stream=sys.stderr)
    if problems:
        return EXIT_USAGE
    many = len(files) > 1
    fmt = args.format or _format_from(args.output, many)
    if fmt not in ("json", "csv", "npz"):
        print(f"aouc: unknown output format `{fmt}`: expected json, csv or npz",
              file=sys.stderr)
        return EXIT_USAGE
    if many and args.output and not args.output.endswith(os.sep) \
            and not os.path.isdir(args.output) and os.path.splitext(args.output)[1]:
        print(f"aouc: several inputs need -o to be a folder, found `{args.output}`",
              file=sys.stderr)
        return EXIT_USAGE
    if many and args.output:
        os.makedirs(args.output, exist_ok=True)
    worst = EXIT_OK
    scene = _scene_options(args)
    for k, src in enumerate(files, 1):
        res = build_file(src, rate=args.rate, check=not args.no_check, scene=scene)
        _print_diags(res.diagnostics, "text", {src: res.lint.source or ""}, stream=sys.stderr)
        dest = _output_path(src, args.output, fmt, many)
        if not res.ok or res.document is None:
            worst = max(worst, _exit_for(res.diagnostics))
            print(f"[{k}/{len(files)}] {src}: failed, nothing written", file=sys.stderr)
            continue
        try:
            write_atomic(dest, encode(res.document, fmt), inputs=files)
        except AouError as err:
            _print_diags(err.diagnostics, "text", stream=sys.stderr)
            worst = EXIT_USAGE
            continue
        tr = res.trajectory
        note = "" if not args.no_check else " (checks skipped)"
        print(f"[{k}/{len(files)}] {src} -> {dest}: {tr.duration:.2f} s of motion, "
              f"{len(tr.t)} samples, compiled in {res.seconds:.2f} s{note}", file=sys.stderr)
        if has_errors(res.diagnostics):
            worst = max(worst, EXIT_ERRORS)
    return worst


def _scene_options(args: argparse.Namespace):
    from .check.scene import SceneOptions

    table = None if args.no_table else args.table_height
    return SceneOptions(target_size=args.target_size, table_height=table)


# --- check ------------------------------------------------------------------------------


def _cmd_check(args: argparse.Namespace) -> int:
    from .build import load_motion
    from .check.replay import replay_motion
    from .diagnostics import AouError
    from .report import format_check

    try:
        motion = load_motion(args.path, **_recording_options(args))
        report = replay_motion(motion, options=_scene_options(args),
                               dynamic=not args.no_dynamic)
    except AouError as err:
        return _report_error(err)
    rec = motion.recording
    if args.format == "json":
        print(format_json({"path": args.path, **report.to_json()}))
    else:
        print(format_check(args.path, rec.robot, rec.t, report))
    return EXIT_OK if report.ok else EXIT_ERRORS


# --- measure ----------------------------------------------------------------------------


def _point(text: str) -> tuple[float, float, float]:
    """argparse type of X,Y,Z options (metres)."""
    parts = text.strip("()").split(",")
    try:
        if len(parts) != 3:
            raise ValueError
        x, y, z = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z in metres, found `{text}`") from None
    return (x, y, z)


def _frame_size(text: str) -> tuple[int, int]:
    """argparse type of --size WxH (pixels)."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
        if w < 8 or h < 8:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH in pixels, e.g. 640x480, found "
                                         f"`{text}`") from None
    return (w, h)


def _cmd_measure(args: argparse.Namespace) -> int:
    from .diagnostics import AouError
    from .measure.descriptors import measure
    from .measure.recording import read_recording
    from .report import format_measured

    try:
        rec = read_recording(args.path, **_recording_options(args))
        m = measure(rec)
    except AouError as err:
        return _report_error(err)
    if args.format == "json":
        print(format_json({"path": args.path, "robot": rec.robot, **m.to_json()}))
    else:
        print(format_measured(args.path, rec.robot, m))
        _print_diags(m.diagnostics, "text", stream=sys.stderr)
    return EXIT_OK


# --- plot, render, variants --------------------------------------------------------------


def _media_missing(exc: ImportError) -> int:
    print(f"aouc: this command needs the media extra ({exc.name} is missing): "
          "pip install 'aou-dsl[media]'", file=sys.stderr)
    return EXIT_USAGE


def _report_error(err) -> int:
    """Print an AouError's diagnostics; the exit code they call for."""
    _print_diags(err.diagnostics, "text", stream=sys.stderr)
    return _exit_for(err.diagnostics)


def _cmd_plot(args: argparse.Namespace) -> int:
    from .build import load_motion
    from .diagnostics import AouError

    try:
        from .media.plot import cv_figure, profile_data, profile_figure, save
    except ImportError as exc:
        return _media_missing(exc)
    try:
        if args.cv:
            from .lint import lint_paths

            results, problems = lint_paths(args.paths)
            if problems:
                return _report_error(AouError(problems))
            bad = [d for r in results if not r.ok for d in r.diagnostics]
            if bad:
                return _report_error(AouError(bad))
            fig = cv_figure([(r.behaviour.name, r.cv) for r in results
                             if r.behaviour is not None and r.cv is not None])
        else:
            if len(args.paths) != 1:
                print("aouc: plot takes one file (or --cv with several)", file=sys.stderr)
                return EXIT_USAGE
            motion = load_motion(args.paths[0], **_recording_options(args))
            fig = profile_figure(profile_data(motion.recording, motion.episodes,
                                              motion.title))
        save(fig, args.output)
    except AouError as err:
        return _report_error(err)
    print(f"wrote {args.output}", file=sys.stderr)
    return EXIT_OK


def _camera(args: argparse.Namespace):
    from .media.render import Camera

    w, h = args.size
    return Camera(distance=args.camera_distance, yaw=args.camera_yaw,
                  pitch=args.camera_pitch, target=args.camera_target, width=w, height=h)


def _cmd_render(args: argparse.Namespace) -> int:
    import time

    from .build import load_motion
    from .diagnostics import AouError

    try:
        from .media.render import render_video
    except ImportError as exc:
        return _media_missing(exc)
    paths = args.side_by_side or ([args.path] if args.path else [])
    if not paths:
        print("aouc: render takes FILE, or --side-by-side A B", file=sys.stderr)
        return EXIT_USAGE
    try:
        camera = _camera(args)
        motions = [load_motion(p, **_recording_options(args)).recording for p in paths]
        start = time.perf_counter()
        info = render_video(motions, args.output, fps=args.fps, camera=camera,
                            scene_options=_scene_options(args))
    except AouError as err:
        return _report_error(err)
    except ImportError as exc:
        return _media_missing(exc)
    except ValueError as exc:
        print(f"aouc: {exc}", file=sys.stderr)
        return EXIT_USAGE
    print(f"wrote {args.output}: {info['frames']} frames at {info['fps']:g} fps "
          f"({info['duration']:.2f} s), {info['size'][0]}x{info['size'][1]}, rendered in "
          f"{time.perf_counter() - start:.1f} s", file=sys.stderr)
    return EXIT_OK


def _cmd_variants(args: argparse.Namespace) -> int:
    import os

    from .compiler.output import write_atomic
    from .diagnostics import AouError
    from .lint import lint_file, lint_source
    from .media.variants import make_variants

    try:
        name, values = args.vary.split("=", 1)
        low, high = (float(v) for v in values.split(","))
    except ValueError:
        print("aouc: --vary takes NAME=LOW,HIGH, e.g. pause_duration=1.0,2.5",
              file=sys.stderr)
        return EXIT_USAGE
    base = lint_file(args.path)
    if not base.ok or base.behaviour is None or base.source is None:
        _print_diags(base.diagnostics, "text", {args.path: base.source or ""},
                     stream=sys.stderr)
        return _exit_for(base.diagnostics)
    try:
        variants = make_variants(base.behaviour, base.source, name, low, high)
    except AouError as err:
        return _report_error(err)
    stem = os.path.splitext(os.path.basename(args.path))[0]
    folder = args.output or "."
    os.makedirs(folder, exist_ok=True)
    outputs = []
    for v in variants:
        out = os.path.join(folder, f"{stem}-{name}-{v.label}.aou")
        lint = lint_source(v.text, out)
        if not lint.ok:
            _print_diags(lint.diagnostics, "text", {out: v.text}, stream=sys.stderr)
            print(f"aouc: the {v.label} variant ({name}={v.value:g}) is not valid; nothing "
                  "written", file=sys.stderr)
            return EXIT_ERRORS
        outputs.append((out, v))
    for out, v in outputs:
        try:
            write_atomic(out, v.text.encode(), inputs=[args.path])
        except AouError as err:
            return _report_error(err)
        print(f"wrote {out} ({name}={v.value:g})", file=sys.stderr)
    if args.render:
        args.robot = args.goal = args.ee_frame = None  # the variants are .aou files
        args.side_by_side = [o for o, _ in outputs]
        args.path = None
        args.output = args.render
        return _cmd_render(args)
    return EXIT_OK


def _render_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--fps", type=float, default=30.0, help="frames per second (default 30)")
    p.add_argument("--size", default=(640, 480), type=_frame_size, metavar="WxH",
                   help="frame size (default 640x480)")
    p.add_argument("--camera-distance", type=float, default=1.2, metavar="M")
    p.add_argument("--camera-yaw", type=float, default=30.0, metavar="DEG")
    p.add_argument("--camera-pitch", type=float, default=-15.0, metavar="DEG")
    p.add_argument("--camera-target", metavar="X,Y,Z", type=_point,
                   help="point looked at (default: halfway from the base to the goal)")


# --- the parser -------------------------------------------------------------------------


def _recording_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robot", help="robot of a CSV recording (panda, ur5)")
    p.add_argument("--ee-frame", help="end-effector frame (default: the robot's)")
    p.add_argument("--goal", metavar="X,Y,Z", type=_point, help="goal position in metres")


def _recording_options(args: argparse.Namespace) -> dict:
    """``robot``, ``goal``, ``ee_frame`` for reading a recording."""
    return {"robot": args.robot, "goal": args.goal, "ee_frame": args.ee_frame}


def _scene_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--target-size", type=float, default=0.05, metavar="M",
                   help="edge of the target cube at the goal, in metres (default 0.05)")
    p.add_argument("--table-height", type=float, default=0.0, metavar="M",
                   help="height of the table plane in the base frame (default 0)")
    p.add_argument("--no-table", action="store_true", help="no table plane")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="aouc", description="aou: expressive robot-arm motion from .aou files.")
    p.add_argument("--version", action="version", version=f"aouc {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    lint = sub.add_parser("lint", help="check .aou files against the language and the C-V model")
    lint.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    lint.add_argument("--format", choices=("text", "json", "github"), default="text")
    lint.add_argument("--strict", action="store_true", help="warnings fail too (exit 1)")
    lint.set_defaults(func=_cmd_lint)

    explain = sub.add_parser("explain", help="show the timeline a file compiles to")
    explain.add_argument("path", metavar="FILE")
    explain.set_defaults(func=_cmd_explain)

    comp = sub.add_parser("compile", help="compile .aou files into joint trajectories")
    comp.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    comp.add_argument("-o", "--output", metavar="FILE|DIR",
                      help="output file, or folder for several inputs (default: STEM.json "
                           "in the current folder)")
    comp.add_argument("--format", choices=("json", "csv", "npz"),
                      help="output format (default: from -o's extension, else json)")
    comp.add_argument("--rate", type=float, metavar="HZ",
                      help="sample rate in Hz (default 250)")
    comp.add_argument("--no-check", action="store_true",
                      help="skip the safety checks (recorded in the output)")
    _scene_arguments(comp)
    comp.set_defaults(func=_cmd_compile)

    chk = sub.add_parser("check", help="replay a behaviour or trajectory in PyBullet and "
                         "report every safety check")
    chk.add_argument("path", metavar="FILE", help="a .aou file or a trajectory .json")
    chk.add_argument("--format", choices=("text", "json"), default="text")
    chk.add_argument("--no-dynamic", action="store_true",
                     help="kinematic checks only (skip the physics replay)")
    _recording_arguments(chk)
    _scene_arguments(chk)
    chk.set_defaults(func=_cmd_check)

    plot = sub.add_parser("plot", help="velocity profile of a behaviour or trajectory, or "
                          "the C-V map of several behaviours (--cv)")
    plot.add_argument("paths", nargs="+", metavar="FILE")
    plot.add_argument("-o", "--output", required=True, metavar="X.png|X.svg")
    plot.add_argument("--cv", action="store_true",
                      help="plot the C-V plane with each behaviour's inferred point")
    _recording_arguments(plot)
    plot.set_defaults(func=_cmd_plot)

    render = sub.add_parser("render", help="render a video of a behaviour or trajectory")
    render.add_argument("path", nargs="?", metavar="FILE")
    render.add_argument("-o", "--output", required=True, metavar="X.mp4|X.gif")
    render.add_argument("--side-by-side", nargs=2, metavar=("A", "B"),
                        help="render two behaviours next to each other")
    _render_arguments(render)
    _recording_arguments(render)
    _scene_arguments(render)
    render.set_defaults(func=_cmd_render)

    var = sub.add_parser("variants", help="write a pair of files that differ in one "
                         "descriptor (the study's Part B stimuli)")
    var.add_argument("path", metavar="FILE")
    var.add_argument("--vary", required=True, metavar="NAME=LOW,HIGH",
                     help="descriptor and its two values, in the descriptor's unit")
    var.add_argument("-o", "--output", metavar="DIR", help="folder (default: here)")
    var.add_argument("--render", metavar="X.mp4|X.gif",
                     help="also render the pair side by side")
    _render_arguments(var)
    _scene_arguments(var)
    var.set_defaults(func=_cmd_variants)

    meas = sub.add_parser("measure", help="measure the eleven descriptors of a trajectory")
    meas.add_argument("path", metavar="FILE", help="a trajectory .json, or a .csv recording")
    _recording_arguments(meas)
    meas.add_argument("--format", choices=("table", "json"), default="table")
    meas.set_defaults(func=_cmd_measure)

    rules = sub.add_parser("rules", help="list the diagnostic codes, or explain some")
    rules.add_argument("codes", nargs="*", metavar="CODE")
    rules.add_argument("--format", choices=("text", "json"), default="text")
    rules.set_defaults(func=_cmd_rules)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        return args.func(args)
    except KeyboardInterrupt:
        print("aouc: interrupted", file=sys.stderr)
        return EXIT_USAGE
    except BrokenPipeError:
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
