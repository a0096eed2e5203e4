"""How much the language server takes in and analyses.

- A document is analysed (linted, compiled, formatted, hovered) up to the size
  ``aouc lint`` reads of a ``.aou`` file: 1 MB of UTF-8 (``AOU_MAX_INPUT_MB`` raises it),
  and lines up to :data:`MAX_LINE` characters. Past either bound the document gets one
  diagnostic (V132) saying so, every request about it an empty answer, and the server
  goes on: the editor's text is still followed, and analysed again once it is back
  under the bounds.
- A message from the editor is read up to :data:`MAX_MESSAGE` bytes; a larger one is
  skipped, unread, and answered with an error.
- The text of a document is followed up to :data:`MAX_HELD` characters; an edit that
  makes it larger ends the following (a diagnostic says to reopen it).
"""

from __future__ import annotations

from ..core.codes import V132
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.inputs import ENV_BYTES, input_limit, size_text
from .convert import Text

__all__ = ["MAX_HELD", "MAX_LINE", "MAX_MESSAGE", "max_document", "refusal",
           "too_large_to_follow"]

#: The longest line analysed [characters].
MAX_LINE = 10_000
#: The largest message read from the editor [bytes].
MAX_MESSAGE = 64 << 20
#: The largest document followed [characters].
MAX_HELD = 64 << 20


def max_document() -> int:
    """The largest document analysed [bytes of UTF-8]: ``aouc lint``'s bound."""
    try:
        return input_limit("behaviour")
    except AouError:  # a wrong AOU_MAX_INPUT_MB: lint says so; the server keeps 1 MB
        return 1 << 20


def _utf8_size(text: str, bound: int) -> int:
    """The UTF-8 size of ``text`` when it may be near ``bound``; else its length in
    characters, which is no more than it and on the same side of the bound."""
    if len(text) > bound or 4 * len(text) <= bound:
        return len(text)
    return len(text.encode("utf-8", "surrogatepass"))


def refusal(text: Text, path: str) -> Diagnostic | None:
    """V132 when ``text`` is past a bound; None when it is analysed."""
    bound = max_document()
    size = _utf8_size(text.text, bound)
    if size > bound:
        return diag(V132, f"the document is larger ({size_text(size)}) than aou analyses "
                    f"({size_text(bound)}): it is not checked until it is smaller",
                    Span(path, 1, 1, 1, 1),
                    hint=f"if it is right, raise the bound: start the server with {ENV_BYTES} "
                         f"set (in MB, e.g. {ENV_BYTES}={max(2 * bound >> 20, 1)})")
    lines = text.lines
    longest = max(range(len(lines)), key=lambda i: len(lines[i]))
    if len(lines[longest]) > MAX_LINE:
        n = len(lines[longest])
        return diag(V132, f"line {longest + 1} is longer ({n:,} characters) than aou "
                    f"analyses ({MAX_LINE:,}): the document is not checked until it is "
                    "shorter", Span(path, longest + 1, 1, longest + 1, 1),
                    hint="break the line: a new line ends a statement as `;` does")
    return None


def too_large_to_follow(path: str, size: int) -> Diagnostic:
    """The diagnostic of a document that grew past :data:`MAX_HELD` by edits."""
    return diag(V132, f"the document grew larger ({size:,} characters) than the server "
                f"follows ({MAX_HELD:,}): close and reopen it once it is smaller",
                Span(path, 1, 1, 1, 1))
