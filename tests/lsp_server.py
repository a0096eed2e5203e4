"""``aouc server`` as an editor starts it: a subprocess driven over stdio by pytest-lsp's
client. The one fixture the editor tests share (import it after skipping when the lsp
extra is missing)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

ROOT = Path(__file__).resolve().parent.parent


def server_client(scope: str = "function"):
    """A fixture named ``client``: a server started and initialised for each ``scope``
    (compiling on save only, so a test decides when a build runs), shut down after it."""

    @pytest_lsp.fixture(
        config=ClientServerConfig(server_command=[sys.executable, "-m", "aou_dsl", "server"]),
        scope=scope)
    async def client(lsp_client: LanguageClient):
        await lsp_client.initialize_session(types.InitializeParams(
            capabilities=types.ClientCapabilities(), root_uri=ROOT.as_uri(),
            initialization_options={"compileOnType": False}))
        yield
        await lsp_client.shutdown_session()

    return client
