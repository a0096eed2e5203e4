"""Only the studio's own page drives it: the token of the printed address, the Host of
every request and the Origin of every websocket, checked by a real server against real
clients (the ``websockets`` library and plain HTTP), and values a page sends that the
page itself would never send."""

from __future__ import annotations

import asyncio
import http.client
import os
import shutil
from pathlib import Path

import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

import msgspec
import viser
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed, InvalidStatus

from aou_dsl.studio.gate import Gate

ROOT = str(Path(__file__).resolve().parents[2])
PROTOCOL = f"viser-v{viser.__version__}"


# --- the check on its own ------------------------------------------------------------

def test_the_host_must_name_the_server_itself():
    gate = Gate("127.0.0.1", token="t")
    for host in ("127.0.0.1:8080", "localhost:8080", "LOCALHOST:8080", "[::1]:8080"):
        assert gate.own_host(host, 8080), host
    for host in ("evil.example:8080", "127.0.0.1:8081", "127.0.0.1", "localhost.evil:8080",
                 "127.0.0.1.nip.io:8080", ":8080", "", "10.0.0.1:8080", "[::2]:8080"):
        assert not gate.own_host(host, 8080), host
    wide = Gate("0.0.0.0", token="t")  # every address of the machine: by number only
    assert wide.own_host("192.168.1.7:8080", 8080) and wide.own_host("[fe80::1]:8080", 8080)
    assert not wide.own_host("rebind.evil.example:8080", 8080)
    named = Gate("studio.lab", token="t")
    assert named.own_host("studio.lab:8080", 8080)
    assert not named.own_host("evil.example:8080", 8080)


def test_the_origin_must_be_the_servers_own_page():
    gate = Gate(token="t")
    assert gate.own_origin("http://127.0.0.1:8080", 8080)
    assert gate.own_origin("http://localhost:8080", 8080)
    for origin in ("http://evil.example", "http://evil.example:8080", "null", "",
                   "https://127.0.0.1:8080", "http://127.0.0.1:9999", "file://",
                   "http://user@127.0.0.1:8080", "http://127.0.0.1:8080/x?y"):
        assert not gate.own_origin(origin, 8080), origin


def test_every_request_needs_the_token_in_its_query_or_its_cookie():
    gate = Gate(token="s3cret")
    ok = (["127.0.0.1:8080"], [], [])
    assert gate.verdict("/?token=s3cret", 8080, *ok) is None
    assert gate.verdict("/index.html?x=1&token=s3cret", 8080, *ok) is None
    for path in ("/", "/?token=", "/?token=s3cre", "/?token=s3cret&token=s3cret",
                 "/?tok=s3cret", "/s3cret"):
        refused = gate.verdict(path, 8080, *ok)
        assert refused is not None and refused.status == 403, path
    jar = ["a=b; aou-token-8080=s3cret"]
    assert gate.verdict("/", 8080, ["127.0.0.1:8080"], [], jar) is None
    assert gate.verdict("/", 8081, ["127.0.0.1:8081"], [], jar) is not None  # another port's
    assert gate.verdict("/", 8080, ["127.0.0.1:8080"], [], ["aou-token-8080=nope"])
    # the token does not open the door to another host or a foreign page
    assert gate.verdict("/?token=s3cret", 8080, ["evil.example:8080"], [], []).status == 403
    assert gate.verdict("/?token=s3cret", 8080, ["127.0.0.1:8080"],
                        ["http://evil.example"], []).status == 403
    assert gate.verdict("/?token=s3cret", 8080, ["127.0.0.1:8080", "127.0.0.1:8080"],
                        [], []) is not None  # two Host headers: which one is meant?
    assert Gate().token != Gate().token and len(Gate().token) >= 32


# --- a real studio -------------------------------------------------------------------

@pytest.fixture(scope="module")
def studio(tmp_path_factory):
    from aou_dsl.studio.app import Studio

    folder = tmp_path_factory.mktemp("gate")
    path = folder / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    s = Studio(str(path), port=0, watch=False).start()
    s.original = path.read_bytes()
    yield s
    s.close()
    assert path.read_bytes() == s.original  # nothing here saves
    assert os.listdir(folder) == ["h.aou"]


def _get(port: int, path: str, host: str | None = None,
         headers: dict[str, str] | None = None) -> tuple[int, str | None, bytes]:
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
    c.putheader("Host", host or f"127.0.0.1:{port}")
    for k, v in (headers or {}).items():
        c.putheader(k, v)
    c.endheaders()
    r = c.getresponse()
    return r.status, r.getheader("Set-Cookie"), r.read()


def test_http_needs_the_token_and_the_servers_own_host(studio):
    port, token = studio.port, studio.gate.token
    assert studio.url == f"http://127.0.0.1:{port}/?token={token}"
    status, _, body = _get(port, "/")
    assert status == 403 and b"token" in body and b"<html" not in body
    status, cookie, body = _get(port, f"/?token={token}")
    assert status == 200 and b"<html" in body
    assert cookie.startswith(f"aou-token-{port}={token};") and "HttpOnly" in cookie \
        and "SameSite=Strict" in cookie
    status, _, body = _get(port, "/", headers={"Cookie": f"aou-token-{port}={token}"})
    assert status == 200 and b"<html" in body  # the page's own requests carry the cookie
    for host in (f"evil.example:{port}", f"127.0.0.1:{port + 1}", "127.0.0.1"):
        status, _, body = _get(port, f"/?token={token}", host=host)  # DNS rebinding
        assert status == 403 and b"<html" not in body, host
    status, _, _ = _get(port, f"/?token={token}", host=f"localhost:{port}")
    assert status == 200
    status, _, _ = _get(port, f"/?token={token}x")
    assert status == 403


