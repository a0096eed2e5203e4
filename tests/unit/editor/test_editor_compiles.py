"""Compile diagnostics off the typing path: a newer edit supersedes an older compile,
whose result is never published; a compile waits for a pause in typing."""

from __future__ import annotations

import asyncio
import threading
from pathlib import Path

import pytest

pytest.importorskip("lsprotocol", reason="the lsp extra is not installed")
from aou_dsl.editor import lsp_engine as engine
from aou_dsl.editor.compiling import Compiles
from aou_dsl.editor.convert import Text
from aou_dsl.editor.state import Document

ROOT = Path(__file__).resolve().parents[3]


def _doc(text: str) -> Document:
    doc = Document("file:///x.aou", "x.aou", Text(text))
    doc.lint = engine.lint(text, "x.aou")
    return doc


def _edit(doc: Document, text: str) -> None:
    doc.view = Text(text)
    doc.generation += 1
    doc.lint = engine.lint(text, "x.aou")


def test_a_newer_edit_supersedes_a_running_compile(monkeypatch) -> None:
    started, release = threading.Event(), threading.Event()
    built_texts: list[str] = []
    real = engine.build

    def build(text, path, robot=None, first=None):
        built_texts.append(text)
        if len(built_texts) == 1:  # the first compile is slow: an edit comes meanwhile
            started.set()
            release.wait(10)
        return real(text, path, robot, first)

    monkeypatch.setattr(engine, "build", build)
    published: list[tuple[int, list[str]]] = []
    doc = _doc("pause 1s\npause 2s\n")

    async def run() -> None:
        compiles = Compiles(lambda d: published.append(
            (d.built_generation, [x.code for x in d.diagnostics])), lambda m: None)
        compiles.request(doc, 0.0, None)
        await asyncio.to_thread(started.wait, 10)
        _edit(doc, "retreat 0.06m\npause 1s x2\napproach\n")  # while the first compiles
        compiles.request(doc, 0.0, None)
        release.set()
        for _ in range(600):
            if published:
                break
            await asyncio.sleep(0.05)
        await asyncio.sleep(0.2)
        compiles.shutdown()

    asyncio.run(run())
    assert len(built_texts) == 2  # both ran: the first was already running
    # only the newest text's results were published (the compiler's, then the whole
    # build's); the first text's was dropped
    assert published and {gen for gen, _ in published} == {doc.generation}
    assert doc.compiled is not None and "C" not in {c[0] for c in published[-1][1]}


def test_queued_compiles_of_old_text_do_not_run(monkeypatch) -> None:
    built_texts: list[str] = []
    monkeypatch.setattr(engine, "compile_only", lambda *args: None)
    monkeypatch.setattr(engine, "build", lambda text, *args: (
        built_texts.append(text), engine.Built())[1])
    doc = _doc("pause 1s\n")

    async def run() -> None:
        compiles = Compiles(lambda d: None, lambda m: None)
        for i in range(5):  # typing: each edit asks for a compile after a pause
            _edit(doc, f"pause {i + 1}s\n")
            compiles.request(doc, 0.2, None)
            await asyncio.sleep(0.02)
        await asyncio.sleep(0.6)
        compiles.shutdown()

    asyncio.run(run())
    assert built_texts == ["pause 5s\n"]


@pytest.mark.parametrize("text", [
    (ROOT / "behaviours" / "hesitant.aou").read_text(),
    "approach\npause 1s x2\nretreat 0.06m a=50\n",  # C304, C310
    "tilt 90deg v=500deg/s\n",  # C309: the compile fails
])
def test_the_compile_first_then_the_build_says_what_the_build_alone_says(text) -> None:
    first = engine.compile_only(text, "x.aou")
    assert first is not None
    codes = {d.code for d in first.diagnostics}
    whole = engine.build(text, "x.aou", None, first)
    alone = engine.build(text, "x.aou")
    assert [(d.code, d.message, d.span) for d in whole.diagnostics] == \
        [(d.code, d.message, d.span) for d in alone.diagnostics]
    assert {c for c in codes if c[0] == "C"} <= {d.code for d in alone.diagnostics}
