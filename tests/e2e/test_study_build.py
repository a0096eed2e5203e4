"""``aouc study build`` and ``aouc study serve`` without a browser: the files a build
writes (the manifest against its schema, the JATOS archive against JATOS's format), the
cache that redraws only what changed and never trusts a video whose bytes changed, the
refusals, and the server's rules (its own Host only, bounded bodies, one submission per
participant, the store answers.py reads)."""

from __future__ import annotations

import base64
import hashlib
import http.client
import json
import os
import re
import shutil
import sqlite3
import threading
import zipfile
from pathlib import Path

import jsonschema
import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.study.answers import read_answers
from aou_dsl.study.build import build_study, manifest_path
from aou_dsl.study.jspsych import FILES, PACKAGES
from aou_dsl.study.serve import MAX_BODY, StudyServer
from aou_dsl.study.spec import read_study

ROOT = str(Path(__file__).resolve().parents[2])

#: Names that must appear nowhere a participant can load.
BEHAVIOURS = {"zeta.aou": ("zephyr_walk", "confident",
                           "approach a=0.3\npause 0.3s\n"),
              "omega.aou": ("quill_drift", "hesitant",
                            "approach a=0.3\npause 0.2s x2\nretreat 0.03m a=0.5\n")}

STUDY = """[study]
title = "How does it move?"
robot = "panda"
seed = 7
[render]
width = 64
height = 48
fps = 4
[texts]
consent = "You are asked to watch videos."
instructions_a = "Watch the videos."
instructions_b = "Compare two videos."
demographics = ["Age"]
end = "Thank you."
[part_a]
behaviours = ["b/zeta.aou", "b/omega.aou"]
[part_b]
pairs = [{ behaviour = "b/omega.aou", descriptor = "pause_duration", low = 0.2, high = 0.5 }]
[[attention.checks]]
question = "Choose the colour of the sky."
options = ["red", "blue"]
answer = "blue"
[completion]
code = "XK42QZ"
"""


def write_study(folder: str) -> str:
    os.makedirs(os.path.join(folder, "b"), exist_ok=True)
    for name, (behaviour, state, body) in BEHAVIOURS.items():
        with open(os.path.join(folder, "b", name), "w") as fh:
            fh.write(f"behaviour {behaviour} : {state}\n\n{body}")
    path = os.path.join(folder, "study.toml")
    with open(path, "w") as fh:
        fh.write(STUDY)
    return path

QUIET = {"log": lambda m: None}


def sha(path) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


@pytest.fixture(scope="module")
def original(tmp_path_factory):
    """The browser tests' tiny study, built once (CDN jsPsych, with a JATOS archive)."""
    folder = str(tmp_path_factory.mktemp("built"))
    path = write_study(folder)
    got = build_study(read_study(path), os.path.join(folder, "site"), jatos=True, **QUIET)
    # B1's low variant has its base's pause: the same motion as A2, one video for both.
    assert got == {"videos": 3, "drawn": 3, "reused": 0}
    return folder


@pytest.fixture
def copy(original, tmp_path):
    """A copy of the built study to change."""
    folder = str(tmp_path / "copy")
    shutil.copytree(original, folder)
    return folder


