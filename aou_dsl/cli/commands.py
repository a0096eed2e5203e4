"""``aouc``: the command line. Thin: each command calls the library and formats records.

Exit codes: 0 no error, 1 the input has errors (or warnings under ``--strict``), 2 usage
or I/O problems, and internal errors (a one-line message; ``--debug`` shows the
traceback), 130 interrupted (Ctrl-C). A 2 is never hidden by a flag. Every command that
writes obeys one output rule (:func:`aou_dsl.core.files.guard_output`), given the files it
reads (:func:`aou_dsl.robot.files_read.files_read`).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence

from ..core.codes import C306, C311, C320, C321
from ..core.diagnostics import AouError, Diagnostic, Severity, Span
from ..editor import cmd_server
from .args import (
    EXIT_ERRORS,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USAGE,
    exit_for,
    scene_kw,
    shared_parser,
    usage_error,
)
from .dmp_cmd import cmd_dmp
from .endings import CtrlC, extra_missing, internal
from .fmt import cmd_fmt
from .lint_cmd import cmd_lint
from .lint_cmd import count as _count
from .live_cmd import cmd_live
from .report import format_json
from .report import print_diagnostics as _print_diags
from .study_cmd import cmd_study
from .tools import cmd_robot, cmd_rules, cmd_synth

__all__ = ["EXIT_ERRORS", "EXIT_OK", "EXIT_USAGE", "main"]


def _fail(err: AouError) -> int:
    _print_diags(err.diagnostics)
    return exit_for(err.diagnostics)


def _package_dirs(args: argparse.Namespace) -> tuple[str, ...]:
    from ..core.options import package_dirs

    return package_dirs(getattr(args, "package_dir", None))


def _read_kw(args: argparse.Namespace) -> dict:
    return {"robot": args.robot, "goal": args.goal, "ee_frame": args.ee_frame,
            "angle_unit": args.angle_unit, "time_unit": args.time_unit,
            "package_dirs": _package_dirs(args)}


def read_motion(path: str, args: argparse.Namespace, **kw):
    """``path`` read with the command's options (``kw`` overrides them) and ``--map``."""
    from ..api import read_trajectory

    options, spec = _read_kw(args) | kw, getattr(args, "map", None)
    if not spec or path.endswith(".aou"):
        return read_trajectory(path, **options)
    from ..core.options import package_dirs as absolute
    from ..measuring.columns import column_map
    from ..measuring.recording import read_recording

    dirs = {"package_dirs": absolute(options["package_dirs"])}
    return read_recording(path, columns=column_map(spec), **(options | dirs))


def _reads(args: argparse.Namespace, paths: Sequence[str]) -> list[str]:
    """Every file the command reads (the output rule keeps its outputs off them), the
    meshes found through ``--package-dir`` too."""
    from ..robot.files_read import files_read

    return files_read(paths, getattr(args, "robot", None), _package_dirs(args))


# --- lint, rules, explain ---------------------------------------------------------------


def _cmd_explain(args: argparse.Namespace) -> int:
    from ..lang.linter import lint_file
    from .report import format_timeline

    r = lint_file(args.path)
    if not r.ok or r.behaviour is None or r.cv is None or r.timeline is None:
        _print_diags(r.diagnostics, sources={r.path: r.source or ""})
        return exit_for(r.diagnostics)
    print(format_timeline(r.behaviour, r.cv, r.timeline))
    return EXIT_OK


# --- compile ----------------------------------------------------------------------------


