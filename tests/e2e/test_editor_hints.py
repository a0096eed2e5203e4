"""The language server's quick fix for a refusal whose hint changes several statements:
one code action, one workspace edit with a text edit per statement, applied at once
(``aouc server`` over stdio, driven by pytest-lsp's client)."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed")
from lsprotocol import types  # noqa: E402
from pytest_lsp import LanguageClient  # noqa: E402

from aou_dsl.driver.builder import build_source  # noqa: E402
from tests.e2e.test_editor_server import _apply, _open, _published  # noqa: E402
from tests.lsp_server import server_client  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.asyncio(loop_scope="module")


client = server_client("module")


async def _refusal(client: LanguageClient, text: str, name: str, code: str, said: str
                   ) -> tuple[str, types.Diagnostic]:
    """Open ``text`` (the server compiles it) and wait for its ``code`` refusal as the
    whole build says it (the compile alone says it sooner, with the compiler's hint):
    with ``said`` in its message."""
    uri = await _open(client, text, (ROOT / name).as_uri())
    for _ in range(10):
        diags = await _published(client, uri, timeout=180)
        if any(d.code == code and said in d.message for d in diags):
            break
    (d,) = [d for d in diags if d.code == code and said in d.message]
    return uri, d


async def test_the_quick_fix_of_a_refusal_writes_every_change_at_once(
        client: LanguageClient):
    """Two shivers of a sequence too fast for the Z1's wrist: the compiler refuses the
    first; the quick fix narrows both (slower, they would read as slow rolls), and the
    file then compiles."""
    text = ("robot z1\nsequence {\n  approach 0.1m\n  pause 1s\n  shiver 5deg f=2.5Hz\n"
            "  pause 1s\n  shiver 4deg f=2.2Hz for 2s\n}\n")
    uri, d = await _refusal(client, text, "untitled-hints-1.aou", "C308",
                            "f=2.2Hz for 2s` at line 7")
    assert d.range.start.line == 4
    actions = await client.text_document_code_action_async(types.CodeActionParams(
        types.TextDocumentIdentifier(uri), d.range, types.CodeActionContext([d])))
    (action,) = actions
    edits = action.edit.changes[uri]
    assert sorted(e.range.start.line for e in edits) == [4, 6]
    fixed = _apply(text, edits)
    assert "shiver 5deg" not in fixed and "shiver 4deg" not in fixed
    assert "f=2.5Hz" in fixed and "f=2.2Hz" in fixed
    res = build_source(fixed, "fixed.aou")
    assert res.ok, (fixed, [(x.code, x.message) for x in res.diagnostics])
