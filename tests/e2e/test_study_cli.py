"""`aouc study init | simulate | analyze` as a researcher runs them: the paper's design,
simulated participants whose policy the analysis recovers, exclusions with reasons,
every store of answers, coded errors for bad files, the same bytes every run."""

from __future__ import annotations

import json
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from scipy import stats as sps

from aou_dsl.lang.declared import declared
from aou_dsl.lang.linter import lint_file
from tests.conftest import BEHAVIOURS

AOUC = [sys.executable, "-m", "aou_dsl"]


def aouc(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([*AOUC, *args], capture_output=True, text=True, timeout=300,
                          cwd=cwd)


@pytest.fixture(scope="module")
def study(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("study")
    run = aouc("study", "init", str(folder / "s"))
    assert run.returncode == 0, run.stderr
    return folder / "s" / "study.toml"


def test_init_writes_the_papers_design(study):
    """Four Part A behaviours that declare what the shipped stimuli declare, twenty Part
    B pairs, the paper's six answers."""
    from aou_dsl.study.spec import read_study

    s = read_study(str(study))
    assert [x.state for x in s.part_a] == ["confident", "curious", "hesitant", "fearful"]
    assert len(s.pairs) == 20 and s.options == ("confident", "curious", "hesitant",
                                                "fearful", "others", "none")
    for x in s.part_a:
        mine, shipped = lint_file(x.path), lint_file(str(BEHAVIOURS / f"{x.state}.aou"))
        assert declared(mine.behaviour, mine.timeline) == \
            declared(shipped.behaviour, shipped.timeline)
    again = aouc("study", "init", str(study.parent))
    assert again.returncode == 2 and "I506" in again.stderr  # not over the researcher's


def _analyze(study: Path, results: list[Path], out: Path) -> dict:
    run = aouc("study", "analyze", *map(str, results), "--study", str(study), "-o", str(out))
    assert run.returncode == 0, run.stderr
    return json.loads((out / "results.json").read_text())


def test_the_analysis_recovers_a_policy(study, tmp_path):
    """A state chosen by 80 % of simulated participants is found dominant for each
    expression; the counts, chi2 and Holm's p agree with scipy's test run here."""
    policy = tmp_path / "policy.toml"
    lines = []
    for i, state in enumerate(["confident", "curious", "hesitant", "fearful"], 1):
        others = [s for s in ("confident", "curious", "hesitant", "fearful") if s != state]
        lines += [f"[part_a.A{i}]", f"{state} = 0.8"] + [f"{o} = 0.05" for o in others] + \
            ["others = 0.03", "none = 0.02"]
    lines += ["[part_b.default]", "high = 0.8", "low = 0.1", "both = 0.05", "neither = 0.05"]
    policy.write_text("\n".join(lines) + "\n")
    results = tmp_path / "r.json"
    run = aouc("study", "simulate", str(study), "--participants", "55", "--policy",
               str(policy), "-o", str(results))
    assert run.returncode == 0, run.stderr
    res = _analyze(study, [results], tmp_path / "rep")
    assert [e["dominant"] for e in res["part_a"]] == ["confident", "curious", "hesitant",
                                                     "fearful"]
    assert all(e["verdict"] == "the high variant" for e in res["part_b"])
    rows = json.loads(results.read_text())
    for e in res["part_a"]:
        counts = [sum(r["aou_part"] == "A" and r["aou_item"] == e["id"] and r["state"] == o
                      for r in rows) for o in e["options"]]
        assert [v["count"] for v in e["options"].values()] == counts
        assert e["chi2"] == pytest.approx(sps.chisquare(counts).statistic)
    ps = [e["exact_p"] if e["exact_p"] is not None else e["p"]
          for e in res["part_a"] + res["part_b"]]
    assert [e["p_holm"] for e in res["part_a"] + res["part_b"]] == pytest.approx(_holm(ps))
    table = [[v["count"] for v in e["options"].values()] for e in res["part_a"]]
    used = [any(col) for col in zip(*table, strict=True)]
    table = [[c for c, keep in zip(row, used, strict=True) if keep] for row in table]
    assert res["independence"]["chi2"] == pytest.approx(
        sps.chi2_contingency(table, correction=False).statistic)
    assert res["confusion"]["hesitant"]["hesitant"] == res["part_a"][2]["options"][
        "hesitant"]["count"]


def _holm(ps: list[float]) -> list[float]:
    order = sorted(range(len(ps)), key=lambda i: ps[i])
    out, run = [0.0] * len(ps), 0.0
    for rank, i in enumerate(order):
        run = max(run, min(1.0, (len(ps) - rank) * ps[i]))
        out[i] = run
    return out


def test_the_report_prints_the_papers_figures_for_its_counts(study, tmp_path):
    """55 participants answer the confident pause-duration pair 46 low, 4 high, 4 both
    and 1 neither, as the study's participants did: the report prints chi2 = 101.29 and
    the low variant's residual +8.70, the published two-decimal figures, and the verdict
    "the low variant" (shorter pauses look more confident)."""
    from aou_dsl.study.spec import read_study

    s = read_study(str(study))
    (pair,) = [p for p in s.pairs if p.state == "confident" and
               p.descriptor == "pause_duration"]
    answers = ["low"] * 46 + ["high"] * 4 + ["both"] * 4 + ["neither"]
    rows = []
    for k, answer in enumerate(answers):
        pid = f"p{k:02d}"
        rows += [{"participant": pid, "aou_part": "A", "aou_item": a.id, "state": a.state,
                  "intensity": 3} for a in s.part_a]
        rows += [{"participant": pid, "aou_part": "B", "aou_item": p.id,
                  "answer": answer if p.id == pair.id else "both"} for p in s.pairs]
        rows.append({"participant": pid, "aou_part": "end", "aou_item": ""})
    results = tmp_path / "r.json"
    results.write_text(json.dumps(rows))
    res = _analyze(study, [results], tmp_path / "rep")
    (entry,) = [e for e in res["part_b"] if e["id"] == pair.id]
    assert [entry["options"][o]["count"] for o in ("low", "high", "both", "neither")] == \
        [46, 4, 4, 1]
    line = next(ln for ln in (tmp_path / "rep" / "report.md").read_text().splitlines()
                if ln.startswith(f"| {pair.id} |"))
    assert "| 46 (+8.70) |" in line and "| 101.29 |" in line, line
    assert line.rstrip().endswith("| the low variant |"), line


def test_exclusions_each_with_its_reason(study, tmp_path):
    """An incomplete participant, one who failed the attention check and one whose id
    answered twice are left out, each named with the reason; the rest are analysed."""
    results = tmp_path / "r.json"
    assert aouc("study", "simulate", str(study), "--participants", "6", "-o",
                str(results)).returncode == 0
    rows = json.loads(results.read_text())
    rows = [r for r in rows if not (r["participant"] == "sim00001" and r["aou_item"] == "B3")]
    rows.append({"participant": "sim00002", "aou_part": "attention", "aou_item": "X1",
                 "passed": False})
    results.write_text(json.dumps(rows))
    again = tmp_path / "again.json"
    again.write_text(json.dumps([r for r in rows if r["participant"] == "sim00003"]))
    res = _analyze(study, [results, again], tmp_path / "rep")
    reasons = {e["participant"]: e["reason"] for e in res["participants"]["excluded"]}
    assert reasons == {"sim00001": "incomplete", "sim00002": "attention",
                       "sim00003": "duplicate"}
    assert res["participants"]["kept"] == 4  # sim00003's first answers still count
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "| sim00002 | attention |" in md and "unanswered: B3" in md


def test_every_store_gives_the_same_report(study, tmp_path):
    """The same answers as a JSON array, as jsPsych's CSV and in the SQLite store give
    byte-identical reports (and one run equals the next)."""
    results = tmp_path / "r.json"
    assert aouc("study", "simulate", str(study), "--participants", "20", "-o",
                str(results)).returncode == 0
    rows = json.loads(results.read_text())
    import csv

    fields = sorted({k for r in rows for k in r})
    with open(tmp_path / "r.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fields)
        w.writeheader()
        w.writerows(rows)
    db = sqlite3.connect(tmp_path / "answers.sqlite")
    db.execute("create table submissions (seq integer primary key, participant text "
               "unique, received text, data text)")
    for pid in dict.fromkeys(r["participant"] for r in rows):
        db.execute("insert into submissions (participant, received, data) values (?,?,?)",
                   (pid, "t", json.dumps([r for r in rows if r["participant"] == pid])))
    db.commit()
    db.close()
    reports = []
    for k, src in enumerate([results, tmp_path / "r.csv", tmp_path / "answers.sqlite",
                             results]):
        _analyze(study, [src], tmp_path / f"rep{k}")
        reports.append({n: (tmp_path / f"rep{k}" / n).read_bytes()
                        for n in ("results.json", "report.md", "report.html")})
    assert all(r == reports[0] for r in reports)


@pytest.mark.parametrize(("edit", "code"), [
    (lambda t: t.replace("[part_a]", "[part_a]\ncolour = 1"), "E701"),
    (lambda t: t.replace("intensity = 5", "intensity = 50"), "E701"),
    (lambda t: t.replace('"behaviours/fearful.aou", ', '"nowhere.aou", ', 1), "E702"),
    (lambda t: t.replace('descriptor = "tilt_angle"', 'descriptor = "speed"', 1), "E701"),
    (lambda t: t + "\n[[[", "E701"),
])
def test_a_bad_study_file_is_a_coded_error(study, tmp_path, edit, code):
    bad = study.parent / f"bad-{code}.toml"
    bad.write_text(edit(study.read_text()))
    run = aouc("study", "simulate", str(bad), "-o", str(tmp_path / "r.json"))
    assert run.returncode == 1 and code in run.stderr and "Traceback" not in run.stderr
    assert "internal error" not in run.stderr


@pytest.mark.parametrize(("content", "code"), [
    ('[{"participant": "p", "aou_part": "A", "aou_item": "A9", "state": "curious"}]', "E703"),
    ('[{"participant": "p", "aou_part": "A", "aou_item": "A1", "state": "angry"}]', "E703"),
    ('{"not": "rows"}', "E703"),
    ("garbage,,\n1,2", "E703"),
])
def test_bad_results_are_a_coded_error(study, tmp_path, content, code):
    bad = tmp_path / "bad.json"
    bad.write_text(content)
    run = aouc("study", "analyze", str(bad), "--study", str(study), "-o", str(tmp_path / "o"))
    assert run.returncode == 1 and code in run.stderr and "Traceback" not in run.stderr
    assert not (tmp_path / "o").exists()


def test_a_bad_policy_is_a_coded_error(study, tmp_path):
    for text in ("[part_a.A1]\nconfident = 0.8\ncurious = 0.5\n",
                 "[part_a.A7]\nconfident = 1\n", "[part_b.default]\nmaybe = 1\n"):
        policy = tmp_path / "p.toml"
        policy.write_text(text)
        run = aouc("study", "simulate", str(study), "--policy", str(policy), "-o",
                   str(tmp_path / "r.json"))
        assert run.returncode == 1 and "E704" in run.stderr, run.stderr
