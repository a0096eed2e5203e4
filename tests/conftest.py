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
