"""`aouc study analyze` reads the answers other platforms keep: a JATOS results archive
laid out as JATOS exports it, and a Qualtrics-style CSV export through a column mapping.
Hostile archives are refused with E703 and nothing is extracted."""

from __future__ import annotations

import csv
import json
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

AOUC = [sys.executable, "-m", "aou_dsl"]


def aouc(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*AOUC, *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def study(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("study")
    run = aouc("study", "init", str(folder / "s"))
    assert run.returncode == 0, run.stderr
    return folder / "s" / "study.toml"


@pytest.fixture(scope="module")
def simulated(study, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("sim") / "rows.json"
    run = aouc("study", "simulate", str(study), "--participants", "12", "-o", str(out))
    assert run.returncode == 0, run.stderr
    return out


def _analyze(study: Path, results: list[Path], out: Path, *extra: str) -> dict:
    run = aouc("study", "analyze", *map(str, results), "--study", str(study), "-o",
               str(out), *extra)
    assert run.returncode == 0, run.stderr
    return json.loads((out / "results.json").read_text())


def _by_participant(rows: list[dict]) -> dict[str, list[dict]]:
    by: dict[str, list[dict]] = {}
    for r in rows:
        by.setdefault(r["participant"], []).append(r)
    return by


def _jatos_archive(path: Path, submissions: list[str]) -> None:
    """A results archive as JATOS's "Export Results" writes it: per study result a
    folder `study_result_<id>`, per component result `comp-result_<id>` holding
    `data.txt` (the submitted text) and `files/` (uploads), and `metadata.json`."""
    meta_results = []
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for k, text in enumerate(submissions):
            srid, crid = 101 + k, 1001 + 3 * k
            zf.writestr(f"study_result_{srid}/comp-result_{crid}/data.txt", text)
            meta_results.append({"id": srid, "uuid": f"u{srid}", "studyCode": "x",
                                 "studyState": "FINISHED", "duration": "00:10:00",
                                 "componentResults": [{
                                     "id": crid, "componentId": 1, "duration": "00:10:00",
                                     "componentState": "FINISHED",
                                     "path": f"/study_result_{srid}/comp-result_{crid}",
                                     "data": {"size": len(text)}, "files": []}]})
        zf.writestr("study_result_101/comp-result_1001/files/notes.txt", "uploaded")
        zf.writestr("metadata.json", json.dumps({"data": [{
            "studyId": 7, "studyUuid": "abc", "studyTitle": "aou",
            "studyResults": meta_results}]}))


def test_a_jatos_archive_gives_the_same_results(study, simulated, tmp_path):
    """Each participant's rows, submitted as one component result's data, read from
    the archive, give byte for byte the results.json of the JSON rows."""
    rows = json.loads(simulated.read_text())
    # in JATOS, the page's own jsPsych rows come along; analyze skips them
    subs = [json.dumps([{"trial_type": "html-button-response", "rt": 812}, *rs])
            for rs in _by_participant(rows).values()]
    archive = tmp_path / "results.jrzip"
    _jatos_archive(archive, subs)
    want = _analyze(study, [simulated], tmp_path / "from-json")
    got = _analyze(study, [archive], tmp_path / "from-jatos")
    assert got == want and got["participants"]["kept"] == 12
    assert (tmp_path / "from-json" / "results.json").read_bytes() == \
        (tmp_path / "from-jatos" / "results.json").read_bytes()
    # one participant's study run twice (two study results) is a duplicate
    again = tmp_path / "again.zip"
    _jatos_archive(again, [*subs, subs[2]])
    res = _analyze(study, [again], tmp_path / "again")
    assert [e["reason"] for e in res["participants"]["excluded"]] == ["duplicate"]


def _patch_declared_size(path: Path, size: int) -> None:
    """Write ``size`` as the uncompressed size of every central directory entry."""
    raw = bytearray(path.read_bytes())
    at = raw.find(b"PK\x01\x02")
    while at >= 0:
        raw[at + 24:at + 28] = struct.pack("<I", size)
        at = raw.find(b"PK\x01\x02", at + 4)
    path.write_bytes(bytes(raw))


def _hostile(kind: str, path: Path, rows: str) -> None:
    if kind == "dotdot":
        with zipfile.ZipFile(path, "w") as zf:
            zf.writestr("study_result_1/comp-result_1/data.txt", rows)
            zf.writestr("../../evil.txt", "x")
    elif kind == "absolute":
        with zipfile.ZipFile(path, "w") as zf:
            zf.writestr("study_result_1/comp-result_1/data.txt", rows)
            info = zipfile.ZipInfo("x")
            info.filename = "/tmp/evil-aou.txt"  # ZipInfo() would strip the slash
            zf.writestr(info, "x")
    elif kind == "huge":
        with zipfile.ZipFile(path, "w") as zf:
            zf.writestr("study_result_1/comp-result_1/data.txt", rows)
        _patch_declared_size(path, 0x7FFF0000)
    elif kind == "many":
        with zipfile.ZipFile(path, "w") as zf:
            for i in range(100_001):
                zf.writestr(f"study_result_{i}/comp-result_{i}/files/a", "")
    elif kind == "not-json":
        with zipfile.ZipFile(path, "w") as zf:
            zf.writestr("study_result_1/comp-result_1/data.txt", rows)
            zf.writestr("study_result_2/comp-result_2/data.txt", "participant,A1\np,x\n")
    elif kind == "bad-row":
        with zipfile.ZipFile(path, "w") as zf:
            zf.writestr("study_result_3/comp-result_9/data.txt", json.dumps(
                [{"participant": "p", "aou_part": "A", "aou_item": "A1", "state": "x"}]))


@pytest.mark.parametrize(("kind", "names"), [
    ("dotdot", "../../evil.txt"), ("absolute", "/tmp/evil-aou.txt"),
    ("huge", "study_result_1/comp-result_1/data.txt"), ("many", "more than"),
    ("not-json", "study_result_2/comp-result_2/data.txt"),
    ("bad-row", "study_result_3/comp-result_9/data.txt"),
])
def test_a_hostile_archive_is_refused(study, simulated, tmp_path, kind, names):
    rows = json.loads(simulated.read_text())
    one = json.dumps(next(iter(_by_participant(rows).values())))
    work = tmp_path / "w"
    work.mkdir()
    archive = work / "bad.jrzip"
    _hostile(kind, archive, one)
    before = sorted(p for p in tmp_path.rglob("*"))
    run = subprocess.run([*AOUC, "study", "analyze", str(archive), "--study", str(study),
                          "-o", str(tmp_path / "o")], capture_output=True, text=True,
                         timeout=300, cwd=work)
    assert run.returncode == 1 and "E703" in run.stderr, run.stderr
    assert names in run.stderr and "Traceback" not in run.stderr
    assert sorted(p for p in tmp_path.rglob("*")) == before  # nothing extracted
    assert not Path("/tmp/evil-aou.txt").exists() and not (tmp_path / "o").exists()


# -- Qualtrics-style exports -----------------------------------------------------------

STATE_LABELS = {"confident": "Confident", "curious": "Curious", "hesitant": "Hesitant",
                "fearful": "Fearful", "others": "Other (please say)", "none": "None of these"}
INTENSITY_LABELS = {1: "1 - Very weak", 2: "2", 3: "3", 4: "4", 5: "5 - Very strong"}
SIDE_LABELS = {"low": "Version L", "high": "Version H"}


def _export(rows: list[dict], study, partial: dict[str, int]) -> list[list[str]]:
    """A Qualtrics-style export of ``rows``: column ids, question texts, ImportId
    JSON, then one line per respondent; Part B answers name the side chosen, and an
    embedded-data column says which version was on the left. ``partial`` maps a
    respondent to the percentage they reached (their later questions left blank)."""
    from aou_dsl.study.spec import read_study

    s = read_study(str(study))
    cols = ["StartDate", "Status", "Progress", "Finished", "ResponseId"]
    texts = ["Start Date", "Response Type", "Progress", "Finished", "Response ID"]
    for i in range(1, len(s.part_a) + 1):
        cols += [f"Q{i}_state", f"Q{i}_state_5_TEXT", f"Q{i}_int", f"Q{i}_desc"]
        texts += ["Which state does the robot show?", "Other (please say) - Text",
                  "How strongly?", "Describe it"]
    for i in range(1, len(s.pairs) + 1):
        cols += [f"P{i}", f"P{i}_left"]
        texts += ["Which video shows it more?", "left_variant"]
    imports = [json.dumps({"ImportId": c}) for c in cols]
    out = [cols, texts, imports]
    for pid, rs in _by_participant(rows).items():
        got = {r["aou_item"]: r for r in rs}
        line = ["2026-01-05 10:00:00", "IP Address", str(partial.get(pid, 100)),
                "False" if pid in partial else "True", pid]
        for a in s.part_a:
            r = got[a.id]
            line += [STATE_LABELS[r["state"]], r["other_text"],
                     INTENSITY_LABELS[r["intensity"]], r["description"]]
        for p in s.pairs:
            r = got[p.id]
            if pid in partial:  # stopped after Part A
                line += ["", ""]
                continue
            side = {"both": "Both equally", "neither": "Neither"}.get(r["answer"]) or (
                "Video on the left" if r["answer"] == r["left"] else "Video on the right")
            line += [side, SIDE_LABELS[r["left"]]]
        out.append(line)
    return out


def _mapping(study) -> str:
    from aou_dsl.study.spec import read_study

    s = read_study(str(study))
    lines = ['participant = "ResponseId"', 'progress = "Progress"', 'finished = "Finished"',
             "[states]"] + [f'"{v}" = "{k}"' for k, v in STATE_LABELS.items()]
    lines += ["[intensity]", '"1 - Very weak" = 1', '"5 - Very strong" = 5', "[answers]",
              '"Video on the left" = "left"', '"Video on the right" = "right"',
              '"Both equally" = "both"', '"Neither" = "neither"', "[sides]",
              '"Version L" = "low"', '"Version H" = "high"']
    for i, a in enumerate(s.part_a, 1):
        lines += [f"[part_a.{a.id}]", f'state = "Q{i}_state"', f'intensity = "Q{i}_int"',
                  f'description = "Q{i}_desc"', f'other_text = "Q{i}_state_5_TEXT"']
    for i, p in enumerate(s.pairs, 1):
        lines += [f"[part_b.{p.id}]", f'answer = "P{i}"', f'left = "P{i}_left"']
    return "\n".join(lines) + "\n"


def _write_csv(path: Path, lines: list[list[str]]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        csv.writer(fh).writerows(lines)


def test_a_qualtrics_export_through_a_mapping(study, simulated, tmp_path):
    """The export's counts equal those of the same answers as rows; respondents whose
    progress is under 100 are excluded as incomplete."""
    rows = json.loads(simulated.read_text())
    export, mapping = tmp_path / "export.csv", tmp_path / "map.toml"
    _write_csv(export, _export(rows, study, {"sim00004": 40, "sim00009": 95}))
    mapping.write_text(_mapping(study))
    got = _analyze(study, [export], tmp_path / "q", "--map", str(mapping))
    kept = [r for r in rows if r["participant"] not in ("sim00004", "sim00009")]
    (tmp_path / "kept.json").write_text(json.dumps(kept))
    want = _analyze(study, [tmp_path / "kept.json"], tmp_path / "rows")
    assert got["part_a"] == want["part_a"] and got["part_b"] == want["part_b"]
    assert got["participants"]["kept"] == 10
    assert {e["participant"]: e["reason"] for e in got["participants"]["excluded"]} == \
        {"sim00004": "incomplete", "sim00009": "incomplete"}
    # the legacy export with two header rows reads the same
    _write_csv(export, [x for i, x in enumerate(_export(rows, study, {})) if i != 2])
    two = _analyze(study, [export], tmp_path / "two", "--map", str(mapping))
    assert two["participants"]["kept"] == 12


@pytest.mark.parametrize(("edit", "says"), [
    (lambda m, e: (m.replace('"Video on the left" = "left"', ""), e), "Video on the left"),
    (lambda m, e: (m.replace('state = "Q2_state"', 'state = "Q99"'), e), "Q99"),
    (lambda m, e: (m.replace("[part_a.A3]", "[part_a.A9]"), e), "part_a.A9"),
    (lambda m, e: (m.replace('"Confident" = "confident"', '"Confident" = "proud"'), e),
     "proud"),
    (lambda m, e: (m, e.replace(",100,", ",most,", 1)), "Progress"),
    (lambda m, e: (m + "[[[", e), "not TOML"),
])
def test_a_bad_mapping_or_export_is_e703(study, simulated, tmp_path, edit, says):
    rows = json.loads(simulated.read_text())
    export, mapping = tmp_path / "export.csv", tmp_path / "map.toml"
    _write_csv(export, _export(rows, study, {}))
    m, e = edit(_mapping(study), export.read_text())
    mapping.write_text(m)
    export.write_text(e)
    run = aouc("study", "analyze", str(export), "--study", str(study), "--map",
               str(mapping), "-o", str(tmp_path / "o"))
    assert run.returncode == 1 and "E703" in run.stderr and says in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and not (tmp_path / "o").exists()


def test_an_attention_column_and_an_unnamed_column(study, simulated, tmp_path):
    """A mapped attention check passes when the label is the check's answer; a column
    without an id in the export is never taken for an unmapped field."""
    from aou_dsl.study.analyze import analyze
    from aou_dsl.study.answers import read_answers
    from aou_dsl.study.spec import read_study

    checked = study.parent / "checked.toml"
    checked.write_text(study.read_text() + '\n[attention]\nchecks = [{question = "Pick '
                       'blue", options = ["red", "blue"], answer = "blue"}]\n')
    s = read_study(str(checked))
    lines = _export(json.loads(simulated.read_text()), study, {})
    lines[0].append("ATT")
    lines[1].append("Pick blue")
    lines[2].append('{"ImportId":"QID99"}')
    for line in lines[3:]:
        line.append("red" if line[4] == "sim00002" else "blue")
    lines[0][0] = ""  # StartDate's id gone: an unnamed column
    for line in lines[3:]:
        line[0] = "7"
    export, mapping = tmp_path / "export.csv", tmp_path / "map.toml"
    _write_csv(export, lines)
    m = _mapping(study).replace('intensity = "Q1_int"\n', "")
    mapping.write_text(m + '[attention.C1]\nanswer = "ATT"\n')
    rows = read_answers([str(export)], s, str(mapping))
    assert {r.participant: r.passed for r in rows if r.part == "attention"} == \
        {f"sim{i:05d}": i != 2 for i in range(1, 13)}
    assert all(r.intensity is None for r in rows if r.part == "A" and r.item == "A1")
    res = analyze(rows, s)
    assert [(e["participant"], e["reason"]) for e in res["participants"]["excluded"]] == \
        [("sim00002", "attention")]
