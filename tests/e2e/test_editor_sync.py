"""The server holds the editor's text exactly, whatever characters it has.

A client model written from the protocol's definitions (lines end at ``\\n``, ``\\r\\n``
and a lone ``\\r`` only; columns in UTF-16 code units, UTF-8 bytes or UTF-32 code
points, as agreed at ``initialize``) makes random incremental edits full of the
characters other line models split at (form feed, vertical tab, the file, group and
record separators, NEL, U+2028, U+2029), lone carriage returns, characters of two
UTF-16 units (split between their units too, as an editor working in UTF-16 can) and
lone surrogates. After every edit the server's text (``aou/documentText``) is the
client's; every diagnostic lies inside its line; Format Document, applied by the model,
gives exactly ``aouc fmt``'s text and leaves both sides equal."""

from __future__ import annotations

import asyncio
import random
import re
import sys

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed")
from lsprotocol import types  # noqa: E402
from pytest_lsp import ClientServerConfig, LanguageClient  # noqa: E402

from aou_dsl.lang.formatter import format_source  # noqa: E402
from tests.lsp_server import ROOT  # noqa: E402

pytestmark = pytest.mark.asyncio(loop_scope="function")

#: Every character some line model ends a line at; only the first three are line ends
#: to the protocol.
LINE_LIKE = ["\n", "\r", "\r\n", "\f", "\v", "\x1c", "\x1d", "\x1e", "\x85", "\u2028",
             "\u2029"]
PIECES = [*LINE_LIKE, *LINE_LIKE, "\r\r", "\n\r", "😀", "a😀b", "\U0010ffff", "é", "€",
          "\ud800", "\udc00", "pause 1s", "pause 3m", "tilt 20deg", "approach a=0.05",
          "behaviour h : hesitant", "# note", ";", " ", "x3", "sequence {", "}", ""]
SEED = "behaviour h : hesitant\fx\r\npause 1s\u2028pause 2s\rretreat 0.06m a=0.12 x3\n" \
       "tilt 20deg\x85# a comment\u2029\vapproach a=0.05\r\r\n😀 pause 1s\n"
_EOL = re.compile(r"\r\n|\r|\n")


class Model:
    """The editor's side: the text, positions in the agreed encoding's units."""

    def __init__(self, text: str, encoding: str):
        self.encoding = encoding
        self.text = text

    def _units(self, s: str) -> int:
        if self.encoding == "utf-16":
            return len(s.encode("utf-16-le", "surrogatepass")) // 2
        if self.encoding == "utf-8":
            return len(s.encode("utf-8", "surrogatepass"))
        return len(s)

    # UTF-16 is edited as code units (an offset may fall between the two units of a
    # character); UTF-8 and UTF-32 as characters.
    def _cells(self) -> list:
        if self.encoding == "utf-16":
            b = self.text.encode("utf-16-le", "surrogatepass")
            return [b[i:i + 2] for i in range(0, len(b), 2)]
        return list(self.text)

    def _join(self, cells: list) -> str:
        if self.encoding == "utf-16":
            return b"".join(cells).decode("utf-16-le", "surrogatepass")
        return "".join(cells)

    def position(self, cells: list, at: int) -> types.Position:
        """The protocol's position of cell ``at``."""
        head = self._join(cells[:at])
        ends = list(_EOL.finditer(head))
        start = ends[-1].end() if ends else 0
        return types.Position(len(ends), self._units(head[start:]))

    def edit(self, rng: random.Random) -> tuple[types.Range, str]:
        cells = self._cells()
        def outside_crlf(k: int) -> int:  # no position lies inside a \r\n
            return k - 1 if 0 < k < len(cells) and \
                self._join(cells[k - 1:k + 1]) == "\r\n" else k

        a = outside_crlf(rng.randint(0, len(cells)))
        b = outside_crlf(min(len(cells), a + rng.choice([0, 0, 1, 2, 5, 20])))
        a, b = min(a, b), max(a, b)
        new = "".join(rng.choice(PIECES) for _ in range(rng.choice([0, 1, 1, 2, 3])))
        rng_ = types.Range(self.position(cells, a), self.position(cells, b))
        if self.encoding == "utf-16":
            nb = new.encode("utf-16-le", "surrogatepass")
            ins = [nb[i:i + 2] for i in range(0, len(nb), 2)]
        else:
            ins = list(new)
        self.text = self._join(cells[:a] + ins + cells[b:])
        if self.encoding != "utf-16":
            # a high and a low surrogate side by side travel in JSON as the one character
            # they make (code points have no halves): so does the text the editor holds
            self.text = self.text.encode("utf-16-le", "surrogatepass").decode(
                "utf-16-le", "surrogatepass")
        return rng_, new

    def lines(self) -> list[str]:
        return _EOL.split(self.text)

    def apply(self, edits: list[types.TextEdit]) -> None:
        """The edits of a formatting, as the editor applies them."""
        lines = self.lines()
        offsets = [0, *(m.end() for m in _EOL.finditer(self.text))]

        def offset(p: types.Position) -> int:
            if p.line >= len(lines):
                return len(self.text)
            line = lines[p.line]
            for i in range(len(line) + 1):
                if self._units(line[:i]) >= p.character:
                    return offsets[p.line] + i
            return offsets[p.line] + len(line)
        for e in sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character),
                        reverse=True):
            self.text = self.text[:offset(e.range.start)] + e.new_text + \
                self.text[offset(e.range.end):]

    def inside(self, rng: types.Range) -> bool:
        lines = self.lines()

        def ok(p: types.Position) -> bool:
            return 0 <= p.line < len(lines) and 0 <= p.character <= self._units(lines[p.line])
        return ok(rng.start) and ok(rng.end) and \
            (rng.start.line, rng.start.character) <= (rng.end.line, rng.end.character)


