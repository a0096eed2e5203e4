"""A built study taken in a real browser, through ``aouc study serve``.

Headless Chromium (Debian's, as the studio's browser tests use) driven by Playwright
takes a tiny study (two behaviours, one pair, one attention check, videos of 64x48 at a
few frames a second) as simulated participants would: every page is reached, every
video plays and loops, each participant's order and sides come from their own seed and
are recorded, each participant's answers arrive in the server's SQLite store, and a
server killed and restarted in the middle loses none of them. jsPsych is installed from
the npm registry into a temporary folder (``npm install``) and copied into the study
with ``--jspsych``, so the page needs no network. Skipped when Chromium, Playwright or
npm is missing.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("playwright", reason="playwright is missing: pip install '.[test]'")

from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.study.build import build_study
from aou_dsl.study.jspsych import PACKAGES
from aou_dsl.study.spec import read_study
from tests.e2e.conftest import find_chromium
from tests.e2e.test_study_build import BEHAVIOURS, write_study

ROOT = str(Path(__file__).resolve().parents[2])
CHROMIUM = find_chromium()
if CHROMIUM is None:
    pytest.skip("no Chromium found for the study's browser tests: install Debian's "
                "(apt-get install -y chromium), or set AOU_CHROMIUM to a Chromium binary",
                allow_module_level=True)
if shutil.which("npm") is None:
    pytest.skip("npm is missing (apt-get install -y npm): the study's tests install jsPsych "
                "with it", allow_module_level=True)

#: ``aouc`` run by this Python, on this worktree's code.
AOUC = [sys.executable, "-m", "aou_dsl"]
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--autoplay-policy=no-user-gesture-required"]

@pytest.fixture(scope="module")
def node_modules(tmp_path_factory):
    """jsPsych and the plugins the page needs, from the npm registry."""
    folder = os.environ.get("AOU_JSPSYCH") or str(tmp_path_factory.mktemp("npm"))
    if not os.path.isdir(os.path.join(folder, "node_modules", "jspsych")):
        with open(os.path.join(folder, "package.json"), "w") as fh:
            fh.write('{"private": true}\n')
        got = subprocess.run(["npm", "install", "--no-audit", "--no-fund", "--silent",
                              *(f"{k}@{v}" for k, v in PACKAGES.items())], cwd=folder,
                             capture_output=True, text=True, timeout=300)
        if got.returncode != 0:
            pytest.skip(f"npm install failed (no registry?): {got.stderr[-300:]}")
    return os.path.join(folder, "node_modules")


@pytest.fixture(scope="module")
def built(tmp_path_factory, node_modules):
    """The tiny study built with a local jsPsych: (study file, site folder)."""
    folder = str(tmp_path_factory.mktemp("study"))
    path = write_study(folder)
    site = os.path.join(folder, "site")
    build_study(read_study(path), site, jobs=1, jspsych=node_modules, log=lambda m: None)
    return path, site


class Server:
    """``aouc study serve`` in a process of its own, killable."""

    def __init__(self, site: str, port: int = 0):
        env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
        self.proc = subprocess.Popen(
            [*AOUC, "study", "serve", site, "--port", str(port)],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
        line = self.proc.stdout.readline()  # type: ignore[union-attr]
        m = re.search(r"http://127\.0\.0\.1:(\d+)/\?token=([A-Za-z0-9_-]+)", line)
        assert m, f"the server printed no address with its token: {line!r}"
        self.port = int(m.group(1))
        self.url = m.group(0)  # as printed: the address with the study's token
        self.base = f"http://127.0.0.1:{self.port}/"
        self.token = m.group(2)

    def at(self, rel: str) -> str:
        """``rel`` on this server, with the token in its query."""
        return f"{self.base}{rel}{'&' if '?' in rel else '?'}token={self.token}"

    def kill(self) -> None:
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(10)


def stored(site: str) -> dict[str, list]:
    db = sqlite3.connect(os.path.join(site, "answers.sqlite"))
    try:
        return {p: json.loads(d) for p, d in
                db.execute("select participant, data from submissions order by seq")}
    finally:
        db.close()


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS, headless=True)
        yield b
        b.close()


def _playing(page) -> None:
    """Every video on the page plays: its time advances from where it was."""
    page.wait_for_function("""() => {
        const vs = [...document.querySelectorAll('video')];
        return vs.length > 0 && vs.every(v => v.readyState >= 2 && v.currentTime > 0
                                          && !v.paused && v.loop && v.muted
                                          && v.hasAttribute('playsinline'));
    }""", timeout=15_000)


def _loops(page) -> None:
    """Every video on the page wraps: its time goes back after it reached its end."""
    page.evaluate("""() => { for (const v of document.querySelectorAll('video')) {
        v.playbackRate = 4; v._aouMax = 0; v._aouWrapped = false;
        v.addEventListener('timeupdate', () => {
            if (v.currentTime + 0.05 < v._aouMax) v._aouWrapped = true;
            v._aouMax = Math.max(v._aouMax, v.currentTime); });
    } }""")
    page.wait_for_function("() => [...document.querySelectorAll('video')].every("
                           "v => v._aouWrapped && v._aouMax > 0.5 * v.duration)",
                           timeout=30_000)


def take(browser, url: str, pid: str, *, loops: bool = False, play: bool = True,
         until: str | None = None, page=None):
    """Participant ``pid`` takes the study at ``url``; the pages seen, and the page
    (left open at its end page, or at the first page of kind ``until``)."""
    if page is None:
        ctx = browser.new_context()
        page = ctx.new_page()
        page.goto(f"{url}{'&' if '?' in url else '?'}PROLIFIC_PID={pid}&STUDY_ID=S1"
                  f"&SESSION_ID=X{pid}")
    seen = []
    while True:
        page.wait_for_selector("#jspsych-html-button-response-stimulus, "
                               "#jspsych-survey-html-form, #aou-end", timeout=15_000)
        if page.query_selector("#aou-end"):
            seen.append("end")
            assert page.inner_text("#aou-code") == "XK42QZ"  # the completion code
            return seen, page
        text = page.inner_text(".jspsych-content")
        if page.query_selector("textarea[name=description]"):
            kind = "A"
        elif page.query_selector("input[name=d0]"):
            kind = "demographics"
        elif "Choose the colour" in text:
            kind = "attention"
        elif page.query_selector("video"):
            kind = "B"
        elif "You are asked" in text:
            kind = "consent"
        else:
            kind = "instructions"
        if kind == until:
            return seen, page
        seen.append(kind)
        if kind in ("A", "B") and play:
            _playing(page)
            if loops:
                _loops(page)
        marker = page.evaluate("() => document.querySelector('.jspsych-content').innerHTML")
        if kind == "A":
            page.fill("textarea[name=description]", f"it moves, says {pid}")
            page.check("input[name=state][value=hesitant]")
            page.check("input[name=intensity][value='4']")
            page.click("#jspsych-survey-html-form-next")
        elif kind == "demographics":
            page.fill("input[name=d0]", "40")
            page.click("#jspsych-survey-html-form-next")
        else:
            label = {"consent": "I agree", "instructions": "Continue", "attention": "blue",
                     "B": "Right"}[kind]
            page.get_by_role("button", name=label, exact=True).click()
        page.wait_for_function("m => { const c = document.querySelector('.jspsych-content');"
                               " return !c || c.innerHTML !== m; }", arg=marker)


def _finish(page) -> str:
    page.wait_for_function("() => /received/.test("
                           "(document.getElementById('aou-status') || {}).textContent || '')",
                           timeout=30_000)
    return page.inner_text("#aou-status")


def _check_rows(rows: list, pid: str) -> None:
    mine = [r for r in rows if r.get("aou_part")]
    assert {r["participant"] for r in rows} == {pid}
    parts = sorted(r["aou_part"] for r in mine)
    assert parts == ["A", "A", "B", "attention", "end"], parts
    assert sorted(r["order"] for r in mine if r["aou_part"] != "end") == [1, 2, 3, 4]
    end = next(r for r in mine if r["aou_part"] == "end")
    assert sorted(end["aou_order"]) == ["A1", "A2", "B1", "C1"]
    assert rows[0]["PROLIFIC_PID"] == pid and rows[0]["SESSION_ID"] == f"X{pid}"
    b = next(r for r in mine if r["aou_part"] == "B")
    assert b["left"] in ("low", "high")
    # "Right" was clicked: the variant on the right, recoded.
    assert b["answer"] == ("high" if b["left"] == "low" else "low")
    assert end["aou_sides"] == {"B1": b["left"]}
    assert all(r["state"] == "hesitant" and r["intensity"] == 4
               for r in mine if r["aou_part"] == "A")
    assert next(r for r in mine if r["aou_part"] == "attention")["passed"] is True


#: Participants taking the study at once (each group in a thread, with its own browser).
GROUPS = 3


def _crowd(url: str, pids: list[str]) -> dict[str, tuple[list, str]]:
    """``pids`` take the study, :data:`GROUPS` at a time; each one's pages and end status.
    The first of them also waits for every video to loop."""
    from concurrent.futures import ThreadPoolExecutor

    from playwright.sync_api import sync_playwright

    def group(mine: list[str]) -> dict:
        out = {}
        with sync_playwright() as pw:
            b = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS, headless=True)
            try:
                for pid in mine:
                    seen, page = take(b, url, pid, loops=pid == pids[0])
                    out[pid] = (seen, _finish(page))
                    page.context.close()
            finally:
                b.close()
        return out

    with ThreadPoolExecutor(GROUPS) as pool:
        done = list(pool.map(group, [pids[i::GROUPS] for i in range(GROUPS)]))
    return {k: v for d in done for k, v in d.items()}


def _run(browser, built, n: int, tmp_path):
    path, site = built
    for suffix in ("", "-wal", "-shm"):
        if os.path.exists(os.path.join(site, "answers.sqlite" + suffix)):
            os.remove(os.path.join(site, "answers.sqlite" + suffix))
    server = Server(site)
    expected = ["consent", "instructions", "A", "A", "instructions"]
    pids = [f"P{i:03d}" for i in range(n)]
    half = n // 2
    try:
        results = _crowd(server.url, pids[:half])
        # The server is killed before this participant's last page: nothing stored is
        # lost, the page keeps the answers and offers them, and sends them once the
        # server is back.
        pid = pids[half]
        seen, page = take(browser, server.url, pid, until="demographics")
        before = stored(site)
        server.kill()
        assert sorted(stored(site)) == sorted(before) == sorted(pids[:half])
        more, page = take(browser, None, pid, page=page)  # type: ignore[arg-type]
        page.wait_for_selector("#aou-download", timeout=15_000)
        offered = page.evaluate("async () => (await fetch(document.querySelector("
                                "'#aou-download').href)).text()")
        assert any(r.get("aou_part") == "end" for r in json.loads(offered))
        server = Server(site, server.port)
        results[pid] = (seen + more, _finish(page))
        page.context.close()
        results.update(_crowd(server.url, pids[half + 1:]))
        # A participant who already submitted is refused, and nothing is stored twice.
        _, page = take(browser, server.url, pids[0])
        assert "already" in _finish(page)
        page.context.close()
    finally:
        server.kill()
    for pid, (seen, status) in results.items():
        assert "received" in status and "already" not in status, (pid, status)
        assert seen[:5] == expected and seen[-2:] == ["demographics", "end"], seen
        assert sorted(seen[5:-2]) == ["B", "attention"], seen
    got = stored(site)
    assert sorted(got) == [f"P{i:03d}" for i in range(n)]
    for pid, rows in got.items():
        _check_rows(rows, pid)
    ends = [next(r for r in rows if r.get("aou_part") == "end") for rows in got.values()]
    orders = {tuple(e["aou_order"]) for e in ends}
    sides = {e["aou_sides"]["B1"] for e in ends}
    seeds = {e["aou_seed"] for e in ends}
    assert len(orders) > 1 and sides == {"low", "high"} and len(seeds) == n
    report = tmp_path / "report"
    done = subprocess.run([*AOUC, "study", "analyze",
                           os.path.join(site, "answers.sqlite"), "--study", path,
                           "-o", str(report)], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=ROOT))
    assert done.returncode == 0, done.stderr
    res = json.loads((report / "results.json").read_text())
    assert res["participants"]["kept"] == n
    a1 = next(e for e in res["part_a"] if e["id"] == "A1")
    assert a1["options"]["hesitant"]["count"] == n


def test_twenty_participants_take_the_study(browser, built, tmp_path):
    _run(browser, built, 20, tmp_path)


@pytest.mark.slow
@pytest.mark.large
def test_fifty_five_participants_take_the_study(browser, built, tmp_path):
    _run(browser, built, 55, tmp_path)


def _served(site: str) -> list[str]:
    from aou_dsl.study.serve import _SERVED

    out = []
    for root, _, files in os.walk(site):
        for f in files:
            rel = os.path.relpath(os.path.join(root, f), site).replace(os.sep, "/")
            if _SERVED.match(rel):
                out.append(rel)
    return out


def _leaks(site: str, served: list[str]) -> list[str]:
    """Every name a participant could read that says which stimulus is which."""
    names = set(REGISTRY) | {b for b, _, _ in BEHAVIOURS.values()} | set(BEHAVIOURS) | \
        {os.path.splitext(n)[0] for n in BEHAVIOURS} | {"study.toml", "manifest"}
    found = []
    for _root, dirs, files in os.walk(site):
        for f in dirs + files:
            found += [f"file name {f}: {n}" for n in names if n in f]
    for rel in served:
        with open(os.path.join(site, rel), "rb") as fh:
            text = fh.read().decode("latin-1")
        found += [f"{rel}: {n}" for n in names if n in text]
    return found


def test_nothing_served_says_which_stimulus_is_which(built, tmp_path):
    import urllib.error
    import urllib.request

    path, site = built
    served = _served(site)
    assert "timeline.json" in served and any(s.startswith("stimuli/") for s in served)
    assert _leaks(site, served) == []
    # The search finds a name where one is (the check can fail).
    copy = str(tmp_path / "copy")
    shutil.copytree(site, copy)
    with open(os.path.join(copy, "timeline.json"), "a") as fh:
        fh.write("quill_drift")
    assert _leaks(copy, _served(copy)) == ["timeline.json: quill_drift"]
    # No stimulus-to-state mapping: Part A's entries hold a blind id and a video; a
    # pair names its base's state (the question asks about it) for both its videos and
    # says which is low only through the parity of an opaque number.
    doc = json.loads(open(os.path.join(site, "timeline.json")).read())
    assert all(set(e) == {"item", "video"} for e in doc["part_a"])
    assert all(set(e) == {"item", "state", "videos", "k"} for e in doc["part_b"])
    text = json.dumps(doc["part_a"]) + json.dumps([e["videos"] for e in doc["part_b"]])
    assert not re.search(r"confident|curious|hesitant|fearful|low|high", text)
    for rel in served:  # videos are named only in the timeline
        if rel != "timeline.json" and not rel.startswith("stimuli/"):
            body = open(os.path.join(site, rel), encoding="utf-8", errors="replace").read()
            assert not re.search(r"[0-9a-f]{64}\.mp4", body), rel
    for rel in [s for s in served if s.startswith("stimuli/")]:
        with open(os.path.join(site, rel), "rb") as fh:
            import hashlib

            assert hashlib.sha256(fh.read()).hexdigest() + ".mp4" == rel.split("/")[1]
    # What is not in the list is not served: the manifest, the cache, the store.
    server = Server(site)
    try:
        for url in ("../site.manifest.json", "%2e%2e/site.manifest.json", ".aou-cache.json",
                    "answers.sqlite", "answers.sqlite-wal", "study.toml"):
            with pytest.raises(urllib.error.HTTPError) as err:
                urllib.request.urlopen(server.at(url), timeout=5)
            assert err.value.code in (400, 404), url
        for rel in served:
            with urllib.request.urlopen(server.at(rel), timeout=5) as r:
                assert r.status == 200
    finally:
        server.kill()
    assert not os.path.abspath(os.path.join(site, "..", "site.manifest.json")).startswith(
        os.path.abspath(site) + os.sep)


def test_the_pinned_hashes_are_the_npm_packages_files(node_modules):
    """The hashes the page's CDN tags carry are those of the files npm installs."""
    import base64
    import hashlib

    from aou_dsl.study.jspsych import FILES

    for pkg, path, pinned in FILES:
        with open(os.path.join(node_modules, *pkg.split("/"), *path.split("/")), "rb") as fh:
            digest = hashlib.sha384(fh.read()).digest()
        assert pinned == "sha384-" + base64.b64encode(digest).decode(), (pkg, path)
        with open(os.path.join(node_modules, *pkg.split("/"), "package.json")) as fh:
            assert json.load(fh)["version"] == PACKAGES[pkg]


