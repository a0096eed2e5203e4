"""``aouc server`` as an editor uses it: started as a subprocess, driven over stdio by
pytest-lsp's client."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed")
from lsprotocol import types  # noqa: E402
from pytest_lsp import LanguageClient  # noqa: E402

from aou_dsl.lang.linter import lint_source  # noqa: E402
from tests.lsp_server import server_client  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.asyncio(loop_scope="module")


client = server_client("module")


_N = iter(range(10_000))


def _uri() -> str:
    return (ROOT / f"untitled-{next(_N)}.aou").as_uri()


async def _open(client: LanguageClient, text: str, uri: str | None = None) -> str:
    uri = uri or _uri()
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=1, text=text)))
    await _published(client, uri)
    return uri


async def _published(client: LanguageClient, uri: str, timeout: float = 60.0) -> list:
    """Wait for diagnostics of ``uri``; the latest published list."""
    async def wait():
        while True:
            params = await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
            if params.uri == uri:
                return params.diagnostics
    return await asyncio.wait_for(wait(), timeout)


def _replace_all(client: LanguageClient, uri: str, text: str, version: int) -> None:
    client.text_document_did_change(types.DidChangeTextDocumentParams(
        text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=version),
        content_changes=[types.TextDocumentContentChangeWholeDocument(text=text)]))


def _apply(text: str, edits: list[types.TextEdit]) -> str:
    lines = text.split("\n")
    for e in sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character),
                    reverse=True):
        s, t = e.range.start, e.range.end
        head = "\n".join(lines[:s.line] + [lines[s.line][:s.character]])
        tail = "\n".join([lines[t.line][t.character:]] + lines[t.line + 1:])
        text = head + e.new_text + tail
        lines = text.split("\n")
    return text


async def test_error_arrives_with_code_and_range_then_clears(client: LanguageClient):
    uri = _uri()
    await _open(client, "pause 3m\n", uri)
    diags = client.diagnostics[uri]
    (d,) = [d for d in diags if d.code == "V102"]
    assert d.range == types.Range(types.Position(0, 6), types.Position(0, 8))
    assert d.severity == types.DiagnosticSeverity.Error
    _replace_all(client, uri, "pause 3s\n", 2)
    diags = await _published(client, uri)
    assert not [d for d in diags if d.severity == types.DiagnosticSeverity.Error]


async def test_hover_on_descriptor_key_header_and_code(client: LanguageClient):
    text = "behaviour h : hesitant\napproach a=0.05\npause 1.67s x5\nretreat 0.06m a=0.12 x3\n"
    uri = await _open(client, text)
    h = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(1, 10)))
    assert h is not None and "approach_acceleration" in h.contents.value
    assert "m/s^2" in h.contents.value and "hesitant: looks more hesitant as it is lower" \
        in h.contents.value
    h = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(0, 3)))
    assert "C=" in h.contents.value and "`hesitant`" in h.contents.value
    h = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(2, 1)))
    assert "episodes" in h.contents.value and h.contents.value.count("- pause") == 5
    uri = await _open(client, "pause 3m\n")
    h = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(0, 7)))
    assert "**V102**" in h.contents.value


async def _labels(client, uri, line, col) -> list[str]:
    res = await client.text_document_completion_async(types.CompletionParams(
        types.TextDocumentIdentifier(uri), types.Position(line, col)))
    return [i.label for i in res.items]


async def test_completion(client: LanguageClient):
    uri = await _open(client, "behaviour h : \nrobot \ngaze \nretreat 0.06m \npause 1\n\n")
    assert "hesitant" in await _labels(client, uri, 0, 14)
    assert "panda" in await _labels(client, uri, 1, 6)
    assert await _labels(client, uri, 2, 5) == ["horizontal", "vertical"]
    assert {"a=", "v="} <= set(await _labels(client, uri, 3, 14))
    assert {"1s", "1ms"} == set(await _labels(client, uri, 4, 7))
    assert "approach" in await _labels(client, uri, 5, 0)


_SLIPS = [
    ("pause 1,5s\n", "S001"),
    ("tilt 20°\npause 1s x2\n", "S003"),
    ("pause 2sec\n", "V104"),
    ("shiver 6deg for=1.2s\n", "V112"),
    ("pauze 1s\n", "V101"),
    ("behaviour h : hesitnt\npause 1s\n", "V114"),
]


@pytest.mark.parametrize(("text", "code"), _SLIPS)
async def test_code_action_applied_clears_the_diagnostic(client: LanguageClient, text, code):
    uri = await _open(client, text)
    (d,) = [d for d in client.diagnostics[uri] if d.code == code]
    actions = await client.text_document_code_action_async(types.CodeActionParams(
        types.TextDocumentIdentifier(uri), d.range, types.CodeActionContext([d])))
    (action,) = [a for a in actions if a.diagnostics and a.diagnostics[0].code == code]
    fixed = _apply(text, action.edit.changes[uri])
    assert code not in {x.code for x in lint_source(fixed).diagnostics}, fixed


async def test_formatting_and_symbols(client: LanguageClient):
    text = "behaviour  h : hesitant   # the state\nsequence {\napproach 0.08m   a = 0.09\n" \
           "pause 1s\n}\n"
    uri = await _open(client, text)
    edits = await client.text_document_formatting_async(types.DocumentFormattingParams(
        types.TextDocumentIdentifier(uri), types.FormattingOptions(2, True)))
    assert _apply(text, edits) == ("behaviour h : hesitant  # the state\nsequence {\n"
                                   "  approach 0.08m a=0.09\n  pause 1s\n}\n")
    syms = await client.text_document_document_symbol_async(types.DocumentSymbolParams(
        types.TextDocumentIdentifier(uri)))
    assert [s.name for s in syms] == ["behaviour  h : hesitant", "sequence"]
    assert [c.name for c in syms[1].children] == ["approach 0.08m   a = 0.09", "pause 1s"]
    assert syms[1].children[1].range.start == types.Position(3, 0)


async def test_compile_diagnostic_after_save(client: LanguageClient):
    text = "approach\npause 1s x2\nretreat 0.06m a=50\n"
    uri = await _open(client, text)
    client.text_document_did_save(types.DidSaveTextDocumentParams(
        types.TextDocumentIdentifier(uri)))
    for _ in range(5):
        diags = await _published(client, uri, timeout=120)
        if any(d.code == "C304" for d in diags):
            break
    (d,) = [d for d in diags if d.code == "C304"]
    assert d.range.start.line == 2
    for _ in range(100):  # the compiled episodes' figures follow the diagnostics
        h = await client.text_document_hover_async(types.HoverParams(
            types.TextDocumentIdentifier(uri), types.Position(2, 2)))
        if "episodes, compiled" in h.contents.value:
            break
        await asyncio.sleep(0.1)
    assert "episodes, compiled" in h.contents.value
    (row,) = [ln for ln in h.contents.value.splitlines() if ln.startswith("- retreat")]
    acc = float(row.split("peak acceleration ")[1].split()[0])
    assert 0.1 < acc < 50  # the arm peaks lower than the declared 50 m/s^2 (C304)


async def test_tilt_too_fast_fix_compiles_clean(client: LanguageClient):
    text = "tilt 90deg v=500deg/s\n"
    uri = await _open(client, text)
    client.text_document_did_save(types.DidSaveTextDocumentParams(
        types.TextDocumentIdentifier(uri)))
    for _ in range(5):
        diags = await _published(client, uri, timeout=120)
        if any(d.code == "C309" for d in diags):
            break
    (d,) = [d for d in diags if d.code == "C309"]
    actions = await client.text_document_code_action_async(types.CodeActionParams(
        types.TextDocumentIdentifier(uri), d.range, types.CodeActionContext([d])))
    (action,) = actions
    fixed = _apply(text, action.edit.changes[uri])
    assert fixed.startswith("tilt 90deg v=") and "500deg/s" not in fixed
    from aou_dsl.driver.builder import build_source

    assert "C309" not in {x.code for x in build_source(fixed).diagnostics}
