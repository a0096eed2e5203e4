"""Shared fixtures: paths to the shipped behaviours and the test fixture folders."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BEHAVIOURS = ROOT / "behaviours"
INVALID = Path(__file__).resolve().parent / "invalid"
VALID = Path(__file__).resolve().parent / "valid"


@pytest.fixture
def behaviours_dir() -> Path:
    return BEHAVIOURS


def fails_with(code: str, fn, *args, **kw):
    """The one diagnostic of the AouError ``fn(*args, **kw)`` raises, checked to be
    ``code``."""
    from aou_dsl.core.diagnostics import AouError

    with pytest.raises(AouError) as err:
        fn(*args, **kw)
    (d,) = err.value.diagnostics
    assert d.code == code, d.message
    return d
