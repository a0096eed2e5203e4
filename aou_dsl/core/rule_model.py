"""What a diagnostic code is: its severity, its category (which decides the exit
status) and its registry entry. The entries themselves are in :mod:`.rules`."""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["Category", "Rule", "Severity"]


class Severity(enum.StrEnum):
    """How serious a diagnostic is. Only errors (and warnings under ``--strict``) fail."""

    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


class Category(enum.Enum):
    """Where a problem comes from; it decides the exit status: a usage or input/output
    problem exits 2, a problem of the input's content exits 1."""

    SYNTAX = "S"
    VALIDATION = "V"
    MODEL = "M"
    COMPILE = "C"
    READING = "R"
    USAGE = "I"
    DMP = "D"
    STUDY = "E"
    PLUGIN = "K"

    @property
    def is_usage(self) -> bool:
        return self is Category.USAGE


@dataclass(frozen=True, slots=True)
class Rule:
    """One diagnostic code: its stable name and the text ``aouc rules`` prints."""

    code: str
    name: str
    severity: Severity
    what: str
    why: str
    example: str

    @property
    def category(self) -> Category:
        return Category(self.code[0])
