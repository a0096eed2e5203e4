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


def test_a_ctrl_c_the_os_hands_to_another_thread_still_stops_the_studio(tmp_path):
    """The OS hands a process's Ctrl-C to any of its threads. When it went to one of the
    studio's own, the main thread, waiting with no end, never saw it: one `aouc studio`
    in twenty under load ignored Ctrl-C. Here the signal is sent to another thread on
    purpose, once the studio serves; a studio that missed it is ended by a stop event 15 s
    later, when the signal is finally seen."""
    pytest.importorskip("viser")
    import threading

    from aou_dsl.studio import serve

    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    stop = threading.Event()
    sent: list[float] = []

    def interrupt() -> None:
        end = time.monotonic() + 60
        while time.monotonic() < end:  # the studio serves once its port answers
            with socket.socket() as c:
                if c.connect_ex(("127.0.0.1", port)) == 0:
                    break
            time.sleep(0.1)
        time.sleep(1.0)  # past the address it prints, into its wait
        sent.append(time.monotonic())
        signal.pthread_kill(threading.get_ident(), signal.SIGINT)  # to this thread
        stop.wait(15)
        stop.set()

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    helper = threading.Thread(target=interrupt, daemon=True)
    helper.start()
    try:
        code = serve(str(path), port=port, stop=stop)
        taken = time.monotonic() - sent[0]
    finally:
        stop.set()
        helper.join(5)
        signal.signal(signal.SIGINT, previous)
    assert code == 130 and taken < 5.0, taken  # not left for the stop event at 15 s
