"""A .dmp folder is untrusted input: nothing named in it runs, it is read only inside
itself and within bounds, and every tampered field is a coded diagnostic, never an
internal error.

The folders are written by `aouc compile --format dmp` and then tampered with as the
format's promises say they must not be (docs/dmp.md); each is read through the command
line, in a child process under a timeout where the old reader hung."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("movement_primitives")

from aou_dsl.cli.commands import main  # noqa: E402
from tests import dmpgen  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CODE = re.compile(r" (D60[0-9]|I50[0-9]) ")
#: Seconds a refusal may take in a child process (the old reader hung for good).
TIMEOUT = 120


@pytest.fixture(scope="module")
def base(tmp_path_factory) -> Path:
    """fearful (approaches, a retreat, pauses, a shiver) written as a .dmp folder."""
    out = tmp_path_factory.mktemp("base") / "fearful.dmp"
    assert main(["compile", str(ROOT / "behaviours" / "fearful.aou"), "-o", str(out)]) == 0
    return out


@pytest.fixture
def folder(base, tmp_path) -> Path:
    """A copy of the base folder to tamper with."""
    return Path(shutil.copytree(base, tmp_path / "x.dmp"))


def _manifest(folder: Path) -> dict:
    return json.loads((folder / "manifest.json").read_text())


def _write(path: Path, doc) -> None:
    path.write_text(json.dumps(doc))


def _first_part(folder: Path) -> Path:
    return folder / next(e["file"] for e in _manifest(folder)["parts"] if e["file"])


def _roll(*argv: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """`aouc dmp roll ...` as a program (a hang fails the test at TIMEOUT, not the
    suite)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "aou_dsl", "dmp", "roll", *argv],
                          capture_output=True, text=True, timeout=TIMEOUT, env=env,
                          cwd=cwd)


def _refused(res, code: str | None = None) -> str:
    """The code a refused run reported (exit 1 or 2, a coded diagnostic, no internal
    error)."""
    err = res.stderr if hasattr(res, "stderr") else res
    assert "internal error" not in err, err
    assert "Traceback" not in err, err
    found = CODE.search(err)
    assert found, err
    if code is not None:
        assert found.group(1) == code, err
    return found.group(1)


# --- code named in a file --------------------------------------------------------------

@pytest.mark.parametrize("payload", [
    {"module": "subprocess", "class": "getoutput", "cmd": "id > {canary}; echo pwned"},
    {"module": "os", "class": "system", "command": "touch {canary}"},
    {"module": "movement_primitives.dmp._cartesian_dmp", "class": "CartesianDMP",
     "forcing_term_pos": {"module": "subprocess", "class": "getoutput",
                          "cmd": "touch {canary}"}},
], ids=["subprocess.getoutput", "os.system", "nested forcing term"])
def test_a_part_naming_a_module_runs_nothing(folder, tmp_path, payload):
    """A part file naming `subprocess.getoutput` (the shared-folder attack), `os.system`,
    or a CartesianDMP whose forcing term names one, is refused with D607 and exit 1; the
    canary file the command would create never appears."""
    canary = tmp_path / "PWNED"
    text = json.dumps(payload).replace("{canary}", str(canary))
    _first_part(folder).write_text(text)
    res = _roll(str(folder), "--goal", "0.6,0.05,0.25")
    assert res.returncode == 1, res.stderr
    assert _refused(res) == "D607"
    assert not canary.exists()


# --- tampered manifests ----------------------------------------------------------------

_NAN, _INF = "NaN", "Infinity"


def _cases() -> list[tuple[str, object]]:
    """The tampered fields: (dotted field, value; _NAN/_INF spelt as JSON's extension)."""
    out: list[tuple[str, object]] = []
    for field in ("robot", "ee_frame", "shiver_joint"):
        out += [(field, v) for v in (3, [1, 2], {"a": 1}, _NAN)]
        if field != "ee_frame":  # null is the arm's own frame
            out.append((field, None))
    out += [("ee_frame", "nope"), ("shiver_joint", "panda_joint99"), ("robot", "nope")]
    out += [("rate", v) for v in (0, -250, _NAN, _INF, 1e12)]
    out += [("descriptors", v) for v in ("x", 3, [1], None)]
    out += [("goal.position", v) for v in ([_NAN, 0, 0], [_INF, 0, 0], [[0.5, 0, 0.3]] * 3,
                                           "start")]
    out += [("parts", {"a": 1}), ("parts", []), ("state", "angry"), ("intensity", 2)]
    return out


def _set(doc: dict, field: str, value: object) -> None:
    *path, last = field.split(".")
    node = doc
    for k in path:
        node = node[k]
    if value == "start":
        value = doc["parts"][0]["start"]["position"]
    node[last] = value


