"""The editor's speed: ``aouc server`` started as an editor starts it (a subprocess on
stdio, driven by pygls's client), and ``aouc fmt`` against ``aouc lint``.

- diagnostics after an edit of a 200-line file: from sending the change to receiving
  the diagnostics of that version (the round trip included);
- hover and completion: the answer's round trip, at positions over a shipped file;
- compile diagnostics after a save of hesitant on the Panda, warm (the first compile,
  which loads the robot, is left out): the compiler's, which the server publishes
  first; the checks' and the measuring's follow;
- ``aouc fmt --check`` of the shipped behaviours against ``aouc lint`` of them: fresh
  processes, startup included, the median CPU time of five runs each.

Beside them, without a goal, the CPU time of the lint and the build behind the two
slowest figures, measured in this process: on a machine busy with other work the
latencies are several times their CPU time, and the difference is the wait for a core.
"""

from __future__ import annotations

import asyncio
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from speed import _cpu_seconds, figure, say

ROOT = Path(__file__).resolve().parent.parent


ARRIVED: list[asyncio.Event] = []


def _p95(xs: list[float]) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(0.95 * (len(xs) - 1))))]


def long_file() -> str:
    """A 200-line sequence: a header, settings and gazes between pauses."""
    lines = ["behaviour scan : curious", "robot panda", "sequence {"]
    for i in range(98):
        lines += [f"  gaze horizontal {10 if i % 2 else -10}deg v=20", "  pause 0.3s"]
    return "\n".join([*lines, "}"]) + "\n"


async def _session(options: dict):
    from lsprotocol import types
    from pygls.lsp.client import LanguageClient

    client = LanguageClient("bench", "1")
    published: list = []
    arrived = asyncio.Event()

    @client.feature(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def _on(params):
        published.append((time.perf_counter(), params))
        arrived.set()

    ARRIVED[:] = [arrived]

    await client.start_io(sys.executable, "-m", "aou_dsl", "server")

    async def drain():
        while await client._server.stderr.read(65536):
            pass
    drainer = asyncio.create_task(drain())
    await client.initialize_async(types.InitializeParams(
        capabilities=types.ClientCapabilities(), root_uri=ROOT.as_uri(),
        initialization_options=options))
    client.initialized(types.InitializedParams())
    return client, published, drainer


async def _wait(published: list, uri: str, since: int, version: int | None = None,
                timeout: float = 60.0) -> float:
    """When the first publication for ``uri`` (of ``version``) after ``since`` arrived."""
    end = time.perf_counter() + timeout
    while time.perf_counter() < end:
        for t, p in published[since:]:
            if p.uri == uri and (version is None or p.version == version):
                return t
        ARRIVED[0].clear()
        try:
            await asyncio.wait_for(ARRIVED[0].wait(), max(0.001, end - time.perf_counter()))
        except TimeoutError:
            break
    raise TimeoutError(uri)


async def _settle(pid: int, timeout: float = 300.0) -> None:
    """Wait until the server has done what it started (the compile an open starts, its
    checks, the compiled episodes' figures): its CPU time stops growing."""
    end = time.perf_counter() + timeout
    (last,) = _cpu_seconds([pid])
    while time.perf_counter() < end:
        await asyncio.sleep(0.5)
        (now,) = _cpu_seconds([pid])
        if now - last < 0.02:
            return
        last = now


async def _close(client, drainer) -> None:
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    drainer.cancel()


async def _typing() -> tuple[list[float], list[float], list[float], float]:
    from lsprotocol import types

    client, published, drainer = await _session({"compileOnType": False})
    uri = (ROOT / "bench-long.aou").as_uri()
    text = long_file()
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=1, text=text)))
    await _wait(published, uri, 0, 1)
    await _wait(published, uri, 1, 1, timeout=300)  # the compile an open starts
    pid = client._server.pid
    await _settle(pid)
    edits = []
    (cpu0,) = _cpu_seconds([pid])
    digits: dict[int, str] = {}
    for v in range(2, 82):
        line = 4 + 2 * (v % 90)  # a pause line: 0.3s <-> 0.4s, each edit a change
        new = digits[line] = "3" if digits.get(line, "3") == "4" else "4"
        n = len(published)
        t = time.perf_counter()
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(version=v, uri=uri),
            [types.TextDocumentContentChangePartial(
                range=types.Range(types.Position(line, 10), types.Position(line, 11)),
                text=new)]))
        edits.append(await _wait(published, uri, n, v) - t)
    (cpu1,) = _cpu_seconds([pid])
    hovers, completions = [], []
    doc = types.TextDocumentIdentifier(uri)
    for i in range(80):
        pos = types.Position(3 + i, [3, 8, 20, 26][i % 4])
        t = time.perf_counter()
        await client.text_document_hover_async(types.HoverParams(doc, pos))
        hovers.append(time.perf_counter() - t)
        t = time.perf_counter()
        await client.text_document_completion_async(types.CompletionParams(doc, pos))
        completions.append(time.perf_counter() - t)
    await _close(client, drainer)
    return edits, hovers, completions, (cpu1 - cpu0) / 80


