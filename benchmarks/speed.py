"""The speed goals of aou, measured: each figure printed beside its goal (see bench.py).

Every time figure says its kind:

- **cold**: a new process (imports, robot loading and all);
- **warm**: the libraries and the arm loaded, the input new: motions this process has
  not seen, values changed in every primitive (:func:`variants`), so that no memo of
  an earlier build can answer;
- **cached**: the same input again, or one only partly new (one value moved, a comment
  added), where what did not change is answered by what the process kept.

Goals are judged on warm figures (and on cold ones where the goal is the start).

Sections (each a function of this module):

- ``build``: the checked build of hesitant (lint, compile, safety replay, measure) in
  one process, as a robot re-planning would run it: warm through ``aou_dsl.compile``
  and end to end through ``aouc compile FILE -o out.json`` (the JSON written), and the
  same input again (cached); the real-time factor and where the warm time goes.
- ``cold``: ``aouc compile`` and ``aouc lint`` started fresh, against the time Python
  takes to import what they depend on (ratios measured in the same run, interleaved).
- ``lint``: time and memory of linting ever longer files (linear? bounded?), and a
  folder of 1000 generated files.
- ``jobs``: ``aouc compile --jobs N``'s pool against one process, on new motions.
- ``sweep``: ``aouc compile --jobs 2`` against ``--jobs 1`` (each a new process) on 40
  different motions (hesitant with its values varied, each file new).
- ``render``: a 640x480 video of hesitant.aou against its duration.
- ``replan``: a live re-plan in the middle of a motion (``bench_replan.py``, whose
  printout is passed on), its median against its goal.
"""

from __future__ import annotations

import contextlib
import gc
import io
import json
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HESITANT = ROOT / "behaviours" / "hesitant.aou"
AOUC = [sys.executable, "-m", "aou_dsl"]


#: The kinds of a figure (module docstring); None: not a time (a size, a count, a ratio
#: of two kinds' times says its kinds in its label).
KINDS = ("cold", "warm", "cached")


@dataclass
class Figure:
    key: str
    label: str
    value: float
    unit: str
    kind: str | None
    goal: str | None = None
    met: bool | None = None


FIGURES: list[Figure] = []
OUT = sys.stdout  # bench.py points this at stderr under --json


def say(text: str) -> None:
    print(text, file=OUT, flush=True)


def figure(key: str, label: str, value: float, unit: str = "", *, kind: str | None,
           at_most: float | None = None, at_least: float | None = None,
           fmt: str = "{:.1f}") -> Figure:
    """Record and print one figure, its kind (:data:`KINDS`) first, beside its goal
    when it has one."""
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS} or None, not {kind!r}")
    goal, met = None, None
    if at_most is not None:
        goal, met = f"<= {fmt.format(at_most)} {unit}".rstrip(), value <= at_most
    elif at_least is not None:
        goal, met = f">= {fmt.format(at_least)} {unit}".rstrip(), value >= at_least
    f = Figure(key, label, float(value), unit, kind, goal, met)
    FIGURES.append(f)
    tail = "" if goal is None else f"   goal {goal}: {'met' if met else 'NOT MET'}"
    tag = "" if kind is None else f"[{kind}] "
    say(f"  {tag}{label}: {fmt.format(value)} {unit}{tail}".replace(" :", ":"))
    return f


def as_json() -> str:
    """Every figure (with its goal and whether it is met; null when it has none), a
    summary of the goals, and the machine."""
    goals = [f for f in FIGURES if f.met is not None]
    summary = {"goals": len(goals), "met": sum(bool(f.met) for f in goals),
               "not_met": [f.key for f in goals if not f.met]}
    return json.dumps({"figures": [asdict(f) for f in FIGURES], "summary": summary,
                       "machine": machine()}, indent=2)


def machine() -> dict:
    return {"cores": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else os.cpu_count(), "load": os.getloadavg()[0] if hasattr(os, "getloadavg")
            else None, "python": sys.version.split()[0]}


