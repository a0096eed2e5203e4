"""Run the same inputs through two checkouts of aou and compare every output byte.

A change that should not move any output (a faster path, a dependency replaced) is
proven here: each checkout compiles the shipped behaviours, the valid test files and a
sample of generated files (tests/langgen.py) to JSON, CSV and NPZ, then measures every
compiled trajectory and a set of simulated recordings (tests/recsim.py: every logger
preset, the arm's dynamic replay for the behaviours, the document's own motion for
generated files) with ``aouc measure --format json``. Files and measurements must be the
same bytes, exit codes the same.

With ``--decoded``, a change of how numbers are written (not of what they are) passes:
files that differ in bytes are compared as what a reader gets from them (a JSON
document parsed; a CSV's cells as numbers, its comment lines' numbers too; an NPZ's
arrays and header), and only a difference there fails; those that differ only in bytes
are counted.

    python -m tests.twin_outputs --baseline /work/main --candidate . --cases 40 --out /tmp/twin

Each checkout runs in its own interpreter with ``PYTHONPATH`` at its root, so the same
venv serves both.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Output formats compiled for every source file (generated files: the first few only).
FORMATS = ("json", "csv", "npz")
#: Generated files also compiled to every format besides JSON.
ALL_FORMATS_CASES = 10


def write_sources(src: Path, cases: int, seed: int) -> None:
    """The inputs: shipped behaviours, the valid test files, ``cases`` generated files."""
    from tests.langgen import random_cases

    src.mkdir(parents=True, exist_ok=True)
    for folder in (ROOT / "behaviours", ROOT / "tests" / "valid"):
        for f in sorted(folder.glob("*.aou")):
            shutil.copy(f, src / f"{folder.name}_{f.name}")
    for i, case in enumerate(random_cases(cases, seed)):
        (src / f"gen{i:03d}_{case.stem}.aou").write_text(case.text)


def compile_all(tree: Path, src: Path, out: Path) -> dict[str, int]:
    """Every source compiled by ``tree`` in one ``aouc compile`` per format (JSON for
    all; the other formats for the non-generated files and the first generated ones).
    The exit code of each command."""
    codes = {}
    env = dict(os.environ, PYTHONPATH=str(tree))
    few = src.parent / "src_few"
    if not few.exists():
        few.mkdir()
        names = sorted(p.name for p in src.glob("*.aou"))
        gen = [n for n in names if n.startswith("gen")][:ALL_FORMATS_CASES]
        for n in [n for n in names if not n.startswith("gen")] + gen:
            shutil.copy(src / n, few / n)
    for fmt in FORMATS:
        folder = src if fmt == "json" else few
        cmd = [sys.executable, "-m", "aou_dsl", "compile", str(folder), "-o",
               str(out / fmt), "--format", fmt, "--jobs", "1"]
        codes[fmt] = subprocess.run(cmd, env=env, cwd=tree, capture_output=True).returncode
    return codes


def write_recordings(docs: Path, rec: Path) -> list[list[str]]:
    """Recordings of the compiled documents by every logger preset, written as the
    tests write them; the ``aouc measure`` arguments of each (compiled documents too)."""
    from tests.recsim import PRESETS, record, to_csv_text, to_json_doc
    from tests.recsim import _signal as replay

    rec.mkdir(parents=True, exist_ok=True)
    jobs = [[str(p)] for p in sorted(docs.glob("*.json"))]
    for p in sorted(docs.glob("*.json")):
        doc = json.loads(p.read_text())
        generated = p.name.startswith("gen")
        if generated and int(p.name[3:6]) >= ALL_FORMATS_CASES:
            continue
        signal = replay(doc, not generated, 1000.0)
        for name, log in PRESETS.items():
            r = record(doc, log, signal=signal)
            goal = ",".join(repr(float(v)) for v in r["goal"]["position"])
            if r.get("decimals") is not None or name.startswith("ros"):
                path = rec / f"{p.stem}.{name}.csv"
                path.write_text(to_csv_text(r))
                jobs.append([str(path), "--robot", r["robot"], "--goal", goal])
            else:
                path = rec / f"{p.stem}.{name}.json"
                path.write_text(json.dumps(to_json_doc(r)))
                jobs.append([str(path)])
    return jobs


def measure_all(jobs: list[list[str]], out: Path) -> None:
    """Run in a checkout's interpreter: ``aouc measure --format json`` of every job, its
    standard output and exit code written to ``out``."""
    import aou_dsl
    from aou_dsl.cli.commands import main

    print(f"measuring with {Path(aou_dsl.__file__).parent}")
    out.mkdir(parents=True, exist_ok=True)
    for i, argv in enumerate(jobs):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
            code = main(["measure", *argv, "--format", "json"])
        (out / f"{i:04d}.json").write_text(f"{code}\n{buf.getvalue()}")


def differences(a: Path, b: Path) -> tuple[int, list[str]]:
    """How many files were compared under ``a`` and ``b``, and those that differ (or
    exist on one side only)."""
    names = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    names |= {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    bad = [str(n) for n in sorted(names)
           if not ((a / n).is_file() and (b / n).is_file()
                   and (a / n).read_bytes() == (b / n).read_bytes())]
    return len(names), bad


def _same_value(a, b) -> bool:
    """Equal as decoded values: floats to the bit (a NaN equals a NaN), containers
    element by element."""
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a)
                                                      == math.copysign(1, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_value(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


_NUMBER = re.compile(r"-?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|nan|inf)")


def _cells(text: str) -> list:
    """A CSV (or any text) as a reader gets it: each line's tokens, numbers as floats."""
    return [[float(t) if _NUMBER.fullmatch(t) else t for t in re.split(r"([,:\[\]{} ])", line)]
            for line in text.splitlines()]


