"""The report's figures: `aouc study analyze` draws the answers chosen per Part A
expression and Part B's four answers per pair as SVG files beside the report, linked
from report.md and shown in report.html, the same bytes every run, each bar as long as
the number of participants who gave its answer (counted here from the simulated rows)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import pytest

AOUC = [sys.executable, "-m", "aou_dsl"]
SVG = "{http://www.w3.org/2000/svg}"
STATES = ("confident", "curious", "hesitant", "fearful", "others", "none")
PART_B = ("low", "high", "both", "neither")


def aouc(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*AOUC, *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def made(tmp_path_factory) -> dict:
    """The paper's design, 40 simulated participants, analysed twice."""
    folder = tmp_path_factory.mktemp("figures")
    assert aouc("study", "init", str(folder / "s")).returncode == 0
    study, results = folder / "s" / "study.toml", folder / "r.json"
    run = aouc("study", "simulate", str(study), "--participants", "40", "-o", str(results))
    assert run.returncode == 0, run.stderr
    for rep in ("one", "two"):
        run = aouc("study", "analyze", str(results), "--study", str(study), "-o",
                   str(folder / rep))
        assert run.returncode == 0, run.stderr
    return {"study": study, "results": results, "one": folder / "one", "two": folder / "two",
            "rows": json.loads(results.read_text())}


def _bars(svg: Path) -> dict[str, tuple[float, float]]:
    """Each group whose id is QUESTION-ANSWER: the width and height of its path."""
    out = {}
    for g in ET.parse(svg).getroot().iter(f"{SVG}g"):
        gid = g.get("id", "")
        if not re.fullmatch(r"[AB]\d+-[a-z]+", gid):
            continue
        path = g.find(f"{SVG}path")
        assert path is not None, gid
        nums = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", path.get("d", ""))]
        xs, ys = nums[0::2], nums[1::2]
        out[gid] = (max(xs) - min(xs), max(ys) - min(ys))
    return out


def _counts(rows: list[dict], part: str, field: str) -> Counter:
    return Counter(f"{r['aou_item']}-{r[field]}" for r in rows if r.get("aou_part") == part)


@pytest.mark.parametrize("name,part,field,options,axis", [
    ("figure-part-a.svg", "A", "state", STATES, 1),
    ("figure-part-b.svg", "B", "answer", PART_B, 0)])
def test_each_bar_is_as_long_as_its_count(made, name, part, field, options, axis):
    """One bar per question and answer (zero answers: a bar of no length); the bars'
    lengths divided by the counts of the simulated rows are one scale."""
    bars = _bars(made["one"] / name)
    n = 4 if part == "A" else 20
    assert set(bars) == {f"{part}{i}-{o}" for i in range(1, n + 1) for o in options}
    counts = _counts(made["rows"], part, field)
    assert sum(counts.values()) == 40 * n
    scales = [bars[gid][axis] / c for gid, c in counts.items() if c]
    assert max(scales) == pytest.approx(min(scales), rel=1e-4) and min(scales) > 0
    assert all(bars[gid][axis] == pytest.approx(0, abs=1e-6) for gid in bars
               if not counts[gid])
    res = json.loads((made["one"] / "results.json").read_text())
    key = "part_a" if part == "A" else "part_b"
    assert {f"{e['id']}-{o}": v["count"] for e in res[key] for o, v in e["options"].items()
            if v["count"]} == {k: v for k, v in counts.items() if v}


def test_the_figures_are_svg_linked_from_the_report_and_the_same_bytes(made):
    for name in ("figure-part-a.svg", "figure-part-b.svg"):
        one, two = made["one"] / name, made["two"] / name
        assert ET.parse(one).getroot().tag == f"{SVG}svg"
        assert one.read_bytes() == two.read_bytes()
        assert f"]({name})" in (made["one"] / "report.md").read_text()
        assert f'<img src="{name}"' in (made["one"] / "report.html").read_text()
    text = (made["one"] / "figure-part-a.svg").read_text()
    assert "<dc:date>" not in text


def test_without_matplotlib_the_report_says_so(made, tmp_path, monkeypatch):
    """The analysis needs the `study` extra only: without matplotlib the report is
    written, without figures, and says why."""
    from aou_dsl.study.analyze import analyze
    from aou_dsl.study.answers import read_answers
    from aou_dsl.study.report_files import write_report
    from aou_dsl.study.spec import read_study

    study = read_study(str(made["study"]))
    rows = read_answers([str(made["results"])], study)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    written = write_report(str(tmp_path / "rep"), analyze(rows, study), rows,
                           [str(made["study"])])
    assert sorted(Path(p).name for p in written) == ["answers.csv", "report.html",
                                                     "report.md", "results.json"]
    assert "need matplotlib" in (tmp_path / "rep" / "report.md").read_text()
