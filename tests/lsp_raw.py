"""``aouc server`` driven with raw bytes on its standard input, for what a well-behaved
client never sends: broken headers and bodies, wrong ids and parameters. The responses
are read from its standard output by a thread of their own, as the base protocol frames
them (written here from the protocol's definition, not from the server's code)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def frame(body: bytes | dict | list | str | None) -> bytes:
    """One message: ``Content-Length`` in bytes, an empty line, the body."""
    data = body if isinstance(body, bytes) else json.dumps(body).encode("utf-8")
    return b"Content-Length: %d\r\n\r\n" % len(data) + data


def request(msg_id: object, method: str, params: object = None) -> dict:
    msg: dict = {"jsonrpc": "2.0", "id": msg_id, "method": method}
    if params is not None:
        msg["params"] = params
    return msg


def hover(msg_id: object, uri: str, line: int = 0, character: int = 0) -> dict:
    return request(msg_id, "textDocument/hover", {
        "textDocument": {"uri": uri}, "position": {"line": line, "character": character}})


class Raw:
    """A server process and every message it wrote."""

    def __init__(self, env: dict | None = None) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "aou_dsl", "server"], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
            env={**os.environ, **(env or {})})
        self.messages: list[dict] = []
        self.bad_frames = 0
        self._lock = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()
        self.stderr = b""
        threading.Thread(target=self._read_err, daemon=True).start()

    def _read_err(self) -> None:
        assert self.proc.stderr is not None
        while chunk := self.proc.stderr.read1(1 << 16):
            self.stderr += chunk

    def _read(self) -> None:
        out = self.proc.stdout
        assert out is not None
        while True:
            length = None
            while True:  # the header
                line = out.readline()
                if not line:
                    return
                if line in (b"\r\n", b"\n"):
                    break
                name, _, value = line.partition(b":")
                if name.strip().lower() == b"content-length":
                    length = int(value.strip())
            if length is None:
                self.bad_frames += 1
                continue
            body = out.read(length)
            with self._lock:
                try:
                    self.messages.append(json.loads(body))
                except ValueError:
                    self.bad_frames += 1
                self._lock.notify_all()

    def send(self, data: bytes) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def initialize(self, encoding: str | None = None) -> dict:
        caps = {"general": {"positionEncodings": [encoding]}} if encoding else {}
        self.send(frame(request(0, "initialize", {"capabilities": caps, "processId": None,
                                                  "rootUri": None})))
        self.send(frame({"jsonrpc": "2.0", "method": "initialized", "params": {}}))
        return self.response(0)

    def response(self, msg_id: object, timeout: float = 20.0) -> dict:
        """The response to ``msg_id`` (AssertionError when none comes in time: a hang)."""
        end = time.monotonic() + timeout
        with self._lock:
            while True:
                for m in self.messages:
                    if "method" not in m and m.get("id") == msg_id and \
                            type(m.get("id")) is type(msg_id):
                        return m
                left = end - time.monotonic()
                assert left > 0, f"no response to id {msg_id!r} in {timeout} s"
                assert self.proc.poll() is None, f"the server ended: {self.stderr[-2000:]!r}"
                self._lock.wait(min(left, 0.2))

    def responses(self) -> list[dict]:
        with self._lock:
            return [m for m in self.messages if "method" not in m]

    def close(self) -> int:
        if self.proc.poll() is None:
            try:
                self.send(frame(request("bye", "shutdown")))
                self.response("bye")
                self.send(frame({"jsonrpc": "2.0", "method": "exit"}))
            except (AssertionError, BrokenPipeError):
                self.proc.kill()
        try:
            return self.proc.wait(20)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
