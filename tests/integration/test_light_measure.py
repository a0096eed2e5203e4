"""Commands that measure stay clear of SciPy's signal and statistics packages.

Importing ``scipy.signal`` costs a cold ``aouc compile``, ``check`` or ``measure`` about a
second (it decorates every function it exports and pulls in ``scipy.stats``), several
times the build of a small behaviour; the measurement filters and finds its peaks with
its own NumPy code instead (aou_dsl/measuring/savgol.py, extrema.py). Each command runs
in a fresh interpreter here and reports the modules it loaded when it ended.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tests.conftest import BEHAVIOURS

#: Packages a measuring command must not load.
HEAVY = ("scipy.signal", "scipy.stats")


def _loaded_after(argv: list[str]) -> tuple[int, list[str]]:
    """The exit code of ``aouc *argv`` run in a fresh interpreter, and which of
    :data:`HEAVY` it had loaded when it ended."""
    code = ("import sys\n"
            "from aou_dsl.cli.commands import main\n"
            f"rc = main({argv!r})\n"
            f"heavy = sorted(m for m in sys.modules if m.split('.')[:2] in "
            f"[h.split('.') for h in {HEAVY!r}])\n"
            "print(rc, ','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    rc, _, heavy = out.stdout.strip().splitlines()[-1].partition(" ")
    return int(rc), [m for m in heavy.split(",") if m]


def test_compile_check_and_measure_load_no_scipy_signal(tmp_path: Path):
    source = BEHAVIOURS / "hesitant.aou"
    out = tmp_path / "hesitant.json"
    assert _loaded_after(["compile", str(source), "-o", str(out), "--jobs", "1"]) == (0, [])
    assert out.is_file()
    assert _loaded_after(["measure", str(out), "--format", "json"]) == (0, [])
    assert _loaded_after(["check", str(out)]) == (0, [])
    assert _loaded_after(["check", str(source)]) == (0, [])


def test_the_pool_preloads_no_scipy_signal():
    """A forked worker gets what its parent preloaded: nothing it does not need."""
    from aou_dsl.driver import pool

    assert not any(m.startswith(HEAVY) for m in pool._STAGES)
