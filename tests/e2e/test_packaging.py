"""The wheel ships the grammar, so an installed `aouc` works outside the checkout."""

import subprocess
import sys
import zipfile

import pytest

from tests.conftest import ROOT


@pytest.mark.slow
def test_wheel_contains_grammar_and_console_script(tmp_path):
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps",
                    "-q", "-w", str(tmp_path), str(ROOT)], check=True, capture_output=True)
    (wheel,) = tmp_path.glob("aou_dsl-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "aou_dsl/grammar/aou.lark" in names
    assert {f"aou_dsl/schemas/{n}.schema.json" for n in ("trajectory", "robot")} <= set(names)
    entry = next(n for n in names if n.endswith("entry_points.txt"))
    assert "aouc = aou_dsl.cli:run" in zipfile.ZipFile(wheel).read(entry).decode()
