"""`aouc studio` on the command line: where it binds, a busy port, what it refuses."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main

ROOT = str(Path(__file__).resolve().parents[2])


def test_without_the_extra_it_says_which_to_install(monkeypatch, capsys, tmp_path):
    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    monkeypatch.setitem(sys.modules, "viser", None)  # import viser fails
    assert main(["studio", str(path)]) == 2
    err = capsys.readouterr().err
    assert "studio extra" in err and "pip install '.[studio]'" in err
    assert os.listdir(tmp_path) == ["h.aou"]


def test_a_file_that_does_not_build_is_an_error_before_serving(capsys, tmp_path):
    pytest.importorskip("viser")
    path = tmp_path / "bad.aou"
    path.write_text("behaviour b : hesitant\napproach\npause 1s x1\nretreat 0.06m x3\n")
    assert main(["studio", str(path)]) == 1
    err = capsys.readouterr().err
    assert "V121" in err and "aouc studio:" not in err
    assert main(["studio", str(tmp_path / "missing.aou")]) == 2
    assert "I501" in capsys.readouterr().err


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.2", 0))
        return s.getsockname()[1]


def test_a_busy_port_takes_the_next_free_one_and_another_host_is_warned_of(tmp_path):
    pytest.importorskip("viser")
    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    before = path.read_bytes()
    port = _free_port()
    with socket.socket() as busy:
        busy.bind(("127.0.0.2", port))
        busy.listen()
        proc = subprocess.Popen(
            [sys.executable, "-m", "aou_dsl", "studio", str(path), "--port", str(port),
             "--host", "127.0.0.2"], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
            text=True, cwd=tmp_path)
        lines = []
        try:
            end = time.monotonic() + 120
            while time.monotonic() < end:
                line = proc.stderr.readline()
                if not line:
                    break
                lines.append(line)
                if line.startswith("aouc studio: http"):
                    break
        finally:
            proc.send_signal(signal.SIGINT)
            _, rest = proc.communicate(timeout=30)
    text = "".join(lines)
    assert "warning: the studio binds 127.0.0.2" in text
    assert f"port {port} is taken" in text
    url = next(ln for ln in lines if ln.startswith("aouc studio: http"))
    served = int(url.split()[2].split(":")[2].split("/")[0])
    assert served > port and url.split()[2].startswith("http://127.0.0.2:")
    assert proc.returncode == 130, rest  # Ctrl-C, as every command
    assert path.read_bytes() == before and os.listdir(tmp_path) == ["h.aou"]


def test_fit_is_for_a_behaviour_and_compare_for_a_aou_file(capsys, tmp_path):
    pytest.importorskip("viser")
    rec = tmp_path / "rec.csv"
    rec.write_text("t,panda_joint1\n0,0\n")
    assert main(["studio", str(rec), "--robot", "panda", "--fit"]) == 2
    assert "--fit shapes a .aou file" in capsys.readouterr().err
    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    assert main(["studio", str(path), "--compare", str(rec)]) == 2
    assert "--compare takes a .aou file" in capsys.readouterr().err
    assert sorted(os.listdir(tmp_path)) == ["h.aou", "rec.csv"]


def test_track_is_for_a_plan_and_draws_the_one_second_arm(capsys, tmp_path):
    """A recording is what an arm did: it is not tracked again. --track and --compare
    would both draw the second arm. Each is a usage error before any work."""
    pytest.importorskip("viser")
    rec = tmp_path / "rec.csv"
    rec.write_text("t,panda_joint1\n0,0\n")
    assert main(["studio", str(rec), "--robot", "panda", "--track"]) == 2
    assert "a recording is already what an arm did" in capsys.readouterr().err
    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    assert main(["studio", str(path), "--track", "--compare", str(path)]) == 2
    assert "--track and --compare" in capsys.readouterr().err
    assert sorted(os.listdir(tmp_path)) == ["h.aou", "rec.csv"]