def _cmd_compile(args: argparse.Namespace) -> int:
    from ..core.diagnostics import has_errors
    from ..core.options import BuildOptions, SceneOptions
    from ..driver.parallel import build_many, default_jobs
    from ..lang.linter import collect_inputs
    from .ci_cmd import keep_changed, no_output_misused, write_sarif
    from .outputs import guard_outputs, put_output, where_built

    inputs, problems = collect_inputs(args.paths)
    if problems:
        _print_diags(problems)
        return EXIT_USAGE
    if no_output_misused(args):
        return EXIT_USAGE
    if args.changed_since:
        inputs = keep_changed(inputs, args.changed_since)
    sources = [src for src, _ in inputs]
    try:  # before any work: the output rule; reads comes back indexed for every write
        dests, fmt, reads = guard_outputs(args, inputs, _reads(args, sources))
    except AouError as err:
        return _fail(err)
    if args.csv_derivatives:
        from ..compiler.output import CSV_DERIVATIVES

        if fmt != "csv" or args.no_output:
            return usage_error("compile", "--csv-derivatives needs a CSV output "
                               "(--format csv, or -o FILE.csv)")
        fmt = CSV_DERIVATIVES
    options = BuildOptions(robot=args.robot, rate=args.rate, check=not args.no_check,
                           scene=SceneOptions(**scene_kw(args)),
                           collision_check=not args.no_collision_check,
                           controller=args.controller, package_dirs=_package_dirs(args),
                           fit=args.fit)
    if args.write_fitted and (len(inputs) != 1 or not args.fit):
        from .fitted import fitted_usage

        return fitted_usage("compile")
    if args.tracked and len(inputs) != 1:  # without --track: I504 (guard_outputs)
        return usage_error("compile", "--tracked needs --track and one .aou input")
    results = build_many(sources, options, args.jobs or default_jobs(), cluster=args.cluster,
                         encode=None if args.no_output else fmt,  # the workers encode
                         outputs=where_built(args, dests, fmt, reads))  # or even write
    worst = EXIT_OK
    found: list[Diagnostic] = []  # for --sarif
    for k, ((src, _), dest, res) in enumerate(zip(inputs, dests, results, strict=True), 1):
        from .fitted import original_text

        _print_diags(res.diagnostics, sources={src: res.lint.source or ""},
                     originals=original_text(res))
        if res.ok and res.header is not None and args.track:
            from .track_cmd import compile_tracked

            res = compile_tracked(args, res, reads)
        found += res.diagnostics
        # the header, not res.document: that makes the samples' lists, in this process
        if not res.ok or res.header is None:
            worst = max(worst, exit_for(res.diagnostics))
            print(f"[{k}/{len(inputs)}] {src}: failed, nothing written", file=sys.stderr)
            continue
        try:
            put_output(dest, res, fmt, reads)  # unless the process that built it did
        except AouError as err:
            worst = max(worst, _fail(err))
            continue
        tr = res.trajectory
        note = " (checks skipped)" if args.no_check else ""
        to = f" -> {dest}" if dest else " (nothing written)"
        print(f"[{k}/{len(inputs)}] {src}{to}: {tr.duration:.2f} s of motion, "
              f"{len(tr.t)} samples, compiled in {res.seconds:.2f} s{note}", file=sys.stderr)
        if has_errors(res.diagnostics):
            worst = max(worst, EXIT_ERRORS)
        if args.write_fitted:
            from .fitted import write_fitted

            worst = max(worst, write_fitted(args.write_fitted, res, [*reads, *filter(None, dests)]))
    if args.sarif:
        worst = max(worst, write_sarif(args.sarif, found, reads))
    return worst



# --- check, measure ---------------------------------------------------------------------


def _cmd_check(args: argparse.Namespace) -> int:
    from ..api import check
    from .ci_cmd import robot_refusals
    from .report import format_check
    from .track_cmd import check_tracking, guard_tracked, nothing_to_track

    if args.tracked:  # before any work: the output rule (and it needs --track)
        guard_tracked(args, _reads(args, [args.path]))
    if args.format == "sarif":
        from .ci_cmd import check_sarif

        return check_sarif(args, _read_kw(args), scene_kw(args), _check_diagnostics)
    if args.fit or args.write_fitted:
        from .fitted import check_fitted

        return check_fitted(args, _read_kw(args))
    with nothing_to_track(args):  # the arm refuses the file: --track says what to do
        tr = read_motion(args.path, args)
    refused = robot_refusals(args, tr)
    _print_diags(refused)
    if any(d.severity == Severity.ERROR for d in refused):
        return EXIT_ERRORS
    report = check(tr, dynamic=not args.no_dynamic, controller=args.controller,
                   **scene_kw(args))
    failed = _check_diagnostics(args.path, report)
    if args.format != "json":
        print(format_check(args.path, tr.robot, tr.t, report))
    more, tracking = check_tracking(args, tr, _reads(args, [args.path])) if args.track \
        else ([], None)
    failed += more
    if args.format == "json":
        print(format_json({"path": args.path, **report.to_json(),
                           **({"tracking": tracking} if args.track else {}),
                           "diagnostics": [d.to_json() for d in failed]}))
    _print_diags(failed)
    return EXIT_ERRORS if any(d.severity == Severity.ERROR for d in failed) else EXIT_OK