def test_the_manifest_traces_every_stimulus(original):
    site = os.path.join(original, "site")
    assert manifest_path(site) == os.path.join(original, "site.manifest.json")
    doc = json.loads(open(manifest_path(site)).read())
    schema = json.loads(open(os.path.join(ROOT, "aou_dsl/schemas/study-manifest.schema.json"))
                        .read())
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.Draft202012Validator(schema).validate(doc)
    assert [(s["item"], s["role"]) for s in doc["stimuli"]] == [
        ("A1", "A"), ("A2", "A"), ("B1", "low"), ("B1", "high")]
    assert doc["study_sha256"] == sha(os.path.join(original, "study.toml"))
    import example_robot_data as erd

    from aou_dsl.core.robot_specs import ROBOTS

    sub = ROBOTS["panda"].urdf
    assert doc["robot_sha256"] == sha(os.path.join(erd.getModelPath(sub), sub))
    for s in doc["stimuli"]:
        video = os.path.join(site, s["video"])
        assert sha(video) == s["video_sha256"] == s["video"][len("stimuli/"):-4]
        on_disk = os.path.join(original, s["behaviour"])
        assert s["behaviour_sha256"] == sha(on_disk)
        if s["role"] == "A":  # Part A compiles the file itself
            assert s["aou_sha256"] == s["behaviour_sha256"]
        else:  # a variant: the file with one value changed, which the hash is of
            assert s["aou_sha256"] != s["behaviour_sha256"]
            assert (s["descriptor"], s["value"]) == ("pause_duration",
                                                      0.2 if s["role"] == "low" else 0.5)
    # An invalid manifest is refused by the schema (the check can fail).
    bad = dict(doc, stimuli=[dict(doc["stimuli"][0], video="stimuli/zeta.mp4")])
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.Draft202012Validator(schema).validate(bad)


def test_the_page_loads_pinned_jsPsych_with_integrity(original):
    html = open(os.path.join(original, "site", "index.html")).read()
    tags = re.findall(r'(?:src|href)="(https://[^"]+)" integrity="([^"]+)" '
                      r'crossorigin="anonymous"', html)
    assert len(tags) == len(FILES) == 4
    for (url, integrity), (pkg, path, pinned) in zip(tags, FILES, strict=True):
        assert url == f"https://cdn.jsdelivr.net/npm/{pkg}@{PACKAGES[pkg]}/{path}"
        assert integrity == pinned and re.fullmatch(r"sha384-[A-Za-z0-9+/]{64}", integrity)
        assert len(base64.b64decode(integrity[7:])) == 48
    assert PACKAGES["jspsych"].startswith("8.")
    assert html.index("experiment.js") > max(html.index(u) for u, _ in tags)


def test_the_jatos_archive_is_a_study_jatos_imports(original):
    """JATOS imports a zip holding one ``.jas`` file (JSON: ``version`` and the study's
    ``data``: ``uuid``, ``title``, ``dirName``, ``componentList`` of components with an
    ``htmlFilePath`` inside the study's folder) and the study's folder ``dirName``."""
    with zipfile.ZipFile(os.path.join(original, "site.jzip")) as z:
        names = z.namelist()
        jas = [n for n in names if n.endswith(".jas")]
        assert jas == ["study.jas"]
        doc = json.loads(z.read("study.jas"))
        index = z.read("site/index.html").decode()
    assert doc["version"] == "3"
    data = doc["data"]
    assert re.fullmatch(r"[0-9a-f-]{36}", data["uuid"]) and data["title"]
    assert data["dirName"] == "site"
    assert all(n == "study.jas" or n.startswith("site/") for n in names)
    for c in data["componentList"]:
        assert re.fullmatch(r"[0-9a-f-]{36}", c["uuid"])
        assert f"site/{c['htmlFilePath']}" in names and c["active"] is True
    assert '<script src="jatos.js"></script>' in index
    assert not any("manifest" in n or "cache" in n or "sqlite" in n for n in names)
    site = os.listdir(os.path.join(original, "site", "stimuli"))
    assert sorted(n[len("site/stimuli/"):] for n in names if "/stimuli/" in n) == sorted(site)