#: A stand-in for the ``jatos.js`` a JATOS server serves: it keeps what the study sends.
JATOS_STUB = """window.jatos = {workerId: "77", onLoad: function (f) { setTimeout(f, 0); },
  endStudy: function (data) { window.aouResult = data; },
  endStudyAndRedirect: function (url, data) { window.aouResult = data; }};"""


def test_in_jatos_the_answers_go_to_jatos(browser, built, tmp_path):
    """The JATOS archive's page loads jatos.js and ends the study with the rows as the
    result data, the participant's id JATOS's worker id."""
    import http.server
    import threading
    import zipfile
    from functools import partial

    from aou_dsl.study.build import write_jzip

    path, site = built
    files = [os.path.join(r, f) for r, _, fs in os.walk(os.path.join(site, "jspsych"))
             for f in fs]
    archive = write_jzip(read_study(path), site, files)
    with zipfile.ZipFile(archive) as z:
        z.extractall(tmp_path / "jatos")
    folder = tmp_path / "jatos" / "site"
    (folder / "jatos.js").write_text(JATOS_STUB)
    handler = partial(http.server.SimpleHTTPRequestHandler, directory=str(folder))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        page = browser.new_context().new_page()
        page.goto(f"http://127.0.0.1:{httpd.server_address[1]}/index.html")
        take(browser, None, "jatos", page=page, play=False)  # type: ignore[arg-type]
        page.wait_for_function("() => window.aouResult !== undefined", timeout=15_000)
        rows = json.loads(page.evaluate("() => window.aouResult"))
        page.context.close()
    finally:
        httpd.shutdown()
        httpd.server_close()
    assert {r["participant"] for r in rows} == {"jatos-77"}
    assert sorted(r["aou_part"] for r in rows if r.get("aou_part")) == [
        "A", "A", "B", "attention", "end"]


