"""The language server under random editing: insertions, deletions, pasted junk and
half-typed numbers, sent as incremental changes. It never crashes, always answers, and
every diagnostic it publishes lies inside the document it was published for."""

from __future__ import annotations

import asyncio
import random
from pathlib import Path

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed")
from lsprotocol import types  # noqa: E402
from pytest_lsp import LanguageClient  # noqa: E402

from tests.lsp_server import server_client  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SEEDS = [p.read_text(encoding="utf-8") for p in sorted(ROOT.glob("behaviours/*.aou"))] + [
    (ROOT / "tests" / "valid" / "peek.aou").read_text(encoding="utf-8")]
JUNK = ["1.", "1e", "-", ".5e-", "0,5", "20°", "x", "x1.5", "=", "a=", "(", ")", "(0.5, 0",
        "{", "}", "sequence {", ";", ":", "#", '"', '"arms/x.urdf"', "\n", "\n\n", " ", "\t",
        "pause", "retreat 0.06m", "gaze horizontal", "shiver 6deg f=", "behaviour b : ",
        "robot ", "m/s^2", "deg/s", "Hz", "\u00a0", "\u2212", "😀", "ü", "x99999",
        "1e308m", "pause 0.1s", "approach -5mm", "tilt 90deg v=500deg/s"]


client = server_client()


def _position(text: str, offset: int) -> types.Position:
    """The LSP position (UTF-16 columns) of a character offset of ``text``."""
    head = text[:offset]
    line = head.count("\n")
    col = head[head.rfind("\n") + 1:]
    return types.Position(line, len(col.encode("utf-16-le")) // 2)


def _inside(rng: types.Range, text: str) -> bool:
    lines = text.split("\n")

    def ok(p: types.Position) -> bool:
        return 0 <= p.line < len(lines) and \
            0 <= p.character <= len(lines[p.line].encode("utf-16-le")) // 2
    return ok(rng.start) and ok(rng.end) and \
        (rng.start.line, rng.start.character) <= (rng.end.line, rng.end.character)


def _edit(rng: random.Random, text: str) -> tuple[int, int, str]:
    """A random edit: (start, end, new text) in character offsets."""
    a = rng.randint(0, len(text))
    what = rng.random()
    if what < 0.35:  # insert junk or a half-typed number
        return a, a, rng.choice(JUNK)
    if what < 0.6:  # delete a few characters
        return a, min(len(text), a + rng.randint(1, 12)), ""
    if what < 0.8:  # type one character
        return a, a, rng.choice("0123456789.-+=xsmdeg ;:{}()#\n")
    b = min(len(text), a + rng.randint(0, 30))  # paste over a selection
    return a, b, "".join(rng.choice(JUNK) for _ in range(rng.randint(1, 4)))


async def _fuzz(client: LanguageClient, n_sequences: int, seed: int) -> None:
    rng = random.Random(seed)
    uri = (ROOT / "fuzz.aou").as_uri()
    version = 1
    text = SEEDS[0]
    texts = {version: text}
    published: list[types.PublishDiagnosticsParams] = []
    features = client.protocol.fm.features
    keep = features[types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS]

    def record(*args, **kwargs):  # every publication, with its version
        published.append(args[-1])
        return keep(*args, **kwargs)

    features[types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS] = record
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=version, text=text)))
    doc = types.TextDocumentIdentifier(uri)
    for _ in range(n_sequences):
        if rng.random() < 0.1:  # start again from a good file
            version += 1
            text = texts[version] = rng.choice(SEEDS)
            client.text_document_did_change(types.DidChangeTextDocumentParams(
                types.VersionedTextDocumentIdentifier(version=version, uri=uri),
                [types.TextDocumentContentChangeWholeDocument(text=text)]))
        for _ in range(rng.randint(1, 4)):
            a, b, new = _edit(rng, text)
            version += 1
            client.text_document_did_change(types.DidChangeTextDocumentParams(
                types.VersionedTextDocumentIdentifier(version=version, uri=uri),
                [types.TextDocumentContentChangePartial(
                    range=types.Range(_position(text, a), _position(text, b)), text=new)]))
            text = texts[version] = text[:a] + new + text[b:]
        at = _position(text, rng.randint(0, len(text)))
        # every request is answered (a crash or a hang fails the wait)
        await asyncio.wait_for(client.text_document_hover_async(
            types.HoverParams(doc, at)), 10)
        await asyncio.wait_for(client.text_document_completion_async(
            types.CompletionParams(doc, at)), 10)
        if rng.random() < 0.2:
            await asyncio.wait_for(client.text_document_document_symbol_async(
                types.DocumentSymbolParams(doc)), 10)
            await asyncio.wait_for(client.text_document_formatting_async(
                types.DocumentFormattingParams(doc, types.FormattingOptions(2, True))), 10)
            await asyncio.wait_for(client.text_document_code_action_async(
                types.CodeActionParams(doc, types.Range(at, at), types.CodeActionContext([]))),
                10)
        for _ in range(1000):  # the newest text's diagnostics arrive
            if published and published[-1].version == version:
                break
            await asyncio.sleep(0.01)
        assert published[-1].version == version
        for p in published:  # each lies inside the text it was published for
            for d in p.diagnostics:
                assert _inside(d.range, texts[p.version]), (d, texts[p.version])
        published.clear()
    assert client.error is None


@pytest.mark.asyncio
async def test_random_editing_short(client: LanguageClient):
    await _fuzz(client, 200, seed=1)


@pytest.mark.slow
@pytest.mark.asyncio
async def test_random_editing_2000_sequences(client: LanguageClient):
    await _fuzz(client, 2000, seed=2)