def _npz(data: bytes) -> dict:
    import numpy as np

    out = {}
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        for name in zf.namelist():
            raw = zf.read(name)
            out[name] = (np.load(io.BytesIO(raw), allow_pickle=False).tolist()
                         if name.endswith(".npy") else json.loads(raw))
    return out


def decoded_equal(a: Path, b: Path) -> bool:
    """Whether two files read as the same values (by their extension: JSON, CSV, NPZ;
    a measurement: its exit code line and its JSON)."""
    x, y = a.read_bytes(), b.read_bytes()
    try:
        if a.suffix == ".npz":
            return _same_value(_npz(x), _npz(y))
        if a.suffix == ".csv":
            return _same_value(_cells(x.decode()), _cells(y.decode()))
        if a.suffix == ".json":
            if a.parent.name == "measured":  # exit code, then the printed JSON
                (cx, jx), (cy, jy) = (t.decode().split("\n", 1) for t in (x, y))
                return cx == cy and _same_value(json.loads(jx or "null"),
                                                json.loads(jy or "null"))
            return _same_value(json.loads(x), json.loads(y))
    except (ValueError, zipfile.BadZipFile):
        return False
    return x == y


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--baseline", type=Path, required=True)
    p.add_argument("--candidate", type=Path, required=True)
    p.add_argument("--cases", type=int, default=40)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--decoded", action="store_true",
                   help="files that differ in bytes pass when they read as the same values")
    p.add_argument("--measure-jobs", type=Path, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.measure_jobs:  # the child: measure in this checkout
        measure_all(json.loads(args.measure_jobs.read_text()), args.out)
        return 0
    trees = {"baseline": args.baseline.resolve(), "candidate": args.candidate.resolve()}
    write_sources(args.out / "src", args.cases, args.seed)
    codes = {k: compile_all(t, args.out / "src", args.out / k / "compiled")
             for k, t in trees.items()}
    jobs = write_recordings(args.out / "baseline" / "compiled" / "json", args.out / "rec")
    (args.out / "jobs.json").write_text(json.dumps(jobs))
    for k, tree in trees.items():
        # Run as a script from the checkout's root: its aou_dsl comes first on the path.
        subprocess.run([sys.executable, str(Path(__file__).resolve()), "--baseline", ".",
                        "--candidate", ".", "--out", str(args.out / k / "measured"),
                        "--measure-jobs", str(args.out / "jobs.json")],
                       env=dict(os.environ, PYTHONPATH=str(tree)), cwd=tree, check=True)
    count, bad = differences(args.out / "baseline", args.out / "candidate")
    print(f"exit codes: {codes}")
    print(f"{count} files compared ({len(jobs)} measurements), {len(bad)} differ in bytes")
    if args.decoded:
        base, cand = args.out / "baseline", args.out / "candidate"
        values = [n for n in bad if not ((base / n).is_file() and (cand / n).is_file()
                                         and decoded_equal(base / n, cand / n))]
        print(f"{len(bad) - len(values)} of them read as the same values, {len(values)} "
              "differ when decoded")
        bad = values
    for name in bad:
        print(f"  differs: {name}")
    return 1 if bad or codes["baseline"] != codes["candidate"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