def test_a_participant_who_declines_sends_nothing(browser, built):
    path, site = built
    server = Server(site)
    try:
        page = browser.new_context().new_page()
        page.goto(server.at("?PROLIFIC_PID=NOPE"))
        page.get_by_role("button", name="I do not agree", exact=True).click()
        page.wait_for_function("() => /did not agree/.test(document.body.innerText)")
        page.wait_for_timeout(500)  # a request the page would send has time to arrive
        assert page.query_selector("#aou-end") is None
        page.context.close()
    finally:
        server.kill()
    assert "NOPE" not in stored(site)


def test_the_page_sends_the_participant_back_to_the_platform(browser, built, tmp_path,
                                                              node_modules):
    """With ``[completion] redirect``, the page goes to the platform's completion address
    once the answers are stored (not before)."""
    path, site = built
    folder = tmp_path / "copy"
    shutil.copytree(os.path.dirname(path), folder, ignore=shutil.ignore_patterns("answers*"))
    study = folder / "study.toml"
    back = "https://app.prolific.com/submissions/complete?cc=XK42QZ"
    study.write_text(study.read_text().replace('code = "XK42QZ"', f'redirect = "{back}"'))
    got = build_study(read_study(str(study)), str(folder / "site"), jspsych=node_modules,
                      log=lambda m: None)
    assert got["drawn"] == 0  # the videos are the built study's
    server = Server(str(folder / "site"))
    try:
        ctx = browser.new_context()
        ctx.route("https://app.prolific.com/**",
                  lambda route: route.fulfill(body="<p id=back>completed</p>",
                                              content_type="text/html"))
        page = ctx.new_page()
        page.goto(server.at("?PROLIFIC_PID=R1&STUDY_ID=S1&SESSION_ID=X1"))
        seen, page = take(browser, None, "R1", page=page, play=False, until="demographics")
        assert seen[-1] in ("B", "attention")
        page.fill("input[name=d0]", "40")
        with page.expect_navigation(url=back, timeout=30_000):
            page.click("#jspsych-survey-html-form-next")
        assert page.inner_text("#back") == "completed"
        ctx.close()
    finally:
        server.kill()
    assert "R1" in stored(str(folder / "site"))