def _median_ms(fn, repeat: int, cpu: list[float] | None = None) -> tuple[float, object]:
    """Median wall time of ``fn()`` [ms], garbage collector paused as timeit does; the
    median CPU time of this process [ms] is appended to ``cpu`` when given (on a shared
    machine the wall time also counts the other processes' turns)."""
    out = None
    gc.collect()
    gc.disable()
    times, cpus = [], []
    try:
        for _ in range(repeat):
            t, c = time.perf_counter(), time.process_time()
            out = fn()
            times.append(time.perf_counter() - t)
            cpus.append(time.process_time() - c)
    finally:
        gc.enable()
    if cpu is not None:
        cpu.append(statistics.median(cpus) * 1000)
    return statistics.median(times) * 1000, out


# --- new motions -----------------------------------------------------------------------

#: The statements that make motion; every number in them is varied by :func:`variant`.
PRIMITIVES = ("approach", "pause", "retreat", "gaze", "shiver", "tilt")
_NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)")


def variant(text: str, k: int) -> str:
    """``text`` with every value of its primitives (not a repeat count ``xN``) scaled by
    ``1 - 0.003 k`` (k >= 1): the same behaviour, a motion no process has built (every
    primitive changes, so no memo of another build can answer)."""
    factor = 1.0 - 0.003 * k
    lines = []
    for line in text.splitlines():
        code, mark, comment = line.partition("#")
        words = code.split()
        if words and words[0] in PRIMITIVES:
            code = _NUMBER.sub(lambda m: f"{float(m.group(1)) * factor:.6g}", code)
        lines.append(code + mark + comment)
    return "\n".join(lines) + "\n"


def write_variants(folder: str, source: Path, ks: range, stem: str | None = None
                   ) -> list[str]:
    """:func:`variant` ``k`` of ``source`` for each k, each a file in ``folder``."""
    text = source.read_text()
    out = []
    for k in ks:
        path = Path(folder, f"{stem or source.stem}_{k:03d}.aou")
        path.write_text(variant(text, k))
        out.append(str(path))
    return out


def load() -> str:
    """The machine's load averages (1, 5, 15 min): a figure on a shared machine is only
    as good as the cores were free."""
    try:
        return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:  # not reported here
        return "load average unknown"


def _each_ms(fn, items: list, cpu: list[float] | None = None) -> tuple[float, object]:
    """Median wall time [ms] of ``fn(item)`` over ``items`` (each timed once: a warm
    figure times each new input once), garbage collector paused as timeit does; the
    median CPU time [ms] appended to ``cpu`` when given."""
    it = iter(items)
    return _median_ms(lambda: fn(next(it)), len(items), cpu)


# --- build ------------------------------------------------------------------------------


def _aouc_compile(path: str, out: str) -> None:
    """``aouc compile PATH -o OUT`` in this process (quietly)."""
    from aou_dsl.cli.commands import main

    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        code = main(["compile", path, "-o", out])
    if code != 0:
        raise RuntimeError(f"aouc compile {path} exited {code}")


