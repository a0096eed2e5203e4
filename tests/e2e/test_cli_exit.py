"""How an ``aouc`` process ends: its exit handlers run, everything it printed is out,
and a thread still running is waited for, though the interpreter's teardown is skipped
(:func:`aou_dsl.cli.endings.leave`)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _python(code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    """``python -c code`` with its standard streams buffered, as they are by default."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, env=env, timeout=60, check=False)


def test_leave_runs_exit_handlers_and_flushes_buffered_output(tmp_path):
    # Standard output to a pipe is block-buffered: without a flush, the last lines
    # printed would be lost, and without the handlers, the marker would never be written.
    code = ("import atexit, sys\n"
            "from aou_dsl.cli.endings import leave\n"
            "atexit.register(lambda: open('marker', 'w').write('ran'))\n"
            "for k in range(1000):\n"
            "    print(k)\n"
            "print('said on stderr', file=sys.stderr)\n"
            "leave(3)\n")
    proc = _python(code, tmp_path)
    assert proc.returncode == 3
    assert proc.stdout.splitlines() == [str(k) for k in range(1000)]
    assert proc.stderr == "said on stderr\n"
    assert (tmp_path / "marker").read_text() == "ran"


def test_leave_waits_for_a_thread_that_still_runs(tmp_path):
    code = ("import threading, time\n"
            "from aou_dsl.cli.endings import leave\n"
            "def late():\n"
            "    time.sleep(0.3)\n"
            "    open('late', 'w').write('written')\n"
            "threading.Thread(target=late).start()\n"
            "leave(0)\n")
    proc = _python(code, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "late").read_text() == "written"


def test_a_compile_leaves_no_robot_folder_and_a_whole_document(tmp_path):
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out = tmp_path / "h.json"
    env = {**os.environ, "TMPDIR": str(tmp)}
    proc = subprocess.run([sys.executable, "-m", "aou_dsl", "compile",
                           str(ROOT / "behaviours" / "hesitant.aou"), "-o", str(out),
                           "--format", "json"], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(out.read_text())["format"].startswith("aou-trajectory")
    # The build loaded its robot from a copy in a folder of its own (aou-robots-PID-...),
    # which its exit handler removes.
    assert not [p.name for p in tmp.iterdir() if p.name.startswith("aou-robots-")]
