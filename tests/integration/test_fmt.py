"""``aouc fmt``: on every .aou file of the repository, the docs' examples and generated
files: idempotent, comments kept, no change of meaning (same diagnostics, same
timeline, byte-identical compile), and any blanks a person adds come out the same."""

from __future__ import annotations

import os
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.formatter import format_source, tokens
from aou_dsl.lang.linter import lint_source
from tests.langgen import random_cases

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted([*ROOT.glob("behaviours/*.aou"), *ROOT.glob("tests/**/*.aou"),
                *ROOT.glob("examples/**/*.aou")])


def _doc_examples() -> list[tuple[str, str]]:
    """The code blocks of README.md and docs/*.md that are .aou files (they parse and
    hold a statement)."""
    out = []
    for md in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for i, block in enumerate(re.findall(r"```[a-z]*\n(.*?)```", md.read_text(), re.S)):
            if re.search(r"^\s*(approach|pause|retreat|gaze|tilt|shiver|sequence)\b", block,
                         re.M) and "$ " not in block:
                try:
                    format_source(block)
                except AouError:
                    continue
                out.append((f"{md.name}#{i}", block))
    return out


def _generated() -> list[tuple[str, str]]:
    from aou_dsl.synth.synthesis import synthesize

    cases = [(c.stem, c.text) for c in random_cases(150, seed=7)]
    cases += [(f"synth-{s}", synthesize(s, intensity=x, verify=False))
              for s in ("confident", "curious", "hesitant", "fearful", "inactive")
              for x in (0.2, 0.5, 0.9)]
    return cases


SOURCES = [(str(p.relative_to(ROOT)), p.read_text(encoding="utf-8")) for p in FILES]


def _comments(text: str) -> list[str]:
    return [t.rstrip() for k, t in tokens(text.removeprefix("\ufeff")) if k == "comment"]


def _meaning(text: str):
    """What lint makes of a text, its positions left out."""
    r = lint_source(text, "x.aou")
    diags = [(d.code, d.message, d.hint) for d in r.diagnostics]
    episodes = [(e.kind, e.start, e.end, e.duration, e.a, e.vmax, e.amplitude, e.f, e.plane)
                for e in (r.timeline.episodes if r.timeline else ())]
    return diags, episodes, r.cv


def _check(text: str) -> str:
    """The formatted text, checked; ``text`` itself when it has a syntax error."""
    try:
        once = format_source(text)
    except AouError as err:  # a syntax error: the formatter refuses, like the parser
        assert err.diagnostics[0].code.startswith("S")
        return text
    assert format_source(once) == once, "not idempotent"
    assert _comments(once) == _comments(text), "comments lost or changed"
    assert _meaning(once) == _meaning(text), "meaning changed"
    return once


def _messy(text: str, rng: random.Random) -> str:
    """``text`` with blanks a person might add: between tokens and at line ends (tokens
    written glued stay glued)."""
    out = []
    prev = ""
    for kind, tok in tokens(text):
        glued = prev in ("word", "quantity") and kind in ("word", "quantity")
        if kind == "newline":
            out.append(rng.choice(["", " ", "\t "]) + tok)
        elif kind == "blank":
            out.append(rng.choice([" ", "  ", "\t", "   "]))
        else:
            if not glued and prev not in ("blank", "newline", "") and rng.random() < .3 \
                    and kind != "comment":
                out.append(" ")
            out.append(tok)
        prev = kind
    return "".join(out)


@pytest.mark.parametrize(("name", "text"), SOURCES + _doc_examples(), ids=lambda x: x
                         if isinstance(x, str) and len(x) < 80 and "\n" not in x else "")
def test_files_and_doc_examples(name: str, text: str) -> None:
    once = _check(text)
    if once is not text:  # it formats (no syntax error)
        assert format_source(_messy(once, random.Random(name))) == once


def test_generated_files() -> None:
    rng = random.Random(3)
    for name, text in _generated():
        once = _check(text)
        assert format_source(_messy(text, rng)) == once, name


def test_there_is_something_to_format() -> None:
    """The sources above are not all canonical already: the checks see real changes."""
    assert sum(_check(t) != t for _, t in SOURCES) >= 1
    assert len(_doc_examples()) >= 2