def _config() -> ClientServerConfig:
    return ClientServerConfig(server_command=[sys.executable, "-m", "aou_dsl", "server"])


@pytest_lsp.fixture(config=_config(), params=["utf-16", "utf-8", "utf-32"])
async def client(lsp_client: LanguageClient, request):
    lsp_client.encoding = request.param
    result = await lsp_client.initialize_session(types.InitializeParams(
        capabilities=types.ClientCapabilities(general=types.GeneralClientCapabilities(
            position_encodings=[request.param])),
        root_uri=ROOT.as_uri(), initialization_options={"compileOnType": False}))
    assert result.capabilities.position_encoding == request.param
    yield
    await lsp_client.shutdown_session()


async def _server_text(client: LanguageClient, uri: str) -> dict:
    held = await asyncio.wait_for(client.protocol.send_request_async(
        "aou/documentText", {"uri": uri}), 30)
    return held if isinstance(held, dict) else held._asdict()  # pygls's client: a tuple


async def _sync(client: LanguageClient, edits: int, seed: int) -> None:
    rng = random.Random(seed)
    model = Model(SEED, client.encoding)
    uri = (ROOT / f"sync-{client.encoding}.aou").as_uri()
    doc = types.TextDocumentIdentifier(uri)
    published: list[types.PublishDiagnosticsParams] = []
    features = client.protocol.fm.features
    keep = features[types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS]

    def record(*args, **kwargs):
        published.append(args[-1])
        return keep(*args, **kwargs)

    features[types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS] = record
    version = 1
    texts = {version: model.text}
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=version, text=model.text)))
    for k in range(edits):
        changes = []
        for _ in range(rng.choice([1, 1, 1, 2, 3])):  # several changes in one message too
            rng_, new = model.edit(rng)
            changes.append(types.TextDocumentContentChangePartial(range=rng_, text=new))
        version += 1
        texts[version] = model.text
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(version=version, uri=uri), changes))
        held = await _server_text(client, uri)
        assert held["version"] == version
        assert held["text"] == model.text, (k, changes)
        if k % 10 == 9:  # Format Document, applied by the editor and sent back
            edits_ = await asyncio.wait_for(client.text_document_formatting_async(
                types.DocumentFormattingParams(doc, types.FormattingOptions(2, True))), 30)
            if edits_:
                before = model.text
                model.apply(edits_)
                assert model.text == format_source(before, "x.aou")
                version += 1
                texts[version] = model.text
                client.text_document_did_change(types.DidChangeTextDocumentParams(
                    types.VersionedTextDocumentIdentifier(version=version, uri=uri),
                    [types.TextDocumentContentChangePartial(range=e.range, text=e.new_text)
                     for e in edits_]))
                held = await _server_text(client, uri)
                assert held["text"] == model.text
    for p in published:  # each diagnostic inside the text it was published for
        inside = Model(texts[p.version], client.encoding)
        for d in p.diagnostics:
            assert inside.inside(d.range), (d, texts[p.version])
    assert published and published[-1].version == version


async def test_random_edits_keep_the_text_exact(client: LanguageClient):
    await _sync(client, 120, seed=3)


@pytest.mark.slow
async def test_random_edits_keep_the_text_exact_long(client: LanguageClient):
    await _sync(client, 1500, seed=4)


async def test_lone_carriage_returns_place_diagnostics_on_their_lines(client: LanguageClient):
    """A lone \\r ends a line for the editor: the error after it is on the next line,
    inside it; formatting does not repeat a line."""
    text = "pause 1s;\rpause 3m;\rtilt 20deg\n"
    uri = (ROOT / f"cr-{client.encoding}.aou").as_uri()
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=1, text=text)))
    for _ in range(100):
        if uri in client.diagnostics:
            break
        await asyncio.sleep(0.05)
    (d,) = [d for d in client.diagnostics[uri] if d.code == "V102"]
    assert d.range == types.Range(types.Position(1, 6), types.Position(1, 8))
    edits = await client.text_document_formatting_async(types.DocumentFormattingParams(
        types.TextDocumentIdentifier(uri), types.FormattingOptions(2, True)))
    model = Model(text, client.encoding)
    model.apply(edits or [])
    assert model.text == (format_source(text, "x.aou") if edits else text)
    assert model.text.count("tilt") == 1 and model.text.count("pause") == 2