def bench_build(repeat: int = 15) -> None:
    import aou_dsl
    from aou_dsl.compiler.pipeline import DEFAULT_RATE, compile_behaviour, sample
    from aou_dsl.driver.builder import CHECK_RATE
    from aou_dsl.lang.linter import lint_file
    from aou_dsl.measuring.measured import measure
    from aou_dsl.safety.replay import replay

    say("checked build of hesitant (lint, compile, safety replay, measure), one process; "
        f"warm: {repeat} motions each new (hesitant's values varied), {load()}")
    with tempfile.TemporaryDirectory() as tmp:
        # distinct motions for each figure, none built before it is timed
        primer, api, cli, stages = (write_variants(tmp, HESITANT, range(a, a + n), f"v{a}")
                                    for a, n in ((1, 3), (10, repeat), (40, repeat),
                                                 (70, repeat)))
        for path in primer:  # the libraries, the arm and the command line loaded
            assert aou_dsl.compile(path).ok
            _aouc_compile(path, path + ".json")
        cpu: list[float] = []
        api_ms, res = _each_ms(lambda p: aou_dsl.compile(p), api, cpu)
        assert res.ok, res.diagnostics
        cli_cpu: list[float] = []
        cli_ms, _ = _each_ms(lambda p: _aouc_compile(p, p + ".json"), cli, cli_cpu)
        lints: list = []
        lint_ms, _ = _each_ms(lambda p: lints.append(lint_file(p)), stages)
        comps: list = []
        compile_ms, _ = _each_ms(lambda lint: comps.append(
            compile_behaviour(lint.behaviour, timeline=lint.timeline)), lints)
        trs = [c.trajectory for c in comps]
        dense = [tr if DEFAULT_RATE >= CHECK_RATE else sample(c, CHECK_RATE)
                 for c, tr in zip(comps, trs, strict=True)]  # as the build samples it
        replay_ms, _ = _each_ms(replay, dense)
        measure_ms, _ = _each_ms(measure, trs)
        cached_ms, _ = _median_ms(lambda: aou_dsl.compile(api[0]), repeat)
    duration = res.trajectory.duration
    figure("build_api_ms", "checked build of a new motion, aou_dsl.compile (no output)",
           api_ms, "ms", kind="warm", at_most=60.0)
    figure("build_api_cpu_ms", "the same, CPU time of this process", cpu[0], "ms",
           kind="warm")
    figure("build_cli_ms", "checked build of a new motion end to end, `aouc compile FILE -o "
           "out.json` in a process that ran it before (JSON written)", cli_ms, "ms",
           kind="warm", at_most=80.0)
    figure("build_cli_cpu_ms", "the same, CPU time of this process", cli_cpu[0], "ms",
           kind="warm")
    figure("build_rtf", "real-time factor (motion / end-to-end checked build)",
           duration / cli_ms * 1000, "", kind="warm", at_least=270.0, fmt="{:.0f}")
    figure("build_cached_ms", "aou_dsl.compile of the same file again", cached_ms, "ms",
           kind="cached")
    say(f"  [warm] where the time goes: lint {lint_ms:.1f} ms, compile {compile_ms:.1f} ms, "
        f"safety replay {replay_ms:.1f} ms ({len(dense[-1].t)} samples), measure "
        f"{measure_ms:.1f} ms; the rest of aouc compile (arguments, the document, writing) "
        f"{cli_ms - api_ms:.1f} ms; motion {duration:.2f} s")
    figure("compile_ms", "compile alone, a new motion", compile_ms, "ms", kind="warm")
    figure("replay_ms", "safety replay, a new motion", replay_ms, "ms", kind="warm")
    figure("measure_ms", "measure, a new motion", measure_ms, "ms", kind="warm")
    figure("build_over_compile", "checked build / compile alone (both warm)",
           api_ms / compile_ms, "x", kind=None, fmt="{:.2f}")


# --- cold starts ------------------------------------------------------------------------


def _run(args: list[str], **kw) -> float:
    t = time.perf_counter()
    subprocess.run(args, capture_output=True, check=False, **kw)
    return time.perf_counter() - t


