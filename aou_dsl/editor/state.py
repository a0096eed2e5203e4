"""What the server keeps of each open document."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..core.diagnostics import Diagnostic
from .convert import Text

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .lsp_engine import Built

__all__ = ["Document"]


@dataclass(eq=False)
class Document:
    """One open document: its text exactly as the editor holds it, and what lint and
    the last compile made of it.

    ``generation`` rises with every edit; ``built`` belongs to ``built_generation``.
    ``refused`` is set, and nothing else made of the text, while it is larger than the
    server analyses."""

    uri: str
    path: str
    view: Text = field(default_factory=lambda: Text(""))
    version: int | None = None
    generation: int = 0
    lint: FileResult | None = None
    built: Built | None = None
    built_generation: int = -1
    closed: bool = False
    refused: Diagnostic | None = None

    @property
    def text(self) -> str:
        return self.view.text

    @property
    def lines(self) -> list[str]:
        """aou's lines of the text (ended by ``\\n``)."""
        return self.view.lines

    @property
    def compiled(self) -> Built | None:
        """The last compile's result, if it is of the current text."""
        return self.built if self.built_generation == self.generation else None

    @property
    def diagnostics(self) -> list[Diagnostic]:
        """What to show: the compile's (which include lint's) when it is of the current
        text, else lint's; only why it is not analysed when it is too large."""
        if self.refused is not None:
            return [self.refused]
        built = self.compiled
        if built is not None:
            return built.diagnostics
        return list(self.lint.diagnostics) if self.lint is not None else []
