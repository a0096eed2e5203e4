"""Ctrl-C during `aouc compile --jobs 2`: one interrupt ends the run at once, with
`aouc: interrupted` and exit status 130 (128 + SIGINT, as shells report it), whether it
reaches the whole process group (as a terminal's Ctrl-C does) or only `aouc` itself,
while the workers warm up or while they build; no worker is left running, no worker
prints a traceback, and the files written are complete ones, the first of the inputs in
order.

Each case runs `python -m aou_dsl` of this checkout in a session of its own, so the
interrupt reaches only its processes."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from aou_dsl.cli.args import EXIT_INTERRUPTED
from tests.conftest import BEHAVIOURS, ROOT

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not sys.platform.startswith("linux"),
                                 reason="reads the processes from /proc")]

#: Long enough to call a run that has not ended hung [s]: an interrupted run ends in
#: well under a second on an idle machine.
HUNG = 20.0
#: The longest motion first, so that its output is the first of the inputs and appears
#: as soon as the workers have built one file, while most are still to build.
ORDER = ("hesitant", "curious", "fearful", "confident", "inactive")


def _inputs(folder: Path, copies: int) -> list[Path]:
    """``copies`` copies of each shipped behaviour, in input (sorted) order."""
    folder.mkdir()
    for k in range(copies):
        for rank, stem in enumerate(ORDER):
            shutil.copy(BEHAVIOURS / f"{stem}.aou", folder / f"{k:02d}_{rank}_{stem}.aou")
    return sorted(folder.glob("*.aou"))


def _group(pgid: int, parent: int | None = None) -> dict[int, str]:
    """The processes of the group ``pgid`` that have not ended (those whose parent is
    ``parent``, when given): pid -> command line. (An ended process whose parent is gone
    may stay a zombie: it runs nothing.)"""
    found = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path("/proc", entry, "stat").read_text()
            cmd = Path("/proc", entry, "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:  # ended meanwhile
            continue
        fields = stat[stat.rfind(")") + 2:].split()  # state, ppid, pgrp, ...
        if int(fields[2]) == pgid and fields[0] not in "ZX" and parent in (None, int(fields[1])):
            found[int(entry)] = cmd
    return found


def _workers(pgid: int) -> list[int]:
    """aouc's workers: its children (forked, or spawned fresh interpreters), but the
    helper that tracks a spawned pool's shared resources."""
    return [pid for pid, cmd in _group(pgid, parent=pgid).items()
            if "resource_tracker" not in cmd]


def _maps_name(pid: int, word: str) -> bool:
    """Whether the process ``pid`` has a file whose path holds ``word`` mapped (a
    library it has begun to import)."""
    try:
        return word in Path("/proc", str(pid), "maps").read_text()
    except OSError:
        return False


def _wait_for(what, proc: subprocess.Popen) -> None:
    end = time.monotonic() + HUNG
    while not what():
        assert proc.poll() is None, "the run ended before Ctrl-C"
        assert time.monotonic() < end, "the run did not get there"
        time.sleep(0.02)


@pytest.mark.parametrize(("to", "phase"), [
    # before any worker: aouc lints and loads what the builds need (forked workers
    # start after that, warm)
    ("the group", "loading"),
    ("the group", "warming up"), ("aouc alone", "warming up"),
    # the workers ignore Ctrl-C, so while they build, aouc alone or all of the group
    # being interrupted are the same to them: aouc stops them
    ("the group", "building")])
def test_one_ctrl_c_ends_a_parallel_compile(tmp_path, to, phase):
    inputs = _inputs(tmp_path / "in", copies=12)
    out, log = tmp_path / "out", tmp_path / "stderr.txt"
    env = dict(os.environ, PYTHONPATH=str(ROOT))  # this checkout, not an installed aou
    with log.open("wb") as stderr:
        proc = subprocess.Popen(
            [sys.executable, "-m", "aou_dsl", "compile", str(tmp_path / "in"), "--jobs",
             "2", "-o", str(out)],
            cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
            stderr=stderr)
    try:
        # --jobs 2: aouc builds too, beside one worker
        if phase == "loading":  # once aouc has begun to load SciPy, a second or so
            _wait_for(lambda: _maps_name(proc.pid, "scipy"), proc)
            assert not _workers(proc.pid) and proc.poll() is None, "too late, or ended"
        else:
            _wait_for(lambda: len(_workers(proc.pid)) == 1, proc)
        if phase == "warming up":  # a spawned worker imports the compiler and loads the
            time.sleep(0.5)        # robot (seconds); a forked one starts building at once
        elif phase == "building":
            _wait_for(lambda: (out / f"{inputs[0].stem}.json").exists(), proc)
        if phase != "loading":
            assert len(_workers(proc.pid)) == 1 and proc.poll() is None, "ended before Ctrl-C"
        if to == "the group":
            os.killpg(proc.pid, signal.SIGINT)
        else:
            os.kill(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=HUNG)
        except subprocess.TimeoutExpired:
            pytest.fail(f"still running {HUNG:.0f} s after Ctrl-C: {_group(proc.pid)}")
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()

    err = log.read_text()
    assert proc.returncode == EXIT_INTERRUPTED, err
    assert "aouc: interrupted" in err
    for word in ("Traceback", "KeyboardInterrupt", "Exception"):  # from no process
        assert word not in err, err
    # No process of the run is left: the workers end with aouc (the helper process that
    # tracks shared resources ends once aouc has, so allow it a moment).
    end = time.monotonic() + 5.0
    while _group(proc.pid) and time.monotonic() < end:
        time.sleep(0.05)
    assert not _group(proc.pid), "left running"

    # Nothing half-written: no temporary file is left, and the files there are complete
    # documents, those of the first inputs (they are written in input order).
    written = sorted(out.iterdir()) if out.exists() else []
    assert not [p.name for p in written if p.name.startswith(".")]
    assert [p.stem for p in written] == [p.stem for p in inputs[:len(written)]]
    assert len(written) < len(inputs), "interrupted after the last file"
    for path in written:
        doc = json.loads(path.read_bytes())
        assert doc["behaviour"] == path.stem.split("_", 2)[2]
        assert len(doc["t"]) == len(doc["q"]) > 0
