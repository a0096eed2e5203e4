"""``aouc study serve``: a built study served, and each participant's answers stored.

Standard library only (``http.server``, ``sqlite3``). What is served is a short list:
``index.html``, ``experiment.js``, ``timeline.json``, ``stimuli/<sha256>.mp4`` and the
study's own copy of jsPsych under ``jspsych/``; anything else (the store, the cache, a
dot file, a path that climbs out) is 404. A request body is at most :data:`MAX_BODY`
bytes.

Only the study's own page is answered, as the studio answers only its own
(:class:`~aou_dsl.studio.gate.Gate`): every request's ``Host`` must name this server (a
DNS name rebound to this machine is refused), an ``Origin`` must be its own page (a page
of another site cannot post answers), and every request carries the study's token, in
the query of the address the command prints (``http://127.0.0.1:PORT/?token=...``) or
in the cookie the first page sets. The token is the study folder's
(:data:`TOKEN_FILE`, made on first serve, readable by its owner only): a server
restarted mid-study takes it again, so a participant's page still reaches it.

A submission (``POST /submit``: ``{"participant": ID, "data": [rows]}``) is stored in one
transaction of the SQLite store ``answers.sqlite`` in the study folder, in write-ahead
logging mode with full synchronisation: once the page is told 201, the answer is on disk,
and a server killed afterwards loses nothing. The table is
``submissions(seq integer primary key, participant text unique, received text, data
text)``; a participant id that already submitted is refused (409).
"""

from __future__ import annotations

import datetime
import errno
import json
import mimetypes
import os
import re
import secrets
import sqlite3
import stat
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

from ..core.codes import I501, I504
from ..core.diagnostics import AouError, Span, diag
from ..studio.gate import Gate

__all__ = ["MAX_BODY", "STORE", "TOKEN_FILE", "StudyServer", "open_store", "serve",
           "study_token"]

STORE = "answers.sqlite"
#: The study folder's token (never served: a dot file).
TOKEN_FILE = ".aou-serve-token"
#: The largest submission accepted (bytes): a participant's rows are some tens of kB.
MAX_BODY = 4_000_000
#: The most rows one submission may hold.
MAX_ROWS = 20_000
LOCAL = "127.0.0.1"
_SERVED = re.compile(r"^(index\.html|experiment\.js|timeline\.json|stimuli/[0-9a-f]{64}\.mp4|"
                     r"jspsych/[A-Za-z0-9@._/-]+\.(js|css))$")
_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
          ".json": "application/json", ".mp4": "video/mp4", ".css": "text/css; charset=utf-8"}


def open_store(folder: str) -> sqlite3.Connection:
    """The study folder's answer store, made when missing (WAL, full sync)."""
    db = sqlite3.connect(os.path.join(folder, STORE), check_same_thread=False,
                         isolation_level=None)
    db.execute("pragma journal_mode=wal")
    db.execute("pragma synchronous=full")
    db.execute("create table if not exists submissions(seq integer primary key, "
               "participant text unique, received text, data text)")
    return db


