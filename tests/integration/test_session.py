"""The warm session: it re-runs only the stages whose inputs changed, and what it gives
is what a fresh process gives for the same text, to the byte."""

from __future__ import annotations

import subprocess
import sys

from aou_dsl.compiler.output import encode
from aou_dsl.core.options import BuildOptions
from aou_dsl.driver.session import Session
from tests.conftest import BEHAVIOURS, ROOT

HESITANT = (BEHAVIOURS / "hesitant.aou").read_text()


def test_the_same_text_is_linted_and_built_once():
    """A text the session has seen is neither linted nor built again; a trailing comment
    (the behaviour and its positions unchanged) is linted again but not built."""
    s = Session()
    first = s.build(HESITANT, "h.aou")
    assert first.ok
    assert s.build(HESITANT, "h.aou") is first
    commented = HESITANT.rstrip("\n") + "  # a note\n"
    assert s.build(commented, "h.aou") is first
    assert s.runs == {"lint": 2, "build": 1}


def test_a_changed_descriptor_is_built_again_and_measures_its_new_value():
    """Changing one value builds again, and the motion measures with that value."""
    s = Session()
    s.build(HESITANT, "h.aou")
    changed = s.build(HESITANT.replace("1.67s", "2.1s"), "h.aou")
    assert changed.ok and s.runs["build"] == 2
    assert abs(changed.measured.descriptors["pause_duration"] - 2.1) < 0.05


def test_other_options_are_another_build():
    """The options are part of what a build depends on: another rate is built again."""
    s = Session(BuildOptions(rate=100.0))
    a = s.build(HESITANT, "h.aou")
    b = s.build(HESITANT, "h.aou", rate=50.0)
    assert a is not b and s.runs["build"] == 2
    assert len(b.trajectory.t) < len(a.trajectory.t)


def test_a_warm_rebuild_writes_the_bytes_a_fresh_process_writes(tmp_path):
    """After one value changed, a session re-solves only the episodes it changed; the
    document it makes is byte for byte the one `aouc compile` writes for that text."""
    s = Session()
    s.build(HESITANT, "h.aou")
    text = HESITANT.replace("retreat 0.06m a=0.12", "retreat 0.07m a=0.12")
    warm = s.build(text, str(tmp_path / "changed.aou"))
    assert warm.ok
    (tmp_path / "changed.aou").write_text(text)
    out = tmp_path / "changed.json"
    subprocess.run([sys.executable, "-m", "aou_dsl", "compile", str(tmp_path / "changed.aou"),
                    "-o", str(out)], check=True, cwd=ROOT, capture_output=True)
    assert encode(warm.document, "json") == out.read_bytes()


def test_an_unreadable_file_is_a_result_with_its_code(tmp_path):
    """build_file of a missing file is a result with I501, as build_file gives."""
    res = Session().build_file(str(tmp_path / "missing.aou"))
    assert not res.ok and [d.code for d in res.diagnostics] == ["I501"]


#: A fresh process's build of a file: its document's bytes and its diagnostics.
_COLD = ("import sys\n"
         "from aou_dsl.driver.builder import build_file\n"
         "from aou_dsl.compiler.output import encode\n"
         "res = build_file(sys.argv[1])\n"
         "open(sys.argv[2], 'wb').write(encode(res.document, 'json'))\n"
         "open(sys.argv[3], 'w').write(repr(res.diagnostics))\n")

#: One value changed at a time, of different kinds: (behaviour, text, its replacement).
_CHANGES = [
    ("hesitant", "pause 1.67s", "pause 1.43s"),  # a pause: later episodes move in time
    ("hesitant", "retreat 0.06m a=0.12", "retreat 0.06m a=0.2"),  # an acceleration
    ("hesitant", "a=0.12 x3", "a=0.12 x2"),  # a repeat count: episodes drop out
    ("hesitant", "a=0.12", "a=9"),  # beyond what the arm gives: a C304 warning
    ("curious", "gaze horizontal 20deg", "gaze horizontal 14deg"),  # a gaze angle
]


def test_warm_rebuilds_after_changes_of_each_kind_match_fresh_builds(tmp_path):
    """A session that rebuilt one behaviour after another, each after one value changed
    (so it holds what the earlier builds kept: solved episodes, distances and poses by
    joint values), gives for each the document and diagnostics a fresh process gives."""
    s = Session()
    procs, warm = [], []
    for k, (name, old, new) in enumerate(_CHANGES):
        base = (BEHAVIOURS / f"{name}.aou").read_text()
        assert old in base
        path = tmp_path / f"{k}_{name}.aou"
        path.write_text(base.replace(old, new, 1))
        assert s.build(base, str(path)).ok
        res = s.build(path.read_text(), str(path))
        assert res.ok, res.diagnostics
        warm.append((encode(res.document, "json"), repr(res.diagnostics)))
        procs.append(subprocess.Popen(
            [sys.executable, "-c", _COLD, str(path), str(path.with_suffix(".json")),
             str(path.with_suffix(".diag"))], cwd=ROOT))
    assert any("C304" in diags for _, diags in warm)
    for k, (proc, (doc, diags)) in enumerate(zip(procs, warm, strict=True)):
        assert proc.wait() == 0
        path = tmp_path / f"{k}_{_CHANGES[k][0]}.aou"
        assert doc == path.with_suffix(".json").read_bytes(), _CHANGES[k]
        assert diags == path.with_suffix(".diag").read_text(), _CHANGES[k]


def test_a_file_is_linted_once_to_be_built(tmp_path, monkeypatch):
    """``build_file`` (what ``aouc compile`` runs) judges the file's text once: the
    lint that read the file is the one built from, and the document is the one a build
    of its text gives."""
    from aou_dsl.lang import linter, relint

    judged: list[str] = []
    real = linter.judge

    def spy(text, path, *args, **kwargs):
        judged.append(path)
        return real(text, path, *args, **kwargs)

    monkeypatch.setattr(linter, "judge", spy)
    monkeypatch.setattr(relint, "judge", spy)
    path = tmp_path / "h.aou"
    path.write_text(HESITANT)
    res = Session().build_file(str(path))
    assert res.ok and judged == [str(path)]
    monkeypatch.undo()
    assert encode(res.document, "json") == encode(Session().build(HESITANT, str(path))
                                                  .document, "json")