def _compile_dependencies(out: str) -> list[str]:
    """The modules of other packages that aou's own code imports during a cold
    ``aouc compile`` (what it depends on directly), in the order it imports them."""
    code = ("import builtins, sys\n"
            "seen = []\n"
            "real = builtins.__import__\n"
            "def spy(name, globals=None, locals=None, fromlist=(), level=0):\n"
            "    mod = real(name, globals, locals, fromlist, level)\n"
            "    caller = (globals or {}).get('__name__', '')\n"
            "    if caller.startswith('aou_dsl') and level == 0 and name.split('.')[0] not in"
            " sys.stdlib_module_names and not name.startswith('aou_dsl'):\n"
            "        for full in [name] + [f'{name}.{f}' for f in fromlist or ()"
            " if f'{name}.{f}' in sys.modules]:\n"
            "            if full not in seen:\n"
            "                seen.append(full)\n"
            "    return mod\n"
            "builtins.__import__ = spy\n"
            "from aou_dsl.cli.commands import main\n"
            f"main(['compile', {str(HESITANT)!r}, '-o', {out!r}])\n"
            "print(' '.join(seen))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       check=True)
    return r.stdout.strip().splitlines()[-1].split() if r.stdout.strip() else []


def _import_all(modules: list[str]) -> str:
    """Code that imports ``modules`` (quietly: PyBullet prints a banner)."""
    return ("import importlib, os, sys\n"
            "null = os.open(os.devnull, os.O_WRONLY); saved = os.dup(1); os.dup2(null, 1)\n"
            f"for m in {modules!r}:\n"
            "    try:\n"
            "        importlib.import_module(m)  # safe: aou's own module names, from its walk\n"
            "    except Exception:\n"
            "        pass\n"
            "os.dup2(saved, 1)\n")


def bench_cold(repeat: int = 7) -> None:
    say("cold starts: a fresh `aouc` against importing its dependencies (medians of "
        f"{repeat}, interleaved)")
    # An installed package has its bytecode compiled; make sure this checkout's is too.
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "aou_dsl")],
                   capture_output=True, check=False)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "h.json")
        deps = _compile_dependencies(out)  # also warms the parser cache
        tops = sorted({d.split(".")[0] for d in deps})
        say(f"  the modules aou imports from {', '.join(tops)}: {', '.join(deps)}")
        runs = {
            "compile floor": [sys.executable, "-c", _import_all(deps)],
            "aouc compile": [*AOUC, "compile", str(HESITANT), "-o", out],
            "lint floor": [sys.executable, "-c", "import lark, pydantic"],
            "aouc lint": [*AOUC, "lint", str(ROOT / "behaviours")],
        }
        times: dict[str, list[float]] = {k: [] for k in runs}
        for _ in range(repeat):
            for k, args in runs.items():
                times[k].append(_run(args, cwd=tmp))
    med = {k: statistics.median(v) * 1000 for k, v in times.items()}
    say(f"  {load()}")
    figure("cold_compile_ms", "`aouc compile behaviours/hesitant.aou -o h.json`",
           med["aouc compile"], "ms", kind="cold")
    figure("cold_compile_floor_ms", "importing its dependencies", med["compile floor"], "ms",
           kind="cold")
    figure("cold_compile_ratio", "cold compile / import floor (both cold)",
           med["aouc compile"] / med["compile floor"], "x", kind=None, at_most=1.2,
           fmt="{:.2f}")
    figure("cold_lint_ms", "`aouc lint behaviours/`", med["aouc lint"], "ms", kind="cold")
    figure("cold_lint_floor_ms", "`import lark, pydantic`", med["lint floor"], "ms",
           kind="cold")
    figure("cold_lint_ratio", "cold lint / import floor (both cold)",
           med["aouc lint"] / med["lint floor"], "x", kind=None, at_most=2.0, fmt="{:.2f}")


# --- lint -------------------------------------------------------------------------------

_LINT_ONE = ("import sys, time\n"
             "t = time.perf_counter()\n"
             "from aou_dsl.cli.commands import main\n"
             "import contextlib, io\n"
             "out = io.StringIO()\n"
             "with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):\n"
             "    main(['lint', sys.argv[1]])\n"
             "secs = time.perf_counter() - t\n"
             # The peak resident memory of this process (VmHWM: getrusage's would count
             # the benchmark that started it, which Linux carries across exec).
             "peak = [l for l in open('/proc/self/status') if l.startswith('VmHWM')]\n"
             "mb = int(peak[0].split()[1]) / 1024 if peak else float('nan')\n"
             "print(secs, mb, out.getvalue().count('\\n'))\n")


