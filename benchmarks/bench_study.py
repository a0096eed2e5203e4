"""Benchmark of ``aouc study`` (docs/study.md), each figure beside its goal.

- build, cold: the paper's design (``aouc study init``: 4 Part A stimuli and 20 pairs, 44
  stimuli in 27 distinct videos at 640x480 and 30 frames a second) built from nothing
  with ``--jobs 2``;
- rebuild, warm: the same study after one behaviour changed (the confident stimulus's
  approach), as a share of the cold build: only that behaviour's videos are drawn again;
- rebuild, cached: nothing changed, nothing drawn;
- analyse, warm: the answers of 1,000 simulated participants read from their JSON file,
  analysed and written as the report (``aouc study analyze``'s work, in this process).

``AOU_BENCH_STUDY=tiny`` builds the same design at 64x48 and 4 frames a second instead:
on a busy machine the full build takes minutes, and the tiny one says the same of the
cache in seconds (the figures then say "tiny", and the build's goal is not judged).
"""

from __future__ import annotations

import os
import tempfile
import time

from speed import figure, say


def bench_study() -> None:
    from aou_dsl.study.analyze import analyze
    from aou_dsl.study.answers import read_answers
    from aou_dsl.study.build import build_study
    from aou_dsl.study.init import init_study
    from aou_dsl.study.report_files import write_report
    from aou_dsl.study.simulate import simulate
    from aou_dsl.study.spec import read_study

    tiny = os.environ.get("AOU_BENCH_STUDY") == "tiny"
    quiet = {"log": lambda m: None}
    with tempfile.TemporaryDirectory() as tmp:
        init_study(tmp)
        path = os.path.join(tmp, "study.toml")
        if tiny:
            text = open(path).read().replace("width = 640", "width = 64")
            text = text.replace("height = 480", "height = 48").replace("fps = 30", "fps = 4")
            with open(path, "w") as fh:
                fh.write(text)
        site = os.path.join(tmp, "site")
        study = read_study(path)
        design = "tiny design, 64x48 at 4 fps" if tiny else "the paper's design, 640x480 at 30 fps"
        t = time.perf_counter()
        got = build_study(study, site, jobs=2, **quiet)
        cold = time.perf_counter() - t
        say(f"study: {design}, {got['videos']} videos, --jobs 2")
        figure("study_build_cold_s", "build from nothing (cold)", cold, "s",
               at_most=None if tiny else 600.0)
        behaviour = os.path.join(tmp, "behaviours", "confident.aou")
        text = open(behaviour).read()
        with open(behaviour, "w") as fh:
            fh.write(text.replace("approach a=0.1", "approach a=0.12"))
        t = time.perf_counter()
        got = build_study(read_study(path), site, jobs=2, **quiet)
        warm = time.perf_counter() - t
        say(f"  one behaviour changed: {got['drawn']} of {got['videos']} videos drawn again "
            f"in {warm:.1f} s")
        figure("study_rebuild_share", "rebuild after one change, share of the cold build "
               "(warm)", 100 * warm / cold, "%", at_most=15.0)
        t = time.perf_counter()
        build_study(read_study(path), site, jobs=2, **quiet)
        figure("study_rebuild_cached_s", "rebuild, nothing changed (cached)",
               time.perf_counter() - t, "s", fmt="{:.2f}")
        results = os.path.join(tmp, "answers.json")
        import json

        with open(results, "w") as fh:
            json.dump(simulate(study, 1000, None), fh)
        t = time.perf_counter()
        rows = read_answers([results], study)
        write_report(os.path.join(tmp, "report"), analyze(rows, study), rows, [path, results])
        figure("study_analyze_1000_s", "analyse 1,000 participants (warm)",
               time.perf_counter() - t, "s", at_most=5.0, fmt="{:.2f}")
