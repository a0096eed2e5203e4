"""The suite's conftest keeps together, on one pytest-xdist worker, the tests that share
set-up: the tests of a module with a module-scoped fixture, and the tests marked with
one ``xdist_group``. Checked on a small suite of its own run on two workers, whatever
the installed pytest writes test ids as."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"

SHARED = '''
import pytest


@pytest.fixture(scope="module")
def built():
    return object()


@pytest.mark.parametrize("i", range(6))
def test_shares(built, i):
    pass
'''

MARKED = '''
import pytest


@pytest.mark.xdist_group("sweep")
@pytest.mark.parametrize("i", range(6))
def test_marked(i):
    pass


@pytest.mark.parametrize("i", range(6))
def test_alone(i):
    pass
'''

PASSED = re.compile(r"^\[(gw\d+)\] .*PASSED (\S+?)(?:@\S+)?\s*$")


def _workers(tmp_path: Path) -> dict[str, set[str]]:
    """Each test's module and name (without parameters) -> the workers that ran one."""
    shutil.copy(CONFTEST, tmp_path / "conftest.py")
    (tmp_path / "test_shared.py").write_text(SHARED)
    (tmp_path / "test_marked.py").write_text(MARKED)
    (tmp_path / "pytest.ini").write_text("[pytest]\nmarkers =\n    slow: slow\n")
    env = {**os.environ, "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}  # xdist alone starts fast
    proc = subprocess.run([sys.executable, "-m", "pytest", "-p", "xdist.plugin", "-v", "-n",
                           "2", "--dist", "loadgroup", "-p", "no:cacheprovider"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    ran: dict[str, set[str]] = defaultdict(set)
    for line in proc.stdout.splitlines():
        if m := PASSED.match(line):
            ran[m.group(2).split("[")[0]].add(m.group(1))
    assert sum(1 for line in proc.stdout.splitlines() if PASSED.match(line)) == 18, \
        proc.stdout[-3000:]
    return ran


def test_tests_that_share_set_up_run_on_one_worker(tmp_path: Path) -> None:
    ran = _workers(tmp_path)
    assert len(ran["test_shared.py::test_shares"]) == 1, ran
    assert len(ran["test_marked.py::test_marked"]) == 1, ran
    assert ran["test_marked.py::test_alone"], ran
