"""The parsers of the commands that take an action of their own: ``aouc study``,
``aouc dmp`` and ``aouc live``."""

from __future__ import annotations

import argparse

from .argtypes import force_option, int_in, number, point

__all__ = ["dmp_parser", "live_parser", "study_parser"]


def study_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``aouc study`` parser (``init``, ``build``, ``serve``, ``simulate``,
    ``analyze``; docs/study.md)."""
    study = sub.add_parser("study", help="a perception study of behaviours: its file, "
                           "simulated participants, the analysis (needs the `study` extra)")
    acts = study.add_subparsers(dest="action", metavar="ACTION", required=True)
    init = acts.add_parser("init", help="write a study file of the paper's design in DIR")
    init.add_argument("folder", metavar="DIR")
    init.add_argument("--force", action="store_true", help="replace files already there")
    bld = acts.add_parser("build", help="the study as a static jsPsych experiment in DIR "
                          "(videos, page; the manifest beside it as DIR.manifest.json)")
    bld.add_argument("study", metavar="STUDY.toml")
    bld.add_argument("-o", "--output", required=True, metavar="DIR")
    bld.add_argument("-j", "--jobs", type=int_in(0, 64), default=1, metavar="N",
                     help="videos drawn at once (0: one per core; default 1)")
    bld.add_argument("--jspsych", metavar="DIR",
                     help="copy jsPsych from this npm install (node_modules) into the study, "
                     "so that it runs offline (default: a pinned CDN version)")
    bld.add_argument("--jatos", action="store_true",
                     help="also write a JATOS study archive, DIR.jzip")
    srv = acts.add_parser("serve", help="serve a built study and store the answers in "
                          "DIR/answers.sqlite")
    srv.add_argument("folder", metavar="DIR")
    srv.add_argument("--port", type=int_in(0, 65535), default=8000, metavar="P",
                     help="port to serve on (default 8000; 0: any free one)")
    srv.add_argument("--host", default="127.0.0.1", metavar="H",
                     help="address to bind (default 127.0.0.1: this machine only)")
    sim = acts.add_parser("simulate", help="answers of simulated participants")
    sim.add_argument("study", metavar="STUDY.toml")
    sim.add_argument("--participants", type=int_in(1, 100_000), default=55, metavar="N")
    sim.add_argument("--policy", metavar="FILE.toml",
                     help="the probability of each answer per question (docs/study.md)")
    sim.add_argument("-o", "--output", required=True, metavar="RESULTS.json")
    ana = acts.add_parser("analyze", help="the study's statistics, as a report")
    ana.add_argument("results", nargs="+", metavar="RESULTS",
                     help="answers: JSON or CSV of jsPsych rows, the SQLite store, or a "
                     "JATOS results archive (.jrzip, .zip)")
    ana.add_argument("--study", required=True, metavar="STUDY.toml")
    ana.add_argument("--map", metavar="MAPPING.toml",
                     help="read each CSV as a Qualtrics-style export through this column "
                     "mapping (docs/study.md)")
    ana.add_argument("-o", "--output", required=True, metavar="REPORT_DIR")
    return study


def dmp_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``aouc dmp`` parser (``roll``)."""
    dmp = sub.add_parser("dmp", help="roll a behaviour's DMPs (--format dmp) out to a new "
                         "goal and tempo (needs the `dmp` extra; docs/dmp.md)")
    dmp.add_argument("action", choices=("roll",))
    dmp.add_argument("path", metavar="FILE.dmp", help="a folder `aouc compile --format dmp` "
                     "wrote")
    dmp.add_argument("--goal", type=point, metavar="X,Y,Z",
                     help="the new goal in metres (default: the one it was compiled for)")
    dmp.add_argument("--time-scale", type=number(0.25, 4.0, what="a time scale"), default=1.0,
                     metavar="K", help="durations times K, accelerations over K^2 (default 1)")
    dmp.add_argument("--intensity", type=number(0.0, 1.0, what="an intensity"),
                     metavar="I", help="in [0, 1] (default: the behaviour's own)")
    from ..dmp.parts import pinnable

    dmp.add_argument("--pin", action="append", default=[], choices=pinnable(),
                     help="keep the peak acceleration of these motions whatever the goal "
                     "(repeatable)")
    dmp.add_argument("-o", "--output", metavar="FILE",
                     help="write the solved trajectory (.json, .csv, .npz)")
    dmp.add_argument("--no-check", action="store_true", help="skip the safety replay")
    return dmp


def live_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    live = sub.add_parser("live", help="run the perception loop on a scenario headless: "
                          "perception, regulator, re-planned motion, checks (docs/live.md)")
    live.add_argument("path", metavar="SCENARIO.toml", help="a scenario file")
    live.add_argument("--robot", metavar="NAME", default="panda", help="the arm (panda)")
    live.add_argument("--perception", choices=("geometric", "camera"), default="geometric",
                      help="geometric: the fitted model (fast, deterministic); camera: a "
                      "rendered camera and an AprilTag detector (the perception extra)")
    live.add_argument("-o", "--output", metavar="RUN.json",
                      help="write the recording: the executed trajectory (aouc measure "
                      "reads it) and, per tick, confidence, uncertainty, state, intensity")
    live.add_argument("--render", metavar="RUN.mp4",
                      help="write a video: the camera's view, the confidence and the arm")
    live.add_argument("-q", "--quiet", action="store_true", help="print no summary")
    force_option(live)
    return live