def _generated(rng: random.Random) -> str:
    """A behaviour like the shipped ones with other numbers (now and then a mistake)."""
    state = rng.choice(["confident", "curious", "hesitant", "fearful", "inactive"])
    lines = [f"# generated {rng.random():.6f}", f"behaviour gen : {state}",
             f"approach a={rng.uniform(0.03, 0.2):.3f}",
             f"pause {rng.uniform(0.6, 2.5):.2f}s x{rng.randint(1, 5)}"]
    if rng.random() < 0.5:
        lines.append(f"retreat {rng.uniform(0.02, 0.08):.3f}m a={rng.uniform(0.05, 0.5):.2f}"
                     f" x{rng.randint(1, 3)}")
    if rng.random() < 0.4:
        lines.append(f"gaze horizontal {rng.randint(5, 25)}deg x{rng.randint(1, 3)}")
    if rng.random() < 0.1:
        lines.append(rng.choice(["pause 1", "retreat 0.06m a=", "gaze sideways 10deg"]))
    return "\n".join(lines) + "\n"


def bench_lint() -> None:
    say("lint: ever longer files (each line an error), then 1000 generated files")
    with tempfile.TemporaryDirectory() as tmp:
        per_line = {}
        for n in (8000, 16000, 32000, 64000):
            path = os.path.join(tmp, f"long{n}.aou")
            Path(path).write_text("pause 1s\n" * n)
            r = subprocess.run([sys.executable, "-c", _LINT_ONE, path], capture_output=True,
                               text=True, check=True)
            secs, rss, printed = r.stdout.split()
            per_line[n] = float(secs) / n
            say(f"  [cold] {n:>6} lines ({os.path.getsize(path) / 1e6:.2f} MB): "
                f"{float(secs):.2f} s, peak memory {float(rss):.0f} MB, {printed} lines printed")
            last_rss = float(rss)
        figure("lint_time_per_line_growth", "time per line, 64k lines / 8k lines (each cold)",
               per_line[64000] / per_line[8000], "x", kind=None, at_most=1.5, fmt="{:.2f}")
        figure("lint_peak_mb_64k", "peak memory linting 64k lines", last_rss, "MB",
               kind=None)
        folder = os.path.join(tmp, "generated")
        os.makedirs(folder)
        rng = random.Random(14)
        for i in range(1000):
            Path(folder, f"g{i:04d}.aou").write_text(_generated(rng))
        secs = statistics.median(_run([*AOUC, "lint", folder]) for _ in range(3))
    figure("lint_files_per_s", "`aouc lint` of 1000 generated files (startup included)",
           1000 / secs, "files/s", kind="cold", at_least=500.0, fmt="{:.0f}")


# --- jobs -------------------------------------------------------------------------------


def _cpu_seconds(pids: list[int]) -> list[float]:
    """The CPU time (user + system) each process has used so far [s] (Linux)."""
    tick = os.sysconf("SC_CLK_TCK")
    out = []
    for pid in pids:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        out.append((int(fields[11]) + int(fields[12])) / tick)
    return out


def _spin(n: int = 4_000_000) -> None:
    while n:
        n -= 1


def _ceiling(cores: int) -> float:
    """How much faster ``cores`` processes do ``cores`` pure-Python loops than one process
    doing them one after the other, now: the most any parallel speed-up measured now can
    be (other programs, and the share of the processor the scheduler gives each session,
    cap it)."""
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    t = time.perf_counter()
    for _ in range(cores):
        _spin()
    one = time.perf_counter() - t
    procs = [ctx.Process(target=_spin) for _ in range(cores)]
    t = time.perf_counter()
    for p in procs:
        p.start()
    for p in procs:
        p.join()
    return one / (time.perf_counter() - t)


