"""The scripts in examples/ and the README's Python example run, and do what they say."""

from __future__ import annotations

import ast
import contextlib
import io
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import BEHAVIOURS

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _run(script: str, out: Path) -> str:
    """Run ``examples/<script>`` from the repository root with ``out`` as its output folder;
    its standard output."""
    proc = subprocess.run([sys.executable, str(EXAMPLES / script), str(out)], cwd=ROOT,
                          check=True, timeout=300, capture_output=True, text=True)
    assert proc.stdout.strip(), f"{script} printed nothing"
    return proc.stdout


def _check_compile_loop(out: Path, stdout: str) -> None:
    rows = [line.split() for line in stdout.splitlines() if re.match(r"\s*\d+\.\d+\s", line)]
    assert len(rows) == 4, stdout
    for pause, declared, measured, _c, _v, state, _motion, seconds in rows:
        assert float(declared) == pytest.approx(float(pause))
        assert float(measured) == pytest.approx(float(pause), abs=0.02)
        assert state == "hesitant"
        assert float(seconds) > 0
    written = out / "hesitant-last.json"
    assert written.is_file() and f"wrote {written}" in stdout


def _check_measure_csv(out: Path, stdout: str) -> None:
    csv = out / "hesitant.csv"
    header = [r for r in csv.read_text().splitlines() if not r.startswith("#")][0]
    assert header.startswith("t,panda_joint1,")
    values = {line.split()[0]: line.split()[-2] for line in stdout.splitlines()
              if line.split() and line.split()[0].endswith(("_count", "_distance"))}
    assert values == {"pause_count": "5", "retreat_count": "3", "retreat_distance": "0.06"}
    assert "(hesitant)" in stdout


def _check_plot_profile(out: Path, stdout: str) -> None:
    for name in ("fearful-profile.png", "cv-map.png"):
        png = out / name
        assert png.read_bytes()[:8] == PNG_MAGIC, name
        assert f"wrote {png}" in stdout
    assert "shiver" in stdout and "retreat" in stdout


def _check_live_regulation(out: Path, stdout: str) -> None:
    png = out / "live-regulation.png"
    assert png.read_bytes()[:8] == PNG_MAGIC and f"wrote {png}" in stdout
    m = re.search(r"(\d+) ticks, (\d+) re-plans", stdout)
    assert m and m.group(1) == "600" and 1 <= int(m.group(2)) < 600, stdout


CHECKS = {
    "compile_loop.py": _check_compile_loop,
    "live_regulation.py": _check_live_regulation,
    "measure_csv.py": _check_measure_csv,
    "plot_profile.py": _check_plot_profile,
}


def test_every_example_is_tested_and_documented() -> None:
    scripts = sorted(p.name for p in EXAMPLES.glob("*.py"))
    assert scripts == sorted(CHECKS)
    for name in scripts:
        doc = ast.get_docstring(ast.parse((EXAMPLES / name).read_text()))
        assert doc and f"python examples/{name}" in doc, name


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(CHECKS))
def test_example_runs(script: str, tmp_path: Path) -> None:
    out = tmp_path / "out"
    CHECKS[script](out, _run(script, out))


def readme_python(text: str) -> str:
    """The first ```python block under the README's ``## Python`` heading (before the
    next ``## `` heading)."""
    section = re.search(r"^## Python[ \t]*\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert section, "README.md has no `## Python` section"
    block = re.search(r"^```python[ \t]*\n(.*?)^```", section.group(1), re.S | re.M)
    assert block, "the `## Python` section of README.md has no ```python block"
    return block.group(1)


def test_readme_python_runs(tmp_path: Path) -> None:
    """The README's Python example, run as a reader would from a checkout (its relative
    paths resolve against a copy of behaviours/ in a temporary folder)."""
    code = readme_python((ROOT / "README.md").read_text(encoding="utf-8"))
    shutil.copytree(BEHAVIOURS, tmp_path / "behaviours")
    printed = io.StringIO()
    old = os.getcwd()
    os.chdir(tmp_path)
    try:
        with contextlib.redirect_stdout(printed):
            exec(compile(code, "README.md:## Python", "exec"), {"__name__": "__readme__"})
    finally:
        os.chdir(old)
    assert printed.getvalue().strip(), "the README's Python example printed nothing"
