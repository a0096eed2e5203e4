"""Every invalid fixture gives exactly the diagnostics its `# expect:` lines name, and every
valid fixture and shipped behaviour lints without errors."""

import re
from pathlib import Path

import pytest

from aou_dsl.core.diagnostics import Severity
from aou_dsl.lang.linter import lint_file
from tests.conftest import BEHAVIOURS, INVALID, VALID

_EXPECT = re.compile(r"^# expect: (\w\d{3}) (\d+):(\d+)$", re.M)


def _expected(path: Path) -> set[tuple[str, int, int]]:
    return {(c, int(line), int(col)) for c, line, col in _EXPECT.findall(path.read_text())}


@pytest.mark.parametrize("path", sorted(INVALID.glob("invalid_*.aou")), ids=lambda p: p.stem)
def test_invalid_fixture_gives_expected_errors(path):
    expected = _expected(path)
    assert expected, f"{path.name} has no `# expect:` line"
    result = lint_file(str(path))
    found = {(d.code, d.span.line, d.span.col) for d in result.diagnostics
             if d.severity is Severity.ERROR}
    assert found == expected
    assert not result.ok


@pytest.mark.parametrize("path", sorted(VALID.glob("*.aou")) + sorted(BEHAVIOURS.glob("*.aou")),
                         ids=lambda p: p.stem)
def test_valid_files_have_no_errors(path):
    result = lint_file(str(path))
    assert result.ok, [d.message for d in result.diagnostics]
    assert result.behaviour is not None