def test_a_rebuild_draws_only_what_changed(copy):
    study = os.path.join(copy, "study.toml")
    site = os.path.join(copy, "site")
    before = json.loads(open(manifest_path(site)).read())
    assert build_study(read_study(study), site, **QUIET)["drawn"] == 0
    zeta = os.path.join(copy, "b", "zeta.aou")
    text = open(zeta).read()
    with open(zeta, "w") as fh:  # a comment changes the text, not the motion
        fh.write(text.replace("\n\n", "\n# still A1\n\n", 1))
    assert build_study(read_study(study), site, **QUIET)["drawn"] == 0
    with open(zeta, "w") as fh:  # A1's motion changes; omega's videos do not
        fh.write(text.replace("pause 0.3s", "pause 0.6s"))
    got = build_study(read_study(study), site, **QUIET)
    assert (got["drawn"], got["reused"]) == (1, 2)
    after = json.loads(open(manifest_path(site)).read())
    changed = [a["item"] for a, b in zip(before["stimuli"], after["stimuli"], strict=True)
               if a["video_sha256"] != b["video_sha256"]]
    assert changed == ["A1"]
    # The old A1 video is gone: the folder holds only what the study shows.
    assert sorted(os.listdir(os.path.join(site, "stimuli"))) == sorted(
        {s["video"][len("stimuli/"):] for s in after["stimuli"]})


def test_the_cache_never_trusts_a_changed_video(copy):
    study = os.path.join(copy, "study.toml")
    site = os.path.join(copy, "site")
    doc = json.loads(open(manifest_path(site)).read())
    victim = os.path.join(site, doc["stimuli"][0]["video"])
    with open(victim, "r+b") as fh:  # same name, other bytes
        fh.seek(100)
        fh.write(b"\0" * 16)
    got = build_study(read_study(study), site, **QUIET)
    assert got["drawn"] == 1
    assert sha(victim) == doc["stimuli"][0]["video_sha256"]  # drawn again, the same video
    # A render setting is part of each video's key: every video is drawn again.
    text = open(study).read().replace("fps = 4", "fps = 3")
    with open(study, "w") as fh:
        fh.write(text)
    got = build_study(read_study(study), site, **QUIET)
    assert got["reused"] == 0 and got["drawn"] == got["videos"] == 3


def test_a_build_refuses_what_it_must_not_write_or_read(copy, tmp_path):
    from aou_dsl.study.jspsych import copy_local

    study = read_study(os.path.join(copy, "study.toml"))
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(AouError) as err:
        build_study(study, str(other), **QUIET)
    assert err.value.diagnostics[0].code == "I502"
    with pytest.raises(AouError) as err:  # the study's own folder holds its inputs
        build_study(study, copy, **QUIET)
    assert err.value.diagnostics[0].code == "I502"
    with pytest.raises(AouError) as err:  # no jsPsych in the folder given
        copy_local(str(tmp_path), str(tmp_path / "x"))
    assert err.value.diagnostics[0].code == "I501"
    fake = tmp_path / "nm" / "node_modules"
    for pkg, path, _ in FILES:  # the right files, other contents
        f = fake.joinpath(*pkg.split("/"), *path.split("/"))
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("/* not jsPsych */")
    with pytest.raises(AouError) as err:
        copy_local(str(fake), str(tmp_path / "x"))
    assert "hash differs" in err.value.diagnostics[0].message
    assert not (tmp_path / "x").exists()


def test_the_study_names_nothing_in_its_files(original):
    """The build folder's names: hashes and fixed names only."""
    site = os.path.join(original, "site")
    for _root, dirs, files in os.walk(site):
        for n in dirs + files:
            assert not any(k in n for k in ("zeta", "omega", "zephyr", "quill")), n
    names = os.listdir(os.path.join(site, "stimuli"))
    assert names and all(re.fullmatch(r"[0-9a-f]{64}\.mp4", n) for n in names)
    assert sorted(BEHAVIOURS) == ["omega.aou", "zeta.aou"]


# --- the server ----------------------------------------------------------------------


@pytest.fixture
def server(copy):
    srv = StudyServer(os.path.join(copy, "site"), port=0)
    t = threading.Thread(target=srv.serve_forever, daemon=True)
    t.start()
    yield srv
    srv.shutdown()
    srv.server_close()


def _request(srv, method, path, body=None, host=None, headers=None, token=True):
    """A request as the study's page sends it: its own Host and, unless ``token`` is
    False, the cookie that carries the study's token."""
    c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=10)
    cookie = {"Cookie": f"{srv.gate.cookie(srv.port)}={srv.gate.token}"} if token else {}
    h = {"Host": host or f"127.0.0.1:{srv.port}", **cookie, **(headers or {})}
    c.request(method, path, body=body, headers=h)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data


