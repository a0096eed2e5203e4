"""Smaller breaks a user met, each as it was met: a missing extra said as one, a figure of
a document whose strings are not text, messages that quote the file's line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main

from .conftest import BEHAVIOURS
from .test_fuzz_outputs import _workspace


def test_cluster_without_its_extra_names_the_extra(tmp_path, monkeypatch, capsys):
    """--cluster where Dask distributed is not installed: the message every other
    missing extra gets (exit 2), not an internal error."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # `import distributed` fails
    out = tmp_path / "c.json"
    code = main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "--cluster",
                 "tcp://127.0.0.1:1", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "internal error" not in err, err
    assert "needs the cluster extra" in err and "pip install '.[cluster]'" in err, err
    assert not out.exists()


@pytest.mark.parametrize("field", ["behaviour", "episodes"])
def test_plot_of_strings_that_are_not_text_is_r401(tmp_path, monkeypatch, capsys, field):
    monkeypatch.chdir(tmp_path)
    _workspace(tmp_path)
    doc = json.loads(Path("t.json").read_text())
    if field == "behaviour":
        doc["behaviour"] = "a\ud800b"
    else:
        doc["episodes"] = [{"kind": "pause\udfff", "t_start": 0.0, "t_end": 0.5}]
    Path("s.json").write_text(json.dumps(doc))  # json writes "\ud800" as an escape
    code = main(["plot", "s.json", "-o", "s.png"])
    err = capsys.readouterr().err
    assert "internal error" not in err and "Traceback" not in err, err
    assert code == 1 and " R401 [error]" in err and "lone surrogate" in err, err
    assert not Path("s.png").exists()