def bench_jobs(per: int = 3, rounds: int = 5) -> None:
    from aou_dsl.compiler.output import encode
    from aou_dsl.driver.parallel import BuildPool, build_many, default_jobs

    cores = default_jobs()
    shipped = sorted((ROOT / "behaviours").glob("*.aou"))
    say(f"`aouc compile --jobs {cores}`'s warm pool against one process, {per} new motions "
        f"of each shipped behaviour a round, the same for both and new each round, "
        f"{rounds} rounds (medians); {load()}")
    with tempfile.TemporaryDirectory() as tmp:

        def batch(r: int) -> list[str]:
            ks = range(1 + r * per, 1 + (r + 1) * per)
            return [p for src in shipped for p in write_variants(tmp, src, ks, f"{src.stem}")]

        list(build_many(batch(rounds), None, 1))  # this process warm too (other motions)
        t = time.perf_counter()
        with BuildPool(cores) as pool:
            start = time.perf_counter() - t
            walls, cpus, ceilings, same = [], [], [], True
            for r in range(rounds):  # interleaved: the machine's load changes
                paths = batch(r)
                c, t = time.process_time(), time.perf_counter()
                one = list(build_many(paths, None, 1))
                t1, c1 = time.perf_counter() - t, time.process_time() - c
                before, t = _cpu_seconds(pool.pids), time.perf_counter()
                many = list(pool.map(paths))
                tn = time.perf_counter() - t
                used = [b - a for a, b in zip(before, _cpu_seconds(pool.pids), strict=True)]
                walls.append(t1 / tn)
                cpus.append(c1 / max(max(used), 1e-9))
                ceilings.append(_ceiling(cores))
                same = same and all(
                    (a.document is None and b.document is None)
                    or encode(a.document, "json") == encode(b.document, "json")
                    for a, b in zip(one, many, strict=True))
    ceiling = statistics.median(ceilings)
    say(f"  {len(paths)} files a round; [cold] the pool started in {start:.2f} s, once; documents "
        f"identical to --jobs 1: {same}; {load()}; what {cores} processes can gain on this "
        f"machine now (pure-Python loops): {ceiling:.2f}x")
    figure("jobs_speedup", f"speed-up of a warm pool on {cores} cores", statistics.median(walls),
           "x", kind="warm", at_least=0.8 * min(cores, ceiling), fmt="{:.2f}")
    figure("jobs_cpu_speedup", "one process's CPU time / the busiest worker's",
           statistics.median(cpus), "x", kind="warm", at_least=0.8 * cores, fmt="{:.2f}")
    figure("jobs_identical", "outputs identical to --jobs 1", float(same), "", kind=None,
           at_least=1.0, fmt="{:.0f}")


# --- sweep ------------------------------------------------------------------------------


#: ``aouc`` (its ``main``, as ``python -m aou_dsl`` runs it) that says, last on its
#: standard error, the CPU time of its own process and of its workers [s].
_AOUC_CPU = ("import resource, sys\n"
             "from aou_dsl.cli.commands import main\n"
             "code = main(sys.argv[1:])\n"
             "me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, "
             "resource.RUSAGE_CHILDREN))\n"
             "print(me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime, file=sys.stderr)\n"
             "from aou_dsl.cli.endings import leave\n"
             "leave(code)  # as the aouc command ends\n")


def _aouc_run(args: list[str]) -> tuple[float, float, float]:
    """Wall time of one ``aouc`` process, and the CPU time of the process itself and of
    its workers [s]."""
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _AOUC_CPU, *args], cwd=ROOT,
                          capture_output=True, check=False)
    wall = time.perf_counter() - t
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.decode()[-2000:])
    own, workers = (float(x) for x in proc.stderr.decode().splitlines()[-1].split())
    return wall, own, workers


def _same_bytes(a: str, b: str) -> bool:
    names = sorted(os.listdir(a))
    return names == sorted(os.listdir(b)) and all(
        Path(a, n).read_bytes() == Path(b, n).read_bytes() for n in names)


