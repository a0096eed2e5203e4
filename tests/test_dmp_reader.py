"""Files written by `aouc compile --format dmp` load with movement_primitives' own reader.

This test imports nothing of aou: it runs `aouc` as a program and reads what it wrote
with ``movement_primitives.io.read_json``, as a user of the library would."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

mp_io = pytest.importorskip("movement_primitives.io")
ROOT = Path(__file__).resolve().parent.parent


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


def test_the_documented_player_runs(tmp_path):
    """The snippet of docs/dmp.md that plays a .dmp folder without aou runs as written
    and ends where the manifest's last part ends."""
    import re

    import numpy as np

    out = tmp_path / "hesitant.dmp"
    subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                    str(ROOT / "behaviours" / "hesitant.aou"), "-o", str(out)],
                   check=True, capture_output=True)
    doc = (ROOT / "docs" / "dmp.md").read_text()
    code = next(b for b in re.findall(r"```python\n(.*?)```", doc, re.S) if "read_json" in b
                and "aou_dsl" not in b)
    scope: dict = {}
    cwd = Path.cwd()
    try:
        import os

        os.chdir(tmp_path)
        exec(compile(code, "docs/dmp.md", "exec"), scope)
    finally:
        os.chdir(cwd)
    last = json.loads((out / "manifest.json").read_text())["parts"][-1]["end"]["position"]
    assert np.linalg.norm(scope["poses"][-1, :3] - np.array(last)) < 1e-3
