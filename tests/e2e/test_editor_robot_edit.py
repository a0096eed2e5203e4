"""``aouc server`` (a subprocess over stdio, as an editor starts it) while the robot file
a document names is edited on disk: the compile diagnostics after the next save show the
new limit's refusal, as ``aouc compile`` in a new process does."""

from __future__ import annotations

import asyncio

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed")
from lsprotocol import types  # noqa: E402
from pytest_lsp import LanguageClient  # noqa: E402

from tests.conftest import BEHAVIOURS  # noqa: E402
from tests.lsp_server import server_client  # noqa: E402

pytestmark = pytest.mark.asyncio(loop_scope="module")

client = server_client("module")


async def _compiled(client: LanguageClient, uri: str, want: str) -> set[str]:
    """Save ``uri``; the codes of the diagnostics published after: the first list with
    ``want``, else the last within a minute."""
    client.text_document_did_save(types.DidSaveTextDocumentParams(
        types.TextDocumentIdentifier(uri)))
    codes: set[str] = set()

    async def wait():
        nonlocal codes
        while True:
            params = await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
            if params.uri == uri:
                codes = {str(d.code) for d in params.diagnostics}
                if want in codes:
                    return
    try:
        await asyncio.wait_for(wait(), 60)
    except TimeoutError:
        pass
    return codes


async def test_a_save_after_the_robot_file_changed_shows_the_new_refusal(
        client: LanguageClient, tmp_path):
    (tmp_path / "arm.toml").write_text('robot = "panda"\njoint_velocity = 2.0\n')
    path = tmp_path / "f.aou"
    text = (BEHAVIOURS / "fearful.aou").read_text().replace(
        "behaviour fearful : fearful\n", 'behaviour fearful : fearful\nrobot "arm.toml"\n')
    path.write_text(text)
    uri = path.as_uri()
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=1, text=text)))
    client.text_document_did_save(types.DidSaveTextDocumentParams(
        types.TextDocumentIdentifier(uri)))
    for _ in range(600):  # the compiled episodes' figures come after its diagnostics
        h = await client.text_document_hover_async(types.HoverParams(
            types.TextDocumentIdentifier(uri), types.Position(5, 2)))
        if h is not None and "episodes, compiled" in h.contents.value:
            break
        await asyncio.sleep(0.1)
    assert "episodes, compiled" in h.contents.value
    assert "C308" not in {d.code for d in client.diagnostics[uri]}  # it fits 2.0 rad/s
    (tmp_path / "arm.toml").write_text('robot = "panda"\njoint_velocity = 0.5\n')
    assert "C308" in await _compiled(client, uri, "C308")  # saved again, no edit