def test_layout_rules() -> None:
    text = ("\n\n  behaviour  h:hesitant   # a comment  \n\n\n\n"
            "robot   panda;;goal ( 0.5 ,0,0.3 )\n"
            "sequence{ approach 0.08m a = 0.09 ; pause 1s }\nsequence {\n\tpause 1s   x2\n"
            "  # inside\n}\n\n")
    assert format_source(text) == (
        "behaviour h : hesitant  # a comment\n\nrobot panda; goal (0.5, 0, 0.3)\n"
        "sequence { approach 0.08m a=0.09; pause 1s }\nsequence {\n  pause 1s x2\n"
        "  # inside\n}\n")
    assert format_source("pause 1s\r\nretreat 0.06m  a=0.1\r\n") == \
        "pause 1s\r\nretreat 0.06m a=0.1\r\n"
    assert format_source("pause 1s x1.5\n") == "pause 1s x1.5\n"  # glued: one slip
    assert format_source("") == ""


def _compiled_bytes(text: str) -> bytes:
    from aou_dsl.driver.builder import build_source

    res = build_source(text, "x.aou", check=False)
    assert res.ok, [d.message for d in res.diagnostics]
    tr = res.trajectory
    return tr.t.tobytes() + tr.q.tobytes() + repr(tr.episodes).encode()


@pytest.mark.parametrize("path", sorted(ROOT.glob("behaviours/*.aou")),
                         ids=lambda p: p.name)
def test_byte_identical_compile(path: Path) -> None:
    text = path.read_text()
    messy = _messy(text, random.Random(path.name))
    formatted = format_source(messy)
    assert messy != formatted
    assert _compiled_bytes(formatted) == _compiled_bytes(messy)


def _aouc(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aou_dsl", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_cli_check_diff_write(tmp_path: Path) -> None:
    good = tmp_path / "good.aou"
    good.write_text("pause 1s\n")
    messy = tmp_path / "messy.aou"
    messy.write_text("pause   1s  x2 # two\n")
    messy.chmod(0o640)
    bad = tmp_path / "bad.aou"
    bad.write_text("pause   1,5s\n")
    r = _aouc("fmt", "--check", str(good), str(messy), cwd=tmp_path)
    assert r.returncode == 1 and "messy.aou" in r.stdout and "good.aou" not in r.stdout
    r = _aouc("fmt", "--diff", str(messy), cwd=tmp_path)
    assert r.returncode == 1 and "+pause 1s x2  # two" in r.stdout
    assert messy.read_text() == "pause   1s  x2 # two\n"  # --check and --diff write nothing
    r = _aouc("fmt", str(tmp_path), cwd=tmp_path)
    assert r.returncode == 1  # bad.aou has a syntax error
    assert "S001" in r.stderr and bad.read_text() == "pause   1,5s\n"  # left untouched
    assert messy.read_text() == "pause 1s x2  # two\n"
    assert messy.stat().st_mode & 0o777 == 0o640
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".aouc")]
    r = _aouc("fmt", "--check", str(good), str(messy), cwd=tmp_path)
    assert r.returncode == 0
    r = _aouc("fmt", str(tmp_path / "missing.aou"), cwd=tmp_path)
    assert r.returncode == 2 and "I501" in r.stderr


def test_fmt_imports_nothing_heavy(tmp_path: Path) -> None:
    """`aouc fmt` is on lint's light path: no numerical library, no editor library."""
    (tmp_path / "a.aou").write_text("pause  1s\n")
    code = ("import sys, aou_dsl.cli.commands as c\n"
            f"c.main(['fmt', '--check', r'{tmp_path}'])\n"
            "heavy = {'pinocchio', 'toppra', 'pybullet', 'numpy', 'pygls', 'lsprotocol'}\n"
            "print(sorted(heavy & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_server_without_the_extra_says_which_to_install() -> None:
    code = ("import sys\nsys.modules['pygls'] = None\nimport aou_dsl.cli.commands as c\n"
            "raise SystemExit(c.main(['server']))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         stdin=subprocess.DEVNULL, timeout=60)
    assert out.returncode == 2
    assert "lsp extra" in out.stderr and "pip install '.[lsp]'" in out.stderr


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                    reason="giving a file to another user needs root")
def test_fmt_keeps_the_owner_group_and_mode_of_what_it_rewrites(tmp_path):
    """A file of nobody's, rewritten by root, stays nobody's: same owner, group, mode."""
    import pwd

    nobody = pwd.getpwnam("nobody")
    messy = tmp_path / "messy.aou"
    messy.write_text("pause   1s  x2 # two\n")
    os.chown(messy, nobody.pw_uid, nobody.pw_gid)
    messy.chmod(0o640)
    from aou_dsl.cli import main

    assert main(["fmt", str(messy)]) == 0
    st = messy.stat()
    assert messy.read_text() == "pause 1s x2  # two\n"
    assert (st.st_uid, st.st_gid, st.st_mode & 0o7777) == (nobody.pw_uid, nobody.pw_gid,
                                                           0o640)
