"""Benchmarks of aou's speed claims; prints each figure beside its goal.

    python benchmarks/bench.py              # everything
    python benchmarks/bench.py build cold   # some sections
    python benchmarks/bench.py --json       # the figures as JSON on stdout (text on stderr)

Every time figure is printed with its kind: ``[cold]`` (a new process), ``[warm]`` (the
libraries and the arm loaded, the motion new: values changed in every primitive) or
``[cached]`` (the same input again, or one only partly new); see ``speed.py``. The goals
are judged on warm figures (cold ones for the start).

Sections: ``build`` (the checked build of a new motion, in-process and through ``aouc
compile``), ``cold`` (cold starts against their import floors), ``lint`` (long files, many
files), ``jobs`` (``--jobs N``'s warm pool), ``sweep`` (``--jobs 2`` against ``--jobs 1``
on 40 different motions), ``render`` (a 640x480 video), ``measure`` (60 s at 1 kHz),
``compile`` (below), ``replan`` (a live re-plan, ``bench_replan.py``), ``house`` (the
warm session: re-lint and rebuild; ``--jobs 2`` against ``--jobs 1``, cold,
``house.py``), ``studio`` (``aouc studio``, ``bench_studio.py``), ``editor`` (the language
server and ``aouc fmt``, ``bench_editor.py``), ``dmp`` (behaviours as DMPs,
``bench_dmp.py``), ``track`` (``--track``, ``bench_track.py``), ``live`` (the perception
loop, ``bench_live.py``); see ``speed.py`` for
``build`` to ``render``. Ratios
are measured in one run, so they hold on any machine; absolute times are this
machine's (its cores and load are in the JSON). The JSON lists every figure with its
goal (null for a figure that only says where the time goes) and whether it is met, and
a summary of the goals.

compile, per shipped behaviour:
- cold: a fresh Python process that imports aou and compiles the file (imports, robot
  model loading and all), as `aouc compile` does once;
- warm: the median of `compile_behaviour` calls in one process, each of a motion it has
  not seen (the behaviour with every primitive's values varied: the case of a robot
  that recompiles as its uncertainty changes), garbage collector paused as timeit does;
- the real-time factor: trajectory duration / warm compile time;
- by hand: the same Cartesian path, sampled at the same rate with linear timing, solved
  with `pybullet.calculateInverseKinematics` per sample, as a user would without aou;
  speed and accuracy (worst position error against the path, worst gaze error) side by
  side with aou's.
"""

from __future__ import annotations

import gc
import statistics
import subprocess
import sys
import time
from pathlib import Path

import bench_dmp
import bench_live
import bench_studio
import bench_study
import bench_track
import numpy as np
import speed
from bench_editor import bench_editor
from house import bench_house
from speed import figure, load, say, variant

ROOT = Path(__file__).resolve().parent.parent
BEHAVIOURS = ["confident", "curious", "hesitant", "fearful", "inactive"]


