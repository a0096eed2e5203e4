"""What the server keeps of each open document."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..core.diagnostics import Diagnostic

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .lsp_engine import Built

__all__ = ["Document"]


@dataclass(eq=False)
class Document:
    """One open document: its text, what lint and the last compile made of it.

    ``generation`` rises with every edit; ``built`` belongs to ``built_generation``."""

    uri: str
    path: str
    text: str = ""
    version: int | None = None
    generation: int = 0
    lint: FileResult | None = None
    built: Built | None = None
    built_generation: int = -1
    closed: bool = False
    lines: list[str] = field(default_factory=list)

    @property
    def compiled(self) -> Built | None:
        """The last compile's result, if it is of the current text."""
        return self.built if self.built_generation == self.generation else None

    @property
    def diagnostics(self) -> list[Diagnostic]:
        """What to show: the compile's (which include lint's) when it is of the current
        text, else lint's."""
        built = self.compiled
        if built is not None:
            return built.diagnostics
        return list(self.lint.diagnostics) if self.lint is not None else []