def test_the_server_answers_only_to_its_own_address(server):
    assert _request(server, "GET", "/")[0] == 200
    assert _request(server, "GET", "/", host=f"localhost:{server.port}")[0] == 200
    for host in ("evil.example", f"evil.example:{server.port}", "127.0.0.1:1"):
        assert _request(server, "GET", "/", host=host)[0] == 403, host
        assert _request(server, "POST", "/submit", b"{}", host=host)[0] == 403, host
    for path in ("/answers.sqlite", "/.aou-cache.json", "/../site.manifest.json",
                 "/stimuli/../timeline.json", "/experiment.js/", "/stimuli/x.mp4"):
        assert _request(server, "GET", path)[0] == 404, path


def test_the_server_answers_only_its_own_page_with_the_studys_token(server, copy):
    """No token, a wrong one, or a page of another site posting answers: 403, nothing
    stored. The address the command prints brings the token and sets the cookie the
    page's own requests carry; a server started again on the folder keeps the token."""
    body = json.dumps({"participant": "x1", "data": []}).encode()
    assert _request(server, "GET", "/", token=False)[0] == 403
    assert _request(server, "GET", "/", token=False,
                    headers={"Cookie": f"{server.gate.cookie(server.port)}=guess"})[0] == 403
    assert _request(server, "POST", "/submit", body, token=False)[0] == 403
    assert _request(server, "POST", "/submit", body,
                    headers={"Origin": "http://evil.example"})[0] == 403
    c = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    c.request("GET", "/" + server.url.split("/", 3)[3])  # /?token=..., as printed
    r = c.getresponse()
    r.read()
    c.close()
    assert r.status == 200 and f"={server.gate.token};" in r.getheader("Set-Cookie", "")
    assert server.url.startswith(f"http://127.0.0.1:{server.port}/?token=")
    token_file = os.path.join(copy, "site", ".aou-serve-token")
    assert oct(os.stat(token_file).st_mode & 0o777) == "0o600"
    again = StudyServer(os.path.join(copy, "site"), port=0)
    try:
        assert again.gate.token == server.gate.token
    finally:
        again.server_close()
    db = sqlite3.connect(os.path.join(copy, "site", "answers.sqlite"))
    try:
        assert db.execute("select count(*) from submissions").fetchone()[0] == 0
    finally:
        db.close()


def test_the_server_stores_each_participant_once(server, copy):
    study = read_study(os.path.join(copy, "study.toml"))
    rows = [{"participant": "p1", "aou_part": "A", "aou_item": "A1", "state": "curious",
             "intensity": 3, "order": 1},
            {"participant": "p1", "aou_part": "end", "aou_item": ""}]
    body = json.dumps({"participant": "p1", "data": rows}).encode()
    assert _request(server, "POST", "/submit", body)[0] == 201
    assert _request(server, "POST", "/submit", body)[0] == 409
    assert _request(server, "POST", "/submit", b"{not json")[0] == 400
    assert _request(server, "POST", "/submit", b'{"participant": "", "data": []}')[0] == 400
    status, _ = _request(server, "POST", "/submit", b"x", headers={
        "Content-Length": str(MAX_BODY + 1)})
    assert status == 413
    store = os.path.join(copy, "site", "answers.sqlite")
    db = sqlite3.connect(store)
    assert db.execute("pragma journal_mode").fetchone()[0] == "wal"
    cols = [r[1] for r in db.execute("pragma table_info(submissions)")]
    assert cols == ["seq", "participant", "received", "data"]
    assert db.execute("select count(*) from submissions").fetchone()[0] == 1
    db.close()
    got = read_answers([store], study)
    assert [(r.participant, r.part, r.item, r.state) for r in got] == [
        ("p1", "A", "A1", "curious"), ("p1", "end", "", None)]


