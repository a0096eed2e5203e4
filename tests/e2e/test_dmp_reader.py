"""Files written by `aouc compile --format dmp` load with movement_primitives' own reader,
and the safe player docs/dmp.md shows plays them and runs nothing a file names.

This test imports nothing of aou: it runs `aouc` as a program and reads what it wrote
(files it made itself, so trusted) with ``movement_primitives.io.read_json``, as a user of
the library would; the documented player reads them without it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

mp_io = pytest.importorskip("movement_primitives.io")
ROOT = Path(__file__).resolve().parents[2]


def test_each_part_loads_with_the_library_reader_and_plays(tmp_path):
    """Every motion part is a CartesianDMP the library's reader loads and rolls out to
    the end pose the manifest gives (within 1 mm)."""
    import numpy as np

    out = tmp_path / "hesitant.dmp"
    subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                    str(ROOT / "behaviours" / "hesitant.aou"), "-o", str(out)],
                   check=True, capture_output=True)
    manifest = json.loads((out / "manifest.json").read_text())
    moves = [p for p in manifest["parts"] if p["file"]]
    assert [p["kind"] for p in moves] == ["approach", "retreat", "retreat", "approach",
                                          "retreat", "approach"]
    for part in moves:
        dmp = mp_io.read_json(str(out / part["file"]))
        assert type(dmp).__name__ == "CartesianDMP"
        _, y = dmp.open_loop()
        assert np.linalg.norm(y[-1, :3] - np.array(part["end"]["position"])) < 1e-3


def _player(doc: str) -> str:
    import re

    return next(b for b in re.findall(r"```python\n(.*?)```", doc, re.S)
                if "CartesianDMP(" in b and "aou_dsl" not in b)


def _play(code: str, where: Path) -> dict:
    import os

    scope: dict = {}
    cwd = Path.cwd()
    try:
        os.chdir(where)
        exec(compile(code, "docs/dmp.md", "exec"), scope)
    finally:
        os.chdir(cwd)
    return scope


def test_the_documented_player_runs(tmp_path):
    """The snippet of docs/dmp.md that plays a .dmp folder without aou runs as written,
    calls no `read_json`, and ends where the manifest's last part ends."""
    import numpy as np

    out = tmp_path / "hesitant.dmp"
    subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                    str(ROOT / "behaviours" / "hesitant.aou"), "-o", str(out)],
                   check=True, capture_output=True)
    code = _player((ROOT / "docs" / "dmp.md").read_text())
    assert "read_json" not in code
    scope = _play(code, tmp_path)
    last = json.loads((out / "manifest.json").read_text())["parts"][-1]["end"]["position"]
    assert np.linalg.norm(scope["poses"][-1, :3] - np.array(last)) < 1e-3


def test_the_documented_player_runs_nothing_a_file_names(tmp_path):
    """Given a part file naming `subprocess.getoutput`, the documented player stops with
    an error and the command never runs (the canary file never appears)."""
    out = tmp_path / "hesitant.dmp"
    subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                    str(ROOT / "behaviours" / "hesitant.aou"), "-o", str(out)],
                   check=True, capture_output=True)
    canary = tmp_path / "PWNED"
    part = next(p["file"] for p in json.loads((out / "manifest.json").read_text())["parts"]
                if p["file"])
    (out / part).write_text(json.dumps({"module": "subprocess", "class": "getoutput",
                                        "cmd": f"touch {canary}"}))
    with pytest.raises(ValueError, match="not a CartesianDMP"):
        _play(_player((ROOT / "docs" / "dmp.md").read_text()), tmp_path)
    assert not canary.exists()