def study_token(folder: str) -> str:
    """The token of the study in ``folder``: read from :data:`TOKEN_FILE`, or made and
    written there (mode 0600) on the first serve.

    Raises:
        AouError: I501 when the file is there but is not a regular file holding a token.
    """
    path = os.path.join(folder, TOKEN_FILE)
    where = Span.whole_file(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except FileNotFoundError:
        token = secrets.token_urlsafe(24)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
        with os.fdopen(fd, "w") as fh:
            fh.write(token + "\n")
        return token
    except OSError as exc:
        raise AouError(diag(I501, f"cannot read the study's token `{path}`: "
                            f"{exc.strerror}", where)) from None
    with os.fdopen(fd, "rb") as fh:
        regular = stat.S_ISREG(os.fstat(fh.fileno()).st_mode)
        text = fh.read(200).decode("ascii", "replace").strip() if regular else ""
    if not re.fullmatch(r"[A-Za-z0-9_-]{16,100}", text):
        raise AouError(diag(I501, f"`{path}` does not hold a study's token (remove it: "
                            "the next serve makes one, and participants need the new "
                            "address)", where))
    return text


class StudyServer(ThreadingHTTPServer):
    """The server of one study folder; ``url`` once bound (with the study's token)."""

    daemon_threads = True
    allow_reuse_address = True

    def __init__(self, folder: str, host: str = LOCAL, port: int = 8000):
        self.folder = os.path.realpath(folder)
        self.gate = Gate(host, study_token(self.folder), name="aou-study")
        self.db = open_store(self.folder)
        self.lock = threading.Lock()
        super().__init__((host, port), _Handler)
        self.port = int(self.server_address[1])

    @property
    def url(self) -> str:
        """The address participants open: the server's, with the study's token."""
        return self.gate.url(self.port)

    def store(self, participant: str, data: list) -> bool:
        """Store one submission in one transaction; False when the id already has one."""
        now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
        with self.lock:
            try:
                self.db.execute("begin immediate")
                self.db.execute("insert into submissions(participant, received, data) "
                                "values (?, ?, ?)", (participant, now, json.dumps(data)))
                self.db.execute("commit")
            except sqlite3.IntegrityError:
                self.db.execute("rollback")
                return False
        return True

    def server_close(self) -> None:
        super().server_close()
        self.db.close()


class _Handler(BaseHTTPRequestHandler):
    server: StudyServer
    timeout = 30
    protocol_version = "HTTP/1.1"

    def log_message(self, format, *args):  # noqa: A002 - the base class's name
        pass

    def _reply(self, code: int, body: bytes = b"", kind: str = "text/plain; charset=utf-8",
               headers: dict | None = None) -> None:
        self.send_response(code)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("X-Content-Type-Options", "nosniff")
        for k, v in ({"Cache-Control": "no-store"} | (headers or {})).items():
            self.send_header(k, v)
        gate, port = self.server.gate, self.server.port
        if gate.has_token(self.path, port, ()):  # the token came in the address
            self.send_header("Set-Cookie", f"{gate.cookie(port)}={gate.token}; Path=/; "
                             "HttpOnly; SameSite=Strict")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _host_ok(self) -> bool:
        """Whether the request may pass the study's gate (its address, its page, its
        token); else it is answered 403, saying why."""
        h = self.headers
        refused = self.server.gate.verdict(self.path, self.server.port, h.get_all("Host", []),
                                           h.get_all("Origin", []), h.get_all("Cookie", []))
        if refused is None:
            return True
        self.close_connection = True
        self._reply(refused.status, refused.reason.encode() + b"\n")
        return False

    def do_GET(self) -> None:  # noqa: N802 - http.server's name
        if not self._host_ok():
            return
        path = self.path.split("?", 1)[0].split("#", 1)[0]
        name = "index.html" if path == "/" else path.lstrip("/")
        if not _SERVED.match(name) or ".." in name or "//" in name:
            self._reply(404, b"not found\n")
            return
        full = os.path.join(self.server.folder, *name.split("/"))
        if not os.path.realpath(full).startswith(self.server.folder + os.sep):
            self._reply(404, b"not found\n")
            return
        try:
            with open(full, "rb") as fh:
                data = fh.read()
        except OSError:
            self._reply(404, b"not found\n")
            return
        kind = _TYPES.get(os.path.splitext(name)[1]) or mimetypes.guess_type(name)[0] or \
            "application/octet-stream"
        rng = self.headers.get("Range")
        m = re.fullmatch(r"bytes=(\d*)-(\d*)", rng.strip()) if rng else None
        if m and (m.group(1) or m.group(2)):
            size = len(data)
            if m.group(1):
                start = int(m.group(1))
                end = min(int(m.group(2)), size - 1) if m.group(2) else size - 1
            else:
                start, end = max(0, size - int(m.group(2))), size - 1
            if start >= size or start > end:
                self._reply(416, b"", headers={"Content-Range": f"bytes */{size}"})
                return
            self._reply(206, data[start:end + 1], kind, {
                "Content-Range": f"bytes {start}-{end}/{size}", "Accept-Ranges": "bytes",
                "Cache-Control": "max-age=31536000, immutable"})
            return
        # A video is named by its hash: it never changes, so the browser may keep it.
        keep = {"Cache-Control": "max-age=31536000, immutable"} if name.startswith(
            "stimuli/") else {}
        self._reply(200, data, kind, {"Accept-Ranges": "bytes", **keep})

    do_HEAD = do_GET

    def do_POST(self) -> None:  # noqa: N802
        if not self._host_ok():
            return
        if self.path != "/submit":
            self.close_connection = True
            self._reply(404, b"not found\n")
            return
        try:
            n = int(self.headers.get("Content-Length", ""))
        except ValueError:
            n = -1
        if not 0 < n <= MAX_BODY:
            self.close_connection = True
            self._reply(413 if n > MAX_BODY else 411, b"a submission of 1 byte to 4 MB\n")
            return
        body = self.rfile.read(n)
        try:
            doc = json.loads(body)
            pid, data = doc["participant"], doc["data"]
            ok = (isinstance(pid, str) and 0 < len(pid) <= 200 and isinstance(data, list)
                  and len(data) <= MAX_ROWS and all(isinstance(r, dict) for r in data))
        except (ValueError, KeyError, TypeError):
            ok = False
        if not ok:
            self._reply(400, b"expected {\"participant\": ID, \"data\": [rows]}\n")
            return
        if not self.server.store(pid, data):
            self._reply(409, b"this participant has already submitted\n")
            return
        print(f"aouc study: stored the answers of {pid}", file=sys.stderr, flush=True)
        self._reply(201, b"{\"stored\": true}\n", "application/json")


def serve(folder: str, *, host: str = LOCAL, port: int = 8000) -> int:
    """Serve the study in ``folder`` until interrupted."""
    if host not in (LOCAL, "localhost"):
        print(f"aouc: warning: the study's server binds {host}: anyone who can reach this "
              "machine can take the study and submit answers", file=sys.stderr)
    server = None
    for p in [port] if port == 0 else range(port, min(port + 20, 65536)):
        try:
            server = StudyServer(folder, host, p)
            break
        except OSError as exc:
            if exc.errno != errno.EADDRINUSE:
                raise AouError(diag(I504, f"cannot serve on {host}:{p}: {exc.strerror}",
                                    Span.whole_file("--host"))) from None
    if server is None:
        raise AouError(diag(I504, f"ports {port} to {port + 19} are all taken: choose "
                            "another with --port", Span.whole_file("--port")))
    if server.port != port and port != 0:
        print(f"aouc: port {port} is taken: serving on {server.port} (--port chooses)",
              file=sys.stderr)
    print(f"aouc study: serving {folder} at {server.url} (Ctrl-C stops); answers go to "
          f"{os.path.join(folder, STORE)}", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0