async def _saves(n: int = 15) -> list[float]:
    from lsprotocol import types

    client, published, drainer = await _session({"compileOnType": False})
    path = ROOT / "behaviours" / "hesitant.aou"
    uri = path.as_uri()
    client.text_document_did_open(types.DidOpenTextDocumentParams(
        types.TextDocumentItem(uri=uri, language_id="aou", version=1, text=path.read_text())))
    await _wait(published, uri, 0, 1)  # lint
    await _wait(published, uri, 1, 1, timeout=300)  # the first, cold compile
    await _settle(client._server.pid)
    out = []
    text = path.read_text()
    for v in range(2, n + 2):  # an edit (a comment), then a save: a real compile
        k = len(published)
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(version=v, uri=uri),
            [types.TextDocumentContentChangeWholeDocument(text=text + f"# edit {v}\n")]))
        await _wait(published, uri, k, v)  # lint's diagnostics of the edit
        k = len(published)
        t = time.perf_counter()
        client.text_document_did_save(types.DidSaveTextDocumentParams(
            types.TextDocumentIdentifier(uri)))
        out.append(await _wait(published, uri, k, v, timeout=120) - t)
        await _settle(client._server.pid)  # the checks, the episodes' figures
    await _close(client, drainer)
    return out


def _cli(*args: str) -> float:
    """The CPU time (user + system) of one ``aouc`` process: unlike the wall time, it
    does not grow with the other work on the machine."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-m", "aou_dsl", *args], cwd=ROOT, capture_output=True,
                   check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _in_process() -> tuple[float, float]:
    """The CPU time [s] (median) of the work behind the two slow figures, done in this
    process: lint of an edit of the 200-line file, and the warm compile of hesitant. On a busy
    machine the latencies above are several times these; on an idle one, close."""
    from aou_dsl.editor import lsp_engine as engine

    text = long_file()
    src = (ROOT / "behaviours" / "hesitant.aou").read_text()
    engine.build(src, "hesitant.aou")

    def cpu(fn) -> float:
        t = time.process_time()
        fn()
        return time.process_time() - t
    engine.lint(text, "long.aou")
    # each an edit, as the typing above makes them (an unchanged text is not linted again)
    lint = statistics.median(cpu(lambda i=i: engine.lint(text + f"# edit {i}\n", "long.aou"))
                             for i in range(15))
    build = statistics.median(cpu(lambda i=i: engine.compile_only(src + f"# {i}\n", "h.aou"))
                              for i in range(7))
    return lint, build


def bench_editor() -> None:
    try:
        import pygls  # noqa: F401
    except ImportError:
        say("editor: skipped (the lsp extra is not installed: pip install '.[lsp]')")
        return
    say("editor: aouc server on stdio, as an editor starts it; aouc fmt against aouc lint")
    say(f"  load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    edits, hovers, completions, per_edit = asyncio.run(_typing())
    figure("editor_diagnostics_p95_ms", "diagnostics after an edit of a 200-line file, p95",
           _p95(edits) * 1e3, "ms", kind="warm", at_most=30.0)
    figure("editor_edit_cpu_ms", "(the server's CPU time per edit, mean)", per_edit * 1e3,
           "ms", kind="warm")
    figure("editor_hover_p95_ms", "hover, p95", _p95(hovers) * 1e3, "ms", kind="cached",
           at_most=10.0)
    figure("editor_completion_p95_ms", "completion, p95", _p95(completions) * 1e3, "ms",
           kind="cached", at_most=10.0)
    saves = asyncio.run(_saves())
    figure("editor_compile_p95_ms", "compile diagnostics after a save (hesitant, panda, "
           "a comment edited), p95", _p95(saves) * 1e3, "ms", kind="cached", at_most=250.0,
           fmt="{:.0f}")
    lint_cpu, build_cpu = _in_process()
    figure("editor_lint200_cpu_ms", "(the lint of the 200-line file: CPU time)",
           lint_cpu * 1e3, "ms", kind="warm")
    figure("editor_build_cpu_ms", "(the compile behind the compile diagnostics: CPU time)",
           build_cpu * 1e3, "ms", kind="cached", fmt="{:.0f}")
    files = [str(p) for p in sorted((ROOT / "behaviours").glob("*.aou"))]
    fmt = statistics.median(_cli("fmt", "--check", *files) for _ in range(5))
    lint = statistics.median(_cli("lint", *files) for _ in range(5))
    say(f"  [cold] aouc fmt --check: {fmt:.2f} s, aouc lint: {lint:.2f} s of CPU (the shipped "
        "behaviours, startup included)")
    figure("editor_fmt_vs_lint", "`aouc fmt` of the shipped behaviours / `aouc lint` of them",
           fmt / lint, "x", kind=None, at_most=1.5, fmt="{:.2f}")