def _check_diagnostics(path: str, report) -> list[Diagnostic]:
    """A failed check as the code compile gives it (C311 the controller's jerk, C320 the
    torque, C321 the tracking error, C306 the rest): ``check`` never fails without a
    code."""
    from ..core.diagnostics import diag

    codes = {"joint-jerk": C311, "joint-torque": C320, "tracking-error": C321}
    out = [diag(codes.get(c.name, C306),
                f"{c.name} check failed" + ("" if c.time is None else f" at t={c.time:.3f}s")
                + f": {c.detail}", Span.whole_file(path), check=c.name, time=c.time,
                joint=c.joint, value=c.value, limit=c.limit) for c in report.failed()]
    if not report.ok and not out:
        out.append(diag(C306, "the checks failed", Span.whole_file(path)))
    return out


def _cmd_measure(args: argparse.Namespace) -> int:
    from ..api import measure
    from ..lang.cv import missing_descriptors
    from .report import format_measured

    if args.against:
        from .against import cmd_measure_against

        return cmd_measure_against(args, read_motion)
    tr = read_motion(args.path, args)
    m = measure(tr)
    missing = missing_descriptors(tr.goal)  # what the C-V point could not use
    if args.format == "json":
        doc = m.to_json()
        doc["cv"] = {**doc["cv"], "missing_descriptors": list(missing),
                     "placed": not missing}  # no goal: C and V without the gazes, no state
        if missing:
            doc["cv"]["state"] = None
        print(format_json({"path": args.path, "robot": tr.robot, **doc}))
    else:
        print(format_measured(args.path, tr.robot, m, missing))
        _print_diags(m.diagnostics)
    return EXIT_OK


# --- plot, render, variants --------------------------------------------------------------


def _cmd_plot(args: argparse.Namespace) -> int:
    from ..core.files import check_output
    from ..lang.linter import lint_paths
    from ..media.plot import FORMATS, cv_figure, profile_data, profile_figure, save

    reads = _reads(args, args.paths)
    if args.map and "=" not in args.map:  # a mapping file is an input too
        reads.append(args.map)
    check_output(args.output, FORMATS, reads=reads)
    if args.cv:
        results, problems = lint_paths(args.paths)
        bad = problems + [d for r in results if not r.ok for d in r.diagnostics]
        if bad:
            return _fail(AouError(bad))
        fig = cv_figure([(r.behaviour.name, r.cv) for r in results
                         if r.behaviour is not None and r.cv is not None])
    elif len(args.paths) != 1:
        print("aouc: plot takes one file (or --cv with several)", file=sys.stderr)
        return EXIT_USAGE
    else:
        tr = read_motion(args.paths[0], args)
        data = profile_data(tr)
        _print_diags(list(data.diagnostics))  # R405: no goal, no goal-distance panel
        fig = profile_figure(data)
    save(fig, args.output, reads)
    print(f"wrote {args.output}", file=sys.stderr)
    return EXIT_OK