@pytest.mark.parametrize("field, value", _cases(), ids=lambda x: str(x)[:24])
def test_each_tampered_manifest_field_is_a_coded_refusal(folder, capsys, field, value):
    """Each field of the manifest given the wrong type, a non-finite or out-of-range
    number, a name the arm lacks, or a goal at the start: a D-coded diagnostic naming
    the field, exit 1; never an internal error."""
    doc = _manifest(folder)
    _set(doc, field, value)
    text = json.dumps(doc).replace(f'"{_NAN}"', "NaN").replace(f'"{_INF}"', "Infinity")
    (folder / "manifest.json").write_text(text)
    assert main(["dmp", "roll", str(folder)]) == 1
    err = capsys.readouterr().err
    assert _refused(err).startswith("D")
    top = field.split(".")[0]
    assert f"`{top}" in err or "not JSON" in err, err


def test_a_goal_given_at_the_start_is_refused(base, capsys):
    """`--goal` at the sequence's start: the rollout would divide by zero; I504."""
    start = _manifest(base)["parts"][0]["start"]["position"]
    assert main(["dmp", "roll", str(base), "--goal", ",".join(map(str, start))]) == 2
    assert _refused(capsys.readouterr().err) == "I504"


# --- the folder is closed --------------------------------------------------------------

@pytest.mark.parametrize("how", ["traversal", "absolute", "symlink"])
def test_a_part_outside_the_folder_is_not_read(folder, tmp_path, how):
    """A part named `../outside.json`, by an absolute path, or a part file that is a
    symbolic link out of the folder: D608, even though the file outside is a valid part."""
    outside = tmp_path / "outside.json"
    shutil.copy(_first_part(folder), outside)
    doc = _manifest(folder)
    i = next(k for k, e in enumerate(doc["parts"]) if e["file"])
    if how == "symlink":
        part = folder / doc["parts"][i]["file"]
        part.unlink()
        part.symlink_to(outside)
    else:
        doc["parts"][i]["file"] = "../outside.json" if how == "traversal" else str(outside)
        _write(folder / "manifest.json", doc)
    res = _roll(str(folder))
    assert res.returncode == 1 and _refused(res) == "D608"
    assert f"parts[{i}].file" in res.stderr


@pytest.mark.parametrize("which", ["manifest", "part"])
def test_a_fifo_is_refused_without_waiting(folder, which):
    """A FIFO as the manifest or as a part file is refused (D608) at once: nothing
    writes to it, and the old reader waited for a writer for good."""
    path = folder / "manifest.json" if which == "manifest" else _first_part(folder)
    path.unlink()
    os.mkfifo(path)
    res = _roll(str(folder))
    assert res.returncode == 1 and _refused(res) == "D608"
    assert "FIFO" in res.stderr


def test_compiling_over_a_folder_with_a_fifo_manifest_does_not_wait(tmp_path):
    """`aouc compile -o X.dmp` over a folder whose manifest is a FIFO: refused (I502)
    at once; the check of whether aou wrote the folder waited on the FIFO for good."""
    out = tmp_path / "x.dmp"
    out.mkdir()
    os.mkfifo(out / "manifest.json")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    res = subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                          str(ROOT / "behaviours" / "confident.aou"), "-o", str(out)],
                         capture_output=True, text=True, timeout=TIMEOUT, env=env)
    assert res.returncode == 2 and _refused(res) == "I502"
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]


@pytest.mark.parametrize("field, value", [("int_dt", -0.001), ("int_dt", 0.0),
                                          ("int_dt", 1e-9), ("_execution_time", -1.0),
                                          ("n_weights_per_dim", 10 ** 9), ("dt_", 0.0)])
def test_numbers_the_library_loops_on_are_checked_first(folder, field, value):
    """A part whose integration step is negative, zero or tiny, whose execution time is
    negative, or whose basis functions are a billion: refused (D602, D608) before the
    library loops on it (the old reader hung on a negative int_dt)."""
    part = _first_part(folder)
    doc = json.loads(part.read_text())
    doc[field] = value
    _write(part, doc)
    res = _roll(str(folder))
    assert res.returncode == 1 and _refused(res) in ("D602", "D608")
    assert f"`{field}`" in res.stderr


@pytest.mark.parametrize("times", [2, 1000])
def test_parts_listed_many_times_are_refused(folder, times):
    """The parts listed twice (a part file named twice) or 1,000 times (beyond the bound
    of parts): D608, at once."""
    doc = _manifest(folder)
    doc["parts"] = doc["parts"] * times
    _write(folder / "manifest.json", doc)
    res = _roll(str(folder))
    assert res.returncode == 1 and _refused(res) == "D608"