def bench_sweep(files: int = 40, rounds: int = 3) -> None:
    """``aouc compile FOLDER --jobs 2`` against ``--jobs 1``, each a new process, on
    ``files`` different motions (hesitant with its values varied): the cold start of the
    command, then every file a motion the process has not seen."""
    say(f"`aouc compile --jobs 2` against `--jobs 1` on {files} different motions (hesitant "
        f"varied, each file new), each a new process, {rounds} rounds interleaved "
        f"(medians); {load()} at the start")
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "sweep")
        os.mkdir(src)
        write_variants(src, HESITANT, range(1, files + 1))
        _aouc_run(["lint", src])  # the parser's cache written, as any user's is
        ratios, cpu_ratios, paths, ceilings = [], [], [], []
        walls: dict[int, list[float]] = {1: [], 2: []}
        same = True
        for r in range(rounds):
            out = {j: os.path.join(tmp, f"out{r}_{j}") for j in (1, 2)}
            w1, c1, _ = _aouc_run(["compile", src, "-o", out[1] + "/", "--jobs", "1"])
            w2, own, workers = _aouc_run(["compile", src, "-o", out[2] + "/", "--jobs", "2"])
            ratios.append(w1 / w2)
            cpu_ratios.append((own + workers) / c1)
            # what the wall ratio is on two free cores: the busier process sets the pace
            paths.append(c1 / max(own, workers))
            walls[1].append(w1)
            walls[2].append(w2)
            ceilings.append(_ceiling(2))
            same = same and _same_bytes(out[1], out[2])
    say(f"  [cold] --jobs 1 {statistics.median(walls[1]):.2f} s, --jobs 2 "
        f"{statistics.median(walls[2]):.2f} s (medians); CPU time of --jobs 2 over --jobs "
        f"1's {statistics.median(cpu_ratios):.2f}; {load()} at the end; what 2 processes "
        f"can gain on this machine now (pure-Python loops): {statistics.median(ceilings):.2f}x")
    figure("sweep_jobs2_cpu_path", "--jobs 1 CPU time / the busier process's of --jobs 2 "
           "(the speed-up on two free cores)", statistics.median(paths), "x", kind="cold",
           fmt="{:.2f}")
    figure("sweep_jobs2_speedup", f"--jobs 1 time / --jobs 2 time, {files} different motions",
           statistics.median(ratios), "x", kind="cold", at_least=1.5, fmt="{:.2f}")
    figure("sweep_identical", "outputs of --jobs 2 byte-identical to --jobs 1", float(same), "",
           kind=None, at_least=1.0, fmt="{:.0f}")


# --- render -----------------------------------------------------------------------------


def bench_render() -> None:
    import resource

    from aou_dsl.driver.builder import build_file
    from aou_dsl.media.render import render_video

    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    say(f"render hesitant.aou at 640x480, 30 fps, mp4 ({cores} cores)")
    tr = build_file(str(HESITANT), check=False).trajectory

    def cpu() -> float:
        me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF,
                                                    resource.RUSAGE_CHILDREN))
        return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    with tempfile.TemporaryDirectory() as tmp:
        c, t = cpu(), time.perf_counter()
        info = render_video([tr], os.path.join(tmp, "h.mp4"), quiet=True)
        secs, used = time.perf_counter() - t, cpu() - c  # the drawing processes and ffmpeg
    ceiling = _ceiling(cores or 1)
    say(f"  [warm] {info['frames']} frames, {info['duration']:.2f} s of video in {secs:.1f} s, "
        f"{used:.1f} s of CPU time in all; load {os.getloadavg()[0]:.2f}; what {cores} "
        f"processes can gain on this machine now (pure-Python loops): {ceiling:.2f}x")
    figure("render_realtime_factor", "video duration / rendering time (motion compiled "
           "before)", info["duration"] / secs, "", kind="warm", at_least=1.0, fmt="{:.2f}")
    figure("render_cpu_realtime_factor", f"video duration / (CPU time / {cores} cores)",
           info["duration"] / (used / (cores or 1)), "", kind="warm", at_least=1.0,
           fmt="{:.2f}")


# --- replan -----------------------------------------------------------------------------


def bench_replan() -> None:
    """``bench_replan.py`` (panda, 20 re-plans): its printout, and its median as a figure."""
    import bench_replan

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        bench_replan.main([])
    text = out.getvalue()
    say(text.rstrip())
    found = re.search(r"\[warm\] re-plan: median ([0-9.]+) ms", text)
    if found is None:
        raise RuntimeError("bench_replan.py no longer prints its median re-plan time")
    figure("replan_ms", "mid-motion re-plan from a new state, the plans made before "
           "(median)", float(found.group(1)), "ms", kind="warm", at_most=100.0)
