"""``aouc study``: a perception study's file, simulated participants and analysis."""

from __future__ import annotations

import argparse
import json
import os
import sys

from .args import EXIT_OK

__all__ = ["cmd_study"]


def cmd_study(args: argparse.Namespace) -> int:
    if args.action == "init":
        from ..core.files import guard_output
        from ..study.init import init_study, written_names

        for name in written_names():
            guard_output(os.path.join(args.folder, name), force=args.force)
        for path in init_study(args.folder):
            print(f"wrote {path}", file=sys.stderr)
        return EXIT_OK
    if args.action == "serve":
        return _serve(args)
    from ..study.spec import read_study

    study = read_study(args.study)
    if args.action == "simulate":
        return _simulate(args, study)
    if args.action == "build":
        return _build(args, study)
    return _analyze(args, study)


def _simulate(args: argparse.Namespace, study) -> int:
    from ..core.files import write_atomic
    from ..study.simulate import read_policy, simulate

    policy = read_policy(args.policy, study) if args.policy else None
    reads = [args.study, *(p.path for p in study.part_a), *(p.path for p in study.pairs)]
    if args.policy:
        reads.append(args.policy)
    rows = simulate(study, args.participants, policy)
    write_atomic(args.output, (json.dumps(rows, indent=0) + "\n").encode(), inputs=reads)
    print(f"wrote {args.output}: {args.participants} simulated participants, "
          f"{len(rows)} rows", file=sys.stderr)
    return EXIT_OK


def _analyze(args: argparse.Namespace, study) -> int:
    from ..study.analyze import analyze
    from ..study.answers import read_answers
    from ..study.report_files import write_report

    rows = read_answers(args.results, study, args.map)
    res = analyze(rows, study)
    reads = [args.study, *args.results, *([args.map] if args.map else [])]
    for path in write_report(args.output, res, rows, reads):
        print(f"wrote {path}", file=sys.stderr)
    p = res["participants"]
    print(f"{p['kept']} of {p['answered']} participants analysed "
          f"({len(p['excluded'])} excluded)", file=sys.stderr)
    return EXIT_OK



def _build(args: argparse.Namespace, study) -> int:
    import time

    from ..driver.parallel import default_jobs
    from ..study.build import build_study, manifest_path

    start = time.perf_counter()
    got = build_study(study, args.output, jobs=args.jobs or default_jobs(),
                      jspsych=args.jspsych, jatos=args.jatos)
    print(f"wrote {args.output}: {got['videos']} videos ({got['drawn']} drawn, "
          f"{got['reused']} up to date) in {time.perf_counter() - start:.1f} s; "
          f"the manifest is {manifest_path(args.output)}"
          + (f", the JATOS archive {os.path.normpath(args.output)}.jzip" if args.jatos else ""),
          file=sys.stderr)
    return EXIT_OK


def _serve(args: argparse.Namespace) -> int:
    from ..core.codes import I501
    from ..core.diagnostics import AouError, Span, diag
    from ..core.files import is_own_output
    from ..study.serve import serve

    if not is_own_output(os.path.join(args.folder, "timeline.json")):
        raise AouError(diag(I501, f"`{args.folder}` is not a study `aouc study build` wrote "
                            "(it has no timeline.json of its own)",
                            Span.whole_file(args.folder)))
    return serve(args.folder, host=args.host, port=args.port)
