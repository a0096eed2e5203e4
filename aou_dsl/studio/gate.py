"""The door of a local web server: only the page its command printed comes in.

A server bound to this machine is still reachable from every web page the user visits:
a page on ``http://evil.example`` can open a websocket to ``ws://127.0.0.1:8080``
(cross-site websocket hijacking), and a name that resolves to 127.0.0.1 lets a page
read the server's answers as its own (DNS rebinding). Local development servers close
this the way :class:`Gate` does:

- the ``Host`` of every request must name the server itself (``127.0.0.1:PORT``,
  ``localhost:PORT``, ``[::1]:PORT``, or the address it was told to bind), so a
  rebound name is refused;
- the ``Origin`` a browser sends with a websocket (and with a cross-site request) must
  be the server's own page;
- every request carries the per-run token the command printed in the page's address
  (``http://127.0.0.1:PORT/?token=...``), in the query or in the cookie the first
  answer sets (the page's own scripts and websocket then carry it), so a process or a
  page that did not see the address gets nothing.

:meth:`Gate.verdict` is the check, on plain strings (no web framework in it);
:meth:`Gate.process_request` adapts it to the ``websockets`` library's
``process_request`` hook, which serves both the page and its websocket.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any
from urllib.parse import parse_qs, urlsplit

__all__ = ["LOCAL_NAMES", "Gate", "Refusal"]

#: The names and addresses of this machine a browser may use for a local server.
LOCAL_NAMES = ("127.0.0.1", "localhost", "[::1]")
#: The wildcard binds: the server answers on every address of the machine.
_WILDCARDS = ("0.0.0.0", "::", "[::]", "")


@dataclass(frozen=True)
class Refusal:
    """A request turned away: the HTTP ``status`` and why (said to the client)."""

    status: int
    reason: str


class Gate:
    """The check of one server's requests.

    Args:
        host: the address the server binds (``127.0.0.1`` unless told otherwise).
        token: the per-run secret (a fresh random one by default).
        name: names the cookie that carries the token (``NAME-token-PORT``).
    """

    def __init__(self, host: str = "127.0.0.1", token: str | None = None,
                 name: str = "aou") -> None:
        self.host = host
        self.token = token if token is not None else secrets.token_urlsafe(24)
        self.name = name

    # --- the addresses ---------------------------------------------------------------

    def url(self, port: int) -> str:
        """The page's address with its token: what the command prints."""
        host = "127.0.0.1" if self.host in (*LOCAL_NAMES, *_WILDCARDS) else self.host
        if ":" in host and not host.startswith("["):
            host = f"[{host}]"
        return f"http://{host}:{port}/?token={self.token}"

    def cookie(self, port: int) -> str:
        """The name of the cookie that carries the token to the server on ``port``
        (cookies are kept per host, not per port: two servers keep two)."""
        return f"{self.name}-token-{port}"

    def own_host(self, value: str, port: int) -> bool:
        """Whether the ``Host`` header ``value`` names this server on ``port``."""
        name, sep, got_port = value.strip().lower().rpartition(":")
        if not sep or got_port != str(port) or not name:
            return False
        if name in LOCAL_NAMES:
            return True
        bound = self.host.lower()
        if bound not in _WILDCARDS:
            return name == bound or name == f"[{bound}]"
        # Bound to every address: any address of the machine may be used, by number
        # (a rebound name is a name, never a number).
        try:
            ipaddress.ip_address(name[1:-1] if name.startswith("[") else name)
        except ValueError:
            return False
        return True

    def own_origin(self, value: str, port: int) -> bool:
        """Whether the ``Origin`` header ``value`` is this server's own page."""
        parts = urlsplit(value.strip())
        if parts.scheme != "http" or parts.path not in ("", "/") or parts.query \
                or parts.username is not None:
            return False
        return self.own_host(parts.netloc, port)

    # --- the check -----------------------------------------------------------------

    def verdict(self, path: str, port: int, hosts: Sequence[str], origins: Sequence[str],
                cookies: Sequence[str]) -> Refusal | None:
        """None when the request may pass; else why not.

        Args:
            path: the request's target (``/index.html?token=...``).
            port: the port the request came in on (the server's own).
            hosts, origins, cookies: every ``Host``, ``Origin`` and ``Cookie`` header
                the request carries.
        """
        if len(hosts) != 1 or not self.own_host(hosts[0], port):
            return Refusal(403, "this server answers only to its own address "
                           f"(127.0.0.1:{port} or localhost:{port})")
        if len(origins) > 1 or (origins and not self.own_origin(origins[0], port)):
            return Refusal(403, "this server answers only to its own page, not to a page "
                           "of another site")
        if not self.has_token(path, port, cookies):
            return Refusal(403, "open the address with its token, as the command printed "
                           "it (http://...:PORT/?token=...)")
        return None

    def has_token(self, path: str, port: int, cookies: Sequence[str]) -> bool:
        """Whether the request carries the token, in its query or in its cookie."""
        given = self.query_token(path)
        if given is not None and self._is_token(given):
            return True
        name = self.cookie(port)
        for header in cookies:
            for item in header.split(";"):
                key, _, value = item.strip().partition("=")
                if key == name and self._is_token(value):
                    return True
        return False

    @staticmethod
    def query_token(path: str) -> str | None:
        """The token given in the query of ``path`` (None: none, or more than one)."""
        values = parse_qs(urlsplit(path).query, keep_blank_values=True).get("token", [])
        return values[0] if len(values) == 1 else None

    def _is_token(self, value: str) -> bool:
        return hmac.compare_digest(value.encode("utf-8", "replace"),
                                   self.token.encode("utf-8"))

    # --- the websockets library ------------------------------------------------------

    def process_request(self, inner: Callable[[Any, Any], Any] | None = None
                        ) -> Callable[[Any, Any], Any]:
        """A ``process_request`` for ``websockets``' server: a request the gate refuses
        is answered 403 (a websocket is refused in its handshake); one it passes goes to
        ``inner`` (the server's own, serving its files), and an answer to a request that
        brought the token in its query sets the cookie that carries it on."""

        def gated(connection: Any, request: Any) -> Any:
            port = int(connection.local_address[1])
            headers = request.headers
            refused = self.verdict(request.path, port, headers.get_all("Host"),
                                   headers.get_all("Origin"), headers.get_all("Cookie"))
            if refused is not None:
                return connection.respond(refused.status, refused.reason + "\n")
            response = inner(connection, request) if inner is not None else None
            if response is not None and hasattr(response, "__await__"):
                return _then_cookie(self, response, request.path, port)
            return self._with_cookie(response, request.path, port)

        return gated

    def _with_cookie(self, response: Any, path: str, port: int) -> Any:
        given = self.query_token(path)
        if response is not None and given is not None and self._is_token(given):
            response.headers["Set-Cookie"] = (
                f"{self.cookie(port)}={self.token}; Path=/; HttpOnly; SameSite=Strict")
        return response


async def _then_cookie(gate: Gate, pending: Any, path: str, port: int) -> Any:
    return gate._with_cookie(await pending, path, port)