async def _open(port: int, *, query: str = "", origin: str | None = None,
                host: str | None = None, cookie: str | None = None,
                send: list[bytes] = (), quiet: float = 1.5) -> tuple[str, object]:
    """Connect as viser's page does, send ``send``, and read until ``quiet`` seconds
    pass without a message; ("open", bytes received) or ("refused", status) or
    ("closed", code)."""
    headers = {"Cookie": cookie} if cookie else {}
    try:  # to 127.0.0.1, whatever ``host`` the request names (as a rebound name does)
        async with connect(f"ws://{host or f'127.0.0.1:{port}'}/{query}",
                           host="127.0.0.1", port=port, subprotocols=[PROTOCOL],
                           origin=origin, additional_headers=headers, max_size=None,
                           open_timeout=30) as ws:
            for raw in send:
                await ws.send(raw)
            got = 0
            end = asyncio.get_running_loop().time() + 4 * quiet
            try:  # the replay of the scene, then the player's ticks: for a while
                while asyncio.get_running_loop().time() < end:
                    got += len(await asyncio.wait_for(ws.recv(), quiet))
            except TimeoutError:
                pass
            return "open", got
    except InvalidStatus as exc:
        return "refused", exc.response.status_code
    except ConnectionClosed as exc:
        return "closed", exc.rcvd.code if exc.rcvd else None


def test_websockets_from_another_origin_without_the_token_or_to_another_host_are_refused(
        studio):
    port, token = studio.port, studio.gate.token
    q = f"?token={token}"
    own = f"http://127.0.0.1:{port}"
    assert asyncio.run(_open(port, query=q, origin="http://evil.example")) == ("refused", 403)
    assert asyncio.run(_open(port, query=q, origin="null")) == ("refused", 403)
    assert asyncio.run(_open(port, origin=own)) == ("refused", 403)
    assert asyncio.run(_open(port, query="?token=wrong", origin=own)) == ("refused", 403)
    assert asyncio.run(_open(port, query=q, origin=own,
                             host=f"evil.example:{port}")) == ("refused", 403)
    # the page's own: the token in the query, or in the cookie its first answer set
    state, got = asyncio.run(_open(port, query=q, origin=own))
    assert state == "open" and got > 10_000  # the scene came
    state, got = asyncio.run(_open(port, origin=f"http://localhost:{port}",
                                   host=f"localhost:{port}",
                                   cookie=f"aou-token-{port}={token}"))
    assert state == "open" and got > 10_000


def _update(uuid: str, updates: object) -> bytes:
    return msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": uuid,
                                   "updates": updates})


def _uuid(handle) -> str:
    return handle._impl.uuid


def test_a_value_no_slider_holds_does_not_break_the_next_page(studio):
    port, q = studio.port, f"?token={studio.gate.token}"
    count = studio.sliders.handles["pause_count"]
    before = count.value
    first = _update(_uuid(count), {"value": 99999999999999999999.0})
    state, _ = asyncio.run(_open(port, query=q, send=[first]))
    assert state == "open"
    # a page that connects afterwards gets the whole scene, not a 1011
    state, got = asyncio.run(_open(port, query=q))
    assert (state, got > 10_000) == ("open", True)
    assert count.value == count.max and isinstance(count.value, int)  # clamped
    assert "pause_count" in studio.notice.content and "range" in studio.notice.content
    _wait_idle(studio)
    count.value = before  # the studio's own slider back as it was
    studio.set_values({**studio.sliders.values(), "pause_count": before})


def _wait_idle(studio, timeout: float = 120.0) -> None:
    import time

    end = time.monotonic() + timeout
    time.sleep(0.3)
    while time.monotonic() < end:
        if studio._pending is None and not studio._busy.locked():
            time.sleep(0.3)
            if studio._pending is None and not studio._busy.locked():
                return
        time.sleep(0.1)
    raise AssertionError("the studio did not settle")


def test_a_viser_that_serves_without_the_gate_is_refused_not_run_open(monkeypatch):
    """Should viser ever bind its server without the ``websockets`` call the gate
    wraps, or take a page's messages without the tables the check uses, the studio
    refuses to start instead of serving unguarded."""
    from aou_dsl.studio import serving

    stopped = []

    class Unguarded:  # binds some other way: the gate's wrapper is never called
        def __init__(self, **kwargs):
            pass

        def stop(self):
            stopped.append(True)

    monkeypatch.setattr(viser, "ViserServer", Unguarded)
    with pytest.raises(RuntimeError, match="without aou's check"):
        serving.open_server(Gate(), "127.0.0.1", 0, "x")
    with pytest.raises(RuntimeError, match="cannot be guarded"):
        serving.Inbox(Unguarded(), print)
    assert stopped == [True, True]