def test_a_part_beyond_its_size_bound_is_not_read(folder, monkeypatch, capsys):
    """A part file larger than the bound is refused (D608) from its size, not parsed."""
    from aou_dsl.dmp import reader

    part = _first_part(folder)
    monkeypatch.setattr(reader, "MAX_PART_BYTES", part.stat().st_size - 1)
    assert main(["dmp", "roll", str(folder)]) == 1
    assert _refused(capsys.readouterr().err) == "D608"


@pytest.mark.parametrize("inside", ["manifest.json", "parts/01-approach.json", "new.json"])
def test_output_into_the_folder_read_is_refused_before_any_work(folder, inside):
    """`-o X.dmp/manifest.json` (or a part, or a new file in the folder) is refused with
    I502 before the folder is even read (a broken part would be D602 otherwise), and
    every file of the folder is unchanged."""
    _first_part(folder).write_text("{}")
    before = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    res = _roll(str(folder), "-o", str(folder / inside))
    assert res.returncode == 2 and _refused(res) == "I502"
    assert {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()} == before


def test_a_written_folder_still_rolls_out(base, tmp_path):
    """The reader refuses only what is wrong: the folder `aouc compile` wrote rolls out
    to a trajectory, read back exactly as the compile wrote it (the round trip's own
    tests compare the motion)."""
    from aou_dsl.dmp import read_dmp

    seq = read_dmp(str(base))
    doc = _manifest(base)
    assert [p.kind for p in seq.parts] == [e["kind"] for e in doc["parts"]]
    assert seq.descriptors == doc["descriptors"]
    for p, e in zip(seq.parts, doc["parts"], strict=True):
        assert (p.dmp is None) == (e["file"] is None)
        if p.dmp is not None:
            raw = json.loads((base / e["file"]).read_text())
            assert p.dmp.forcing_term_pos.weights_.tolist() == \
                raw["forcing_term_pos"]["weights_"]
            assert p.dmp.int_dt == raw["int_dt"]
            assert math.isclose(p.dmp.execution_time_, raw["_execution_time"])


def test_the_rule_examples_trigger_their_own_codes(folder, capsys):
    """`aouc rules D607` shows a part file naming `subprocess.getoutput`, `aouc rules
    D608` a part path with `..`: put into a written folder, each is reported with that
    very code."""
    from aou_dsl.core.diagnostics import RULES

    where, text = RULES["D607"].example.split(": ", 1)
    (folder.parent / where).write_text(text)
    assert main(["dmp", "roll", str(folder)]) == 1
    assert _refused(capsys.readouterr().err) == "D607"
    path = re.search(r'"file": "([^"]+)"', RULES["D608"].example).group(1)
    doc = _manifest(folder)
    next(e for e in doc["parts"] if e["file"])["file"] = path
    _write(folder / "manifest.json", doc)
    assert main(["dmp", "roll", str(folder)]) == 1
    assert _refused(capsys.readouterr().err) == "D608"


# --- the fuzz suite --------------------------------------------------------------------

def _fuzz(base: Path, tmp_path: Path, seed: int, count: int, solve: bool = False) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    argv = [sys.executable, "-m", "tests.dmpgen", str(base), str(seed), str(count),
            str(tmp_path)] + (["solve"] if solve else [])
    try:
        res = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT,
                             timeout=TIMEOUT + 6 * count)
    except subprocess.TimeoutExpired:
        last = (tmp_path / "progress").read_text() if (tmp_path / "progress").exists() \
            else "?"
        pytest.fail(f"a tampered folder hangs: case {last}")
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.splitlines()[-1])
    print(f"dmp fuzz: {out['cases']} cases, {len(out['internal'])} internal errors, "
          f"0 hangs, {len(out['changed'])} inputs changed, canary "
          f"{'written' if out['canary'] else 'absent'}; outcomes {out['codes']}")
    assert out["internal"] == [], out["internal"][:5]
    assert out["changed"] == []
    assert not out["canary"] and not (tmp_path / dmpgen.CANARY_NAME).exists()
    assert set(out["codes"]) <= {"read", "D602", "D603", "D604", "D605", "D607", "D608",
                                 "I501", "I504"}, out["codes"]
    return out


def test_fuzzed_folders_are_refused_with_codes(base, tmp_path):
    """Tampered folders from the generator (types, values, sizes, names, module and
    class fields): 0 internal errors, 0 hangs, 0 inputs changed, 0 code executed;
    those read roll out."""
    out = _fuzz(base, tmp_path, seed=7, count=30)
    assert out["cases"] == 30


@pytest.mark.slow
def test_fuzzed_folders_are_refused_with_codes_at_length(base, tmp_path):
    """The same over 200 tampered folders, those read solved, checked and measured."""
    out = _fuzz(base, tmp_path, seed=11, count=200, solve=True)
    assert out["cases"] == 200