def _render(paths: list[str], output: str, args: argparse.Namespace, read_kw: dict,
            reads: Sequence[str]) -> int:
    import time

    from ..api import read_trajectory
    from ..core.options import SceneOptions
    from ..media.render import Camera, check_output, render_video, start_workers

    check_output(output, reads)
    w, h = args.size
    camera = Camera(distance=args.camera_distance, yaw=args.camera_yaw,
                    pitch=args.camera_pitch, target=args.camera_target, width=w, height=h)
    workers = start_workers()  # they start while the motions are compiled or read
    try:
        motions = [read_trajectory(p, **read_kw) for p in paths]
    except BaseException:
        if workers is not None:
            workers.close()
        raise
    start = time.perf_counter()
    info = render_video(motions, output, fps=args.fps, camera=camera,
                        scene_options=SceneOptions(**scene_kw(args),
                                                   package_dirs=_package_dirs(args)),
                        workers=workers, inputs=reads)
    print(f"wrote {output}: {info['frames']} frames at {info['fps']:g} fps "
          f"({info['duration']:.2f} s), {info['size'][0]}x{info['size'][1]}, "
          f"{_count(info['drawn'], 'image')} drawn (a frame where the arm holds still "
          f"repeats one) in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return EXIT_OK


def _cmd_render(args: argparse.Namespace) -> int:
    paths = args.side_by_side or ([args.path] if args.path else [])
    if not paths:
        print("aouc: render takes FILE, or --side-by-side A B", file=sys.stderr)
        return EXIT_USAGE
    return _render(paths, args.output, args, _read_kw(args), _reads(args, paths))


def _cmd_variants(args: argparse.Namespace) -> int:
    from ..core.files import guard_output, write_atomic
    from ..lang.linter import lint_file
    from ..media.variants import base_stem, make_variants, parse_vary

    name, low, high = parse_vary(args.vary)
    reads = _reads(args, [args.path])
    base = lint_file(args.path)
    if not base.ok or base.behaviour is None or base.source is None:
        _print_diags(base.diagnostics, sources={args.path: base.source or ""})
        return exit_for(base.diagnostics)
    folder = args.output or "."
    variants = make_variants(base.behaviour, base.source, name, low, high,
                             os.path.join(folder, f"{base_stem(args.path)}-{name}"))
    for v in variants:  # both checked before either is written
        guard_output(v.path, reads, force=args.force)
    if args.render:
        from ..media.render import check_output

        check_output(args.render, [*reads, *(v.path for v in variants)])
    for v in variants:
        write_atomic(v.path, v.text.encode(), inputs=reads)
        print(f"wrote {v.path} ({name}={v.value:g})", file=sys.stderr)
    if args.render:
        return _render([v.path for v in variants], args.render, args, {},
                       [*reads, *(v.path for v in variants)])
    return EXIT_OK


def _cmd_studio(args: argparse.Namespace) -> int:
    from .studio_cmd import cmd_studio

    return cmd_studio(args)


_COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "lint": cmd_lint, "rules": cmd_rules, "explain": _cmd_explain,
    "compile": _cmd_compile, "check": _cmd_check, "measure": _cmd_measure,
    "plot": _cmd_plot, "render": _cmd_render, "variants": _cmd_variants,
    "robot": cmd_robot, "synth": cmd_synth, "studio": _cmd_studio,
    "fmt": cmd_fmt, "server": cmd_server, "dmp": cmd_dmp, "live": cmd_live,
    "study": cmd_study,
}


def main(argv: Sequence[str] | None = None) -> int:
    parser, commands = shared_parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # said with the usage of the command they were given to
        (commands.get(args.command) or parser).error(
            f"unrecognized arguments: {' '.join(extra)}")
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    with CtrlC() as ctrl_c:
        return _run(args, ctrl_c)


def _run(args: argparse.Namespace, ctrl_c: CtrlC) -> int:
    try:
        return _COMMANDS[args.command](args)
    except AouError as err:
        return _fail(err)
    except ImportError as exc:
        extra = None if ctrl_c.seen else extra_missing(args.command, exc)
        if extra is None:
            return internal(exc, args.debug, ctrl_c)
        print(f"aouc: this command needs the {extra} extra ({exc.name} is missing): "
              f"pip install '.[{extra}]' in aou's folder (the one with pyproject.toml)",
              file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("aouc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        return EXIT_OK
    except Exception as exc:  # noqa: BLE001 - the last line of defence
        return internal(exc, args.debug, ctrl_c)


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