def _cold(path: Path) -> float:
    code = ("import time; t = time.perf_counter()\n"
            "from aou_dsl.lang.linter import lint_file\n"
            "from aou_dsl.compiler.pipeline import compile_behaviour\n"
            f"r = compile_behaviour(lint_file({str(path)!r}).behaviour)\n"
            "assert r.ok\n"
            "print(time.perf_counter() - t)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.strip().splitlines()[-1])


def _errors(arm, q: np.ndarray, pos: np.ndarray, goal: np.ndarray) -> tuple[float, float]:
    """Worst position error [mm] against ``pos`` and worst gaze error [deg]."""
    p, r = arm.fk(q)
    perr = np.linalg.norm(p - pos, axis=1).max() * 1000
    g = goal - p
    cos = np.einsum("ij,ij->i", r[:, :, 2], g) / np.linalg.norm(g, axis=1)
    return float(perr), float(np.degrees(np.arccos(np.clip(cos, -1, 1))).max())


def _by_hand(res, arm) -> tuple[float, np.ndarray, np.ndarray]:
    """The path sampled with linear timing; IK by PyBullet per sample. Returns the time
    [s] and the joint path, plus the targets it was asked for."""
    from aou_dsl.lang.timeline import Pose
    from aou_dsl.robot.scene import Scene

    tr, tl, frame = res.trajectory, res.timeline, res.frame
    targets = []
    for (_, t0, t1), ep in zip(tr.episodes, tl.episodes, strict=True):
        n = max(1, int(round((t1 - t0) * (1 / (tr.t[1] - tr.t[0])))))
        for x in np.arange(n) / n:  # linear timing: constant speed over the episode
            a, b = ep.start, ep.end
            targets.append(frame.target(Pose(a.d + x * (b.d - a.d), a.h + x * (b.h - a.h),
                                             a.v + x * (b.v - a.v),
                                             a.roll + x * (b.roll - a.roll))))
    scene = Scene(tr.robot)
    pb = scene.pb
    scene.set_arm(tr.q[0])
    out = np.empty((len(targets), arm.n))
    start = time.perf_counter()
    for i, (p, r) in enumerate(targets):
        quat = _quat(r)
        sol = pb.calculateInverseKinematics(scene.body, scene.ee_link, p.tolist(), quat,
                                            maxNumIterations=100, residualThreshold=1e-6,
                                            physicsClientId=scene.client)
        q = np.array(sol[:arm.n])
        scene.set_arm(q)  # warm start the next sample, as a careful user would
        out[i] = q
    elapsed = time.perf_counter() - start
    scene.close()
    return elapsed, out, np.array([p for p, _ in targets])


def _quat(r: np.ndarray) -> list[float]:
    """Rotation matrix -> PyBullet quaternion (x, y, z, w)."""
    import pinocchio as pin

    q = pin.Quaternion(r)
    return [q.x, q.y, q.z, q.w]


def bench_compile(repeat: int = 15) -> None:
    from aou_dsl.compiler.pipeline import compile_behaviour, target_path
    from aou_dsl.lang.linter import lint_file, lint_source
    from aou_dsl.robot.load import load_arm

    say(f"compile (panda, 250 Hz); warm: {repeat} new motions of each behaviour; {load()}")
    say(f"{'behaviour':<10}{'cold s':>8}{'warm ms':>9}{'motion s':>9}{'RTF':>7}"
          f"{'by-hand ms':>11}{'speed-up':>9}  {'pos err mm aou/hand':>20}"
          f"  {'gaze err deg aou/hand':>22}")
    for name in BEHAVIOURS:
        path = ROOT / "behaviours" / f"{name}.aou"
        cold = _cold(path)
        b = lint_file(str(path)).behaviour
        compile_behaviour(b)
        text = path.read_text()
        lints = [lint_source(variant(text, k), f"{name}_{k}.aou") for k in range(1, repeat + 1)]
        # As timeit does: collect, then keep the garbage collector out of the timed runs,
        # so that garbage left by the previous behaviour's by-hand run is not charged here.
        gc.collect()
        gc.disable()
        times = []
        try:
            for lint in lints:  # each a motion this process has not compiled
                t = time.perf_counter()
                res = compile_behaviour(lint.behaviour, timeline=lint.timeline)
                times.append(time.perf_counter() - t)
        finally:
            gc.enable()
        warm = statistics.median(times)
        tr = res.trajectory
        arm = load_arm(tr.robot)
        goal = np.asarray(tr.goal)
        pos, _ = target_path(res)
        aou_p, aou_g = _errors(arm, tr.q, pos, goal)
        hand_t, hand_q, hand_pos = _by_hand(res, arm)
        hand_p, hand_g = _errors(arm, hand_q, hand_pos, goal)
        if name == "hesitant":
            hesitant = (warm, tr.duration / warm, hand_t / warm)
        say(f"{name:<10}{cold:>8.2f}{warm * 1000:>9.1f}{tr.duration:>9.2f}"
              f"{tr.duration / warm:>7.0f}{hand_t * 1000:>11.1f}{hand_t / warm:>9.1f}"
              f"  {aou_p:>9.4f} / {hand_p:<8.4f}  {aou_g:>10.4f} / {hand_g:<9.4f}")
    warm, rtf, speedup = hesitant
    figure("compile_warm_hesitant_ms", "compile of a new hesitant motion", warm * 1000, "ms",
           kind="warm", at_most=100.0)
    figure("compile_rtf", "compile real-time factor (hesitant)", rtf, "", kind="warm",
           at_least=250.0, fmt="{:.0f}")
    figure("compile_vs_by_hand", "faster than by hand (hesitant)", speedup, "x", kind="warm",
           at_least=10.0)


def bench_measure() -> None:
    from aou_dsl.compiler.pipeline import CompileOptions, compile_behaviour
    from aou_dsl.lang.linter import load
    from aou_dsl.measuring.measured import measure

    text = "approach a=0.05\npause 2s x14\nretreat 0.05m a=0.1 x8\ngaze horizontal 15deg x4\n"
    b, _ = load(text, "long.aou")
    res = compile_behaviour(b, CompileOptions(rate=1000.0))
    rec = res.trajectory
    measure(rec)  # load the robot model once
    times = []
    for k in range(1, 6):  # every sample moved by a nanoradian more: new to every memo
        new = rec.with_(q=rec.q + 1e-9 * k)
        t = time.perf_counter()
        m = measure(new)
        times.append(time.perf_counter() - t)
    say(f"measure: {res.trajectory.duration:.1f} s of motion at 1 kHz ({len(rec.t)} samples), "
        f"{len(m.episodes)} episodes found")
    figure("measure_60s_1khz_s", "measure of 60 s at 1 kHz, new samples", statistics.median(times),
           "s", kind="warm", at_most=1.0, fmt="{:.3f}")


_NOISY = (
    "import time\n"
    "import numpy as np\n"
    "from aou_dsl.compiler.pipeline import CompileOptions, compile_behaviour\n"
    "from aou_dsl.lang.linter import load\n"
    "text = 'approach a=0.05\\npause 2s x14\\nretreat 0.05m a=0.1 x8\\n"
    "gaze horizontal 15deg x4\\n'\n"
    "b, _ = load(text, 'long.aou')\n"
    "rec = compile_behaviour(b, CompileOptions(rate=1000.0)).trajectory\n"
    "clean = np.asarray(rec.q)\n"
    "q = clean + np.random.default_rng(0).normal(0, 3e-4, np.shape(clean))\n"
    "rec = rec.with_(q=q, qd=None, qdd=None)\n"
)


def bench_measure_noisy() -> None:
    """Measuring a 60 s recording at 1 kHz with uncertainties (3e-4 rad of noise on every
    joint), in CPU seconds of the process (the machine is shared: its wall clock counts
    the other processes' turns): cold, a fresh process's first measurement (imports,
    robot model, the re-noised copies); warm, the median of three in one process that
    measured one before, each a recording it has not seen (a new draw of the noise: the
    same recording again would find its forward kinematics kept, a cached figure)."""
    cold = ("t = time.process_time()\n"
            "from aou_dsl.measuring.measured import measure\n"
            "m = measure(rec)\n"
            "print(time.process_time() - t, len(m.uncertainty))")
    out = subprocess.run([sys.executable, "-c", _NOISY + cold], capture_output=True,
                         text=True, check=True)
    cold_s, spreads = out.stdout.split()
    warm = ("from aou_dsl.measuring.measured import measure\n"
            "measure(rec)\n"
            "ts = []\n"
            "for seed in (1, 2, 3):  # each a recording this process has not measured\n"
            "    new = rec.with_(q=clean + np.random.default_rng(seed).normal(0, 3e-4, "
            "np.shape(q)))\n"
            "    t = time.process_time(); measure(new); ts.append(time.process_time() - t)\n"
            "print(sorted(ts)[1])")
    out = subprocess.run([sys.executable, "-c", _NOISY + warm], capture_output=True,
                         text=True, check=True)
    say(f"measure with uncertainties: 60 s at 1 kHz, 3e-4 rad of noise, {spreads} "
        "descriptors with an interval (CPU time)")
    figure("measure_noisy_60s_1khz_cold_s", "measure of a noisy 60 s at 1 kHz with "
           "uncertainties, CPU", float(cold_s), "s", kind="cold", fmt="{:.2f}")
    figure("measure_noisy_60s_1khz_warm_s", "measure of a noisy 60 s at 1 kHz with "
           "uncertainties, CPU", float(out.stdout.strip()), "s", kind="warm", at_most=1.0,
           fmt="{:.2f}")


SECTIONS = {"build": speed.bench_build, "cold": speed.bench_cold, "lint": speed.bench_lint,
            "jobs": speed.bench_jobs, "sweep": speed.bench_sweep, "render": speed.bench_render,
            "measure": bench_measure,
            "measure_noisy": bench_measure_noisy, "compile": bench_compile,
            "replan": speed.bench_replan,
            "house": bench_house,
            "studio": bench_studio.bench_studio, "editor": bench_editor,
            "dmp": bench_dmp.bench_dmp, "track": bench_track.bench_track,
            "study": bench_study.bench_study}
SECTIONS["live"] = bench_live.bench_live


def main(argv: list[str]) -> int:
    as_json = "--json" in argv
    what = [a for a in argv if a != "--json"] or list(SECTIONS)
    unknown = [w for w in what if w not in SECTIONS]
    if unknown:
        print(f"unknown section(s) {', '.join(unknown)}; choose from {', '.join(SECTIONS)}",
              file=sys.stderr)
        return 2
    if as_json:
        speed.OUT = sys.stderr
    for w in what:
        SECTIONS[w]()
    if as_json:
        print(speed.as_json())
    missed = [f.key for f in speed.FIGURES if f.met is False]
    say(f"goals met: {sum(f.met is True for f in speed.FIGURES)} of "
        f"{sum(f.met is not None for f in speed.FIGURES)}"
        + (f" (not met: {', '.join(missed)})" if missed else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