@pytest.mark.parametrize("check", [
    'question = "Sky?"\noptions = ["red", "blue"]\nanswer = "green"',
    'question = "Sky?"\noptions = ["blue"]\nanswer = "blue"',
    'question = "Sky?"\noptions = ["red", "blue"]',
])
def test_a_bad_attention_check_is_E701(tmp_path, check):
    path = write_study(str(tmp_path))
    text = open(path).read()
    start = text.index("[[attention.checks]]")
    end = text.index("[completion]")
    with open(path, "w") as fh:
        fh.write(text[:start] + "[[attention.checks]]\n" + check + "\n" + text[end:])
    with pytest.raises(AouError) as err:
        read_study(path)
    assert err.value.diagnostics[0].code == "E701"
    assert "attention" in err.value.diagnostics[0].message


def test_the_papers_design_makes_every_pair(tmp_path):
    """Every pair of `aouc study init`'s design has its two variants (the tilts and the
    vertical gaze the paper varied are added to a copy of their base first)."""
    from aou_dsl.lang.linter import lint_source
    from aou_dsl.study.build import plan_stimuli
    from aou_dsl.study.init import PAIRS, init_study

    init_study(str(tmp_path))
    study = read_study(str(tmp_path / "study.toml"))
    stims = plan_stimuli(study)
    assert len(stims) == 4 + 2 * len(PAIRS) == 44
    for s in stims:
        assert lint_source(s.text, s.path).ok, (s.item, s.role)
    for p, (base, d, lo, hi) in zip(study.pairs, PAIRS, strict=True):
        assert p.state == base and p.descriptor == d
        low, high = (s for s in stims if s.item == p.id)
        assert (low.value, high.value) == (lo, hi) and low.text != high.text


def test_a_build_stopped_early_resumes_where_it_stopped(copy):
    """The cache is written as each video is drawn, and a folder a stopped build left is
    one a build may write into: a second build draws only what the first did not."""
    study = os.path.join(copy, "study.toml")
    site = os.path.join(copy, "site")
    shutil.rmtree(site)
    os.remove(manifest_path(site))

    def stop(msg: str) -> None:
        if "[2/" in msg:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        build_study(read_study(study), site, log=stop)
    assert not os.path.exists(os.path.join(site, "timeline.json"))
    got = build_study(read_study(study), site, **QUIET)
    assert (got["drawn"], got["reused"]) == (1, 2)


def test_the_command_line_builds_and_refuses(copy, tmp_path):
    """``aouc study build`` over a built study draws nothing and says so; ``serve`` on a
    folder that is not a built study, and a build whose pair cannot be made, are coded
    errors, not tracebacks."""
    import subprocess
    import sys

    aouc = [sys.executable, "-m", "aou_dsl"]
    env = dict(os.environ, PYTHONPATH=ROOT)
    study = os.path.join(copy, "study.toml")
    site = os.path.join(copy, "site")
    got = subprocess.run([*aouc, "study", "build", study, "-o", site, "--jobs", "2"],
                         capture_output=True, text=True, env=env, timeout=300)
    assert got.returncode == 0, got.stderr
    assert "3 videos (0 drawn, 3 up to date)" in got.stderr
    assert "site.manifest.json" in got.stderr
    got = subprocess.run([*aouc, "study", "serve", str(tmp_path)], capture_output=True,
                         text=True, env=env, timeout=60)
    assert got.returncode == 2 and "I501" in got.stderr and "Traceback" not in got.stderr
    text = open(study).read().replace("low = 0.2", "low = 0.1")  # a pause too short
    with open(study, "w") as fh:
        fh.write(text)
    got = subprocess.run([*aouc, "study", "build", study, "-o", site], capture_output=True,
                         text=True, env=env, timeout=300)
    assert got.returncode in (1, 2) and "E702" in got.stderr and "pair B1" in got.stderr
    assert "Traceback" not in got.stderr
