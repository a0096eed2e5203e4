"""The test plugin ``aou-anticipate`` through every command, as a user runs them: with it
installed (a ``dist-info`` on the import path, as pip leaves one), uninstalled, and
installed with a part missing."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.plugins.install import ROOT, for_commands, wind_up, without_plugins

AOUC = [sys.executable, "-m", "aou_dsl"]

#: A sequence whose anticipation draws back 10 mm at 0.4 m/s^2 before approaches at a
#: tenth of that: its drive (the largest peak acceleration of an approach or an
#: anticipation) comes from the anticipation alone.
SEQUENCE = wind_up()
D, A = 0.010, 0.4


def aouc(*args: str, env: dict[str, str], cwd: Path | None = None
         ) -> subprocess.CompletedProcess:
    return subprocess.run([*AOUC, *args], capture_output=True, text=True, timeout=300,
                          env=env, cwd=cwd)


def no_traceback(run: subprocess.CompletedProcess) -> None:
    assert "Traceback" not in run.stderr + run.stdout, run.stderr


@pytest.fixture(scope="module")
def env(tmp_path_factory) -> dict[str, str]:
    """The environment of an ``aouc`` that has the plugin installed."""
    return for_commands(tmp_path_factory.mktemp("plugin")).env


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("files")
    (folder / "wind_up.aou").write_text(SEQUENCE, encoding="utf-8")
    return folder


@pytest.fixture(scope="module")
def compiled(env, files) -> Path:
    out = files / "wind_up.json"
    run = aouc("compile", str(files / "wind_up.aou"), "-o", str(out), env=env)
    assert run.returncode == 0, run.stderr
    return out


def _lint(path: Path, env: dict[str, str]) -> tuple[int, dict]:
    run = aouc("lint", "--format", "json", str(path), env=env)
    no_traceback(run)
    return run.returncode, json.loads(run.stdout)["files"][0]


def test_lint_infers_the_state_with_the_plugin_kind(env, files):
    """The anticipation's evidence (its peak acceleration adds to the drive, the largest
    counting) is in the point lint infers: the C-V model's formula, fed by hand from the
    file's definitions, gives lint's point, and without the anticipation's drive the
    same file would be another state."""
    from aou_dsl.lang.cv import Composition, infer

    code, out = _lint(files / "wind_up.aou", env)
    assert code == 0, out
    assert [d["code"] for d in out["diagnostics"]] == ["M204"]
    want, _ = infer(Composition(drive=max(A, 0.01), stillness=2.0))
    without, _ = infer(Composition(drive=0.01, stillness=2.0))
    assert (out["cv"]["C"], out["cv"]["V"]) == pytest.approx((want.C, want.V), abs=1e-3)
    assert out["cv"]["state"] == want.state.value
    assert without.state != want.state  # the test can tell the evidence was used


def test_lint_reports_the_plugin_kinds_own_checks(env, tmp_path):
    """The kind validates its statements with V codes: too small to see (V123), larger
    than an anticipation (V130), a duration for a distance (V102), repeated in place in a
    sequence (V113)."""
    bad = SEQUENCE.replace("  anticipate 10mm a=0.4\n",
                           "  anticipate 2mm\n  anticipate 8cm\n  anticipate 1s\n"
                           "  anticipate 10mm x2\n")
    (tmp_path / "bad.aou").write_text(bad, encoding="utf-8")
    code, out = _lint(tmp_path / "bad.aou", env)
    assert code == 1
    got = sorted((d["line"], d["code"]) for d in out["diagnostics"])
    assert got == [(7, "V123"), (8, "V130"), (9, "V102"), (10, "V113")], got


def test_lint_refuses_an_anticipation_no_approach_follows(env, tmp_path):
    """What the kind needs around it (an approach, directly after) is checked: an
    anticipation followed by a pause is refused, naming the kind. Accepted, it would not
    count as declared, yet be measured as a retreat between two pauses."""
    bad = SEQUENCE.replace("  anticipate 10mm a=0.4\n  approach 0.1m a=0.01\n",
                           "  approach 0.1m a=0.01\n  anticipate 10mm a=0.4\n")
    (tmp_path / "late.aou").write_text(bad, encoding="utf-8")
    code, out = _lint(tmp_path / "late.aou", env)
    assert code == 1, out
    errors = [d for d in out["diagnostics"] if d["severity"] == "error"]
    assert errors and all(d["code"].startswith("V") for d in errors), errors
    assert any("anticipat" in d["message"] for d in errors), errors
    assert [d["code"] for d in errors] == ["V121"], errors
    assert "no approach directly after it" in errors[0]["message"], errors


@pytest.mark.parametrize(("drawn", "ok"), [(40, True), (10, False)])
def test_the_standoff_check_counts_the_draw_back(env, tmp_path, drawn, ok):
    """From 15 cm, an 85 mm approach stays outside a 10 cm standoff only after a 40 mm
    draw-back (ending at 10.5 cm), not after a 10 mm one (7.5 cm: V120)."""
    src = tmp_path / "s.aou"
    src.write_text(SEQUENCE.replace("start 0.30m", "start 0.15m").replace(
        "  anticipate 10mm a=0.4\n  approach 0.1m a=0.01\n",
        f"  anticipate {drawn}mm a=0.4\n  approach 85mm a=0.01\n"), encoding="utf-8")
    code, out = _lint(src, env)
    codes = [d["code"] for d in out["diagnostics"] if d["severity"] == "error"]
    assert (code, codes) == ((0, []) if ok else (1, ["V120"])), out["diagnostics"]


DESCRIPTOR_FORM = """\
behaviour wind_up2 : confident
robot panda
start 0.35m
standoff 0.10m
approach a=0.1
anticipate 12mm a=0.3 x2
pause 1s x2
"""


def test_the_descriptor_form_lays_each_anticipation_before_an_approach(env, tmp_path):
    """Laid out from the kind's needs: each of the two anticipations directly before a
    piece of the approach, and the file measures as it declares."""
    src = tmp_path / "d.aou"
    src.write_text(DESCRIPTOR_FORM, encoding="utf-8")
    out = tmp_path / "d.json"
    run = aouc("compile", str(src), "-o", str(out), env=env)
    no_traceback(run)
    assert run.returncode == 0, run.stdout + run.stderr
    kinds = [e["kind"] for e in json.loads(out.read_text(encoding="utf-8"))["episodes"]]
    at = [i for i, k in enumerate(kinds) if k == "anticipate"]
    assert len(at) == 2 and all(kinds[i + 1] == "approach" for i in at), kinds
    run = aouc("measure", str(out), "--against", str(src), "--format", "json", env=env)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = {r["descriptor"]: r for r in json.loads(run.stdout)["descriptors"]}
    assert rows["anticipate_count"]["measured"] == 2
    assert rows["anticipate_distance"]["measured"] == pytest.approx(0.012, abs=1e-3)


def test_the_descriptor_form_without_an_approach_is_refused_by_its_needs(env, tmp_path):
    """No approach, so no layout can show an anticipation: V121 says what the kind
    needs."""
    src = tmp_path / "n.aou"
    src.write_text(DESCRIPTOR_FORM.replace("approach a=0.1\n", ""), encoding="utf-8")
    code, out = _lint(src, env)
    assert code == 1
    errors = [d for d in out["diagnostics"] if d["severity"] == "error"]
    assert {d["code"] for d in errors} == {"V121"}, errors
    (d,) = [d for d in errors if d["line"] == 5]  # the anticipation's statement
    assert "anticipate_count" in d["message"] and "directly before an approach" in \
        d["message"], d


def test_compile_times_the_kind_by_its_law_and_checks_it(compiled):
    """The anticipation is an episode of its own in the trajectory, timed rest to rest
    at its peak acceleration (a bang-bang profile: ``2 sqrt(d / a)`` under the speed
    cap), and the checks pass."""
    traj = json.loads(compiled.read_text(encoding="utf-8"))
    kinds = [e["kind"] for e in traj["episodes"]]
    assert kinds == ["pause", "anticipate", "approach", "pause", "approach"], kinds
    ep = traj["episodes"][1]
    assert ep["t_end"] - ep["t_start"] == pytest.approx(2 * math.sqrt(D / A), rel=0.02)
    assert all(c["ok"] for c in traj["checks"]["kinematic"]["checks"])
    assert traj["descriptors"]["declared"]["anticipate_count"] == 1
    assert traj["descriptors"]["declared"]["anticipate_distance"] == pytest.approx(D)


def test_measure_reads_it_back_as_declared(env, files, compiled):
    run = aouc("measure", str(compiled), "--against", str(files / "wind_up.aou"),
               "--format", "json", env=env)
    no_traceback(run)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = {r["descriptor"]: r for r in json.loads(run.stdout)["descriptors"]}
    assert (rows["anticipate_count"]["declared"], rows["anticipate_count"]["measured"]) \
        == (1, 1)
    assert rows["anticipate_distance"]["declared"] == pytest.approx(D)
    assert rows["anticipate_distance"]["measured"] == pytest.approx(D, abs=1e-3)
    assert all(r["result"] == "pass" for r in rows.values()), rows
    run = aouc("measure", str(compiled), "--format", "json", env=env)
    out = json.loads(run.stdout)
    assert out["descriptors"]["retreat_count"] == 0  # the draw-back is no retreat
    assert [e["kind"] for e in out["episodes"]] == \
        ["pause", "anticipate", "approach", "pause", "approach"]


def test_a_retreat_with_a_pause_after_it_stays_a_retreat(env, tmp_path):
    """The plugin's measurement claims only a move away that an approach follows at once:
    a file without the kind measures as it always did."""
    src = SEQUENCE.replace("  anticipate 10mm a=0.4\n",
                           "  retreat 10mm a=0.4\n  pause 1s\n")
    (tmp_path / "r.aou").write_text(src, encoding="utf-8")
    run = aouc("compile", str(tmp_path / "r.aou"), "-o", str(tmp_path / "r.json"), env=env)
    assert run.returncode == 0, run.stderr
    run = aouc("measure", str(tmp_path / "r.json"), "--format", "json", env=env)
    got = json.loads(run.stdout)["descriptors"]
    assert got["retreat_count"] == 1 and got["anticipate_count"] == 0, got


def test_dmp_export_has_a_part_for_it(env, files, tmp_path):
    pytest.importorskip("movement_primitives")
    out = tmp_path / "wind_up.dmp"
    run = aouc("compile", str(files / "wind_up.aou"), "--format", "dmp", "-o", str(out),
               env=env)
    no_traceback(run)
    assert run.returncode == 0, run.stderr
    manifest = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    assert "anticipate" in json.dumps(manifest)
    kinds = [p.get("kind") for p in manifest.get("parts", manifest.get("episodes", []))]
    assert "anticipate" in kinds, kinds


def test_synth_leaves_out_a_kind_whose_plugin_gives_no_recipe(env, tmp_path):
    """The plugin gives no synthesis recipe: synthesis writes what it writes without it,
    to the byte, and never the kind's statement."""
    texts = []
    for name, run_env in (("with", env), ("without", without_plugins())):
        out = tmp_path / f"{name}.aou"
        run = aouc("synth", "--state", "hesitant", "--intensity", "0.8", "-o", str(out),
                   env=run_env)
        no_traceback(run)
        assert run.returncode == 0, run.stderr
        texts.append(out.read_text(encoding="utf-8").replace(f"{name}.aou", ""))
    assert texts[0] == texts[1]
    assert "anticipate" not in texts[0]


@pytest.mark.parametrize("command", [("rules",), ("robot", "--list")])
def test_rules_and_robot_list_the_plugin(env, command):
    run = aouc(*command, env=env)
    assert run.returncode == 0, run.stderr
    assert "aou-anticipate" in run.stdout and "anticipate" in run.stdout
    bare = aouc(*command, env=without_plugins())
    assert "aou-anticipate" not in bare.stdout


# --- uninstalled --------------------------------------------------------------------------


@pytest.mark.parametrize("how", ["not installed", "AOU_NO_PLUGINS=1"])
def test_uninstalled_the_kind_is_an_unknown_statement_saying_why(files, how, env):
    run_env = without_plugins() if how == "not installed" else dict(env, AOU_NO_PLUGINS="1")
    code, out = _lint(files / "wind_up.aou", run_env)
    assert code == 1
    (d,) = [d for d in out["diagnostics"] if d["severity"] == "error"]
    assert d["code"] == "V101" and d["line"] == 7
    assert "plugin" in d["message"] and "anticipate" in d["message"], d["message"]


def test_uninstalled_aou_works_as_before(tmp_path):
    """A shipped behaviour lints and compiles without the plugin, to the same bytes as
    with it."""
    src = ROOT / "behaviours" / "hesitant.aou"
    outs = []
    inst = for_commands(tmp_path / "with")
    for name, env in (("with", inst.env), ("without", without_plugins())):
        run = aouc("compile", str(src), "-o", str(tmp_path / f"{name}.json"), env=env)
        assert run.returncode == 0, run.stderr
        outs.append(json.loads((tmp_path / f"{name}.json").read_text(encoding="utf-8")))
    for out in outs:
        out.pop("generator", None)
    assert outs[0]["q"] == outs[1]["q"]
    assert outs[0]["episodes"] == outs[1]["episodes"]


# --- a plugin with a part missing ---------------------------------------------------------


def test_a_plugin_without_a_dmp_part_gets_k802(files, tmp_path):
    inst = for_commands(tmp_path, "aou_anticipate.partial:without_dmp")
    run = aouc("compile", str(files / "wind_up.aou"), "--format", "dmp", "-o",
               str(tmp_path / "w.dmp"), env=inst.env)
    no_traceback(run)
    assert run.returncode != 0
    assert "K802" in run.stdout + run.stderr
    assert "anticipate" in run.stdout + run.stderr and "dmp" in run.stdout + run.stderr
    assert not (tmp_path / "w.dmp").exists()


def test_a_plugin_without_a_measure_part_gets_k802(files, compiled, tmp_path):
    inst = for_commands(tmp_path, "aou_anticipate.partial:without_measure")
    run = aouc("measure", str(compiled), "--against", str(files / "wind_up.aou"),
               env=inst.env)
    no_traceback(run)
    assert run.returncode != 0
    assert "K802" in run.stdout + run.stderr and "measure" in run.stdout + run.stderr


def test_compile_says_k802_when_no_measure_part_can_check_the_motion(files, tmp_path):
    """Compile checks its own trajectory by measuring it; with no pass that reads the
    plugin's kind back, that check cannot be done, and the compile says so (not a C310
    that blames the motion, nor a pass)."""
    inst = for_commands(tmp_path, "aou_anticipate.partial:without_measure")
    run = aouc("compile", str(files / "wind_up.aou"), "-o", str(tmp_path / "w.json"),
               env=inst.env)
    no_traceback(run)
    out = run.stdout + run.stderr
    assert run.returncode == 1, out
    assert "K802" in out and "measure" in out and "C310" not in out, out


def test_a_plugin_that_gives_no_kind_is_reported_k801(files, tmp_path):
    inst = for_commands(tmp_path, "aou_anticipate.partial:nothing")
    rules = aouc("rules", env=inst.env)
    lint = aouc("lint", str(files / "wind_up.aou"), env=inst.env)
    no_traceback(rules)
    no_traceback(lint)
    assert "K801" in rules.stdout + rules.stderr and "aou-anticipate" in rules.stdout + \
        rules.stderr
    assert lint.returncode == 1
    assert ":7:3: K801 [warning]" in lint.stdout and ":7:3: V101 [error]" in lint.stdout


# --- the package itself -------------------------------------------------------------------


_TEXT = (".py", ".md", ".json", ".toml", ".txt", ".js", ".html", ".css", ".lark")


#: The kind's keyword, its descriptors' names (``anticipate_count``) and its node's class
#: (``Anticipate``), in any case; not the English verb's other forms (``anticipates``).
_NAMED = re.compile(r"anticipate(?![a-z])", re.IGNORECASE)


def naming(folder: Path) -> list[str]:
    """The text files under ``folder`` that name the plugin's kind."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")
                  if p.is_file() and p.suffix in _TEXT
                  and _NAMED.search(p.read_text(encoding="utf-8", errors="replace")))


def test_no_file_of_the_package_names_the_plugin_kind():
    """aou knows the kind only through the installed plugin."""
    assert naming(ROOT / "aou_dsl") == []


def test_the_scan_finds_a_planted_name(tmp_path):
    """The check above can fail: a copy of a module with the kind planted in it is found."""
    (tmp_path / "lang").mkdir()
    text = (ROOT / "aou_dsl" / "lang" / "layout.py").read_text(encoding="utf-8")
    (tmp_path / "lang" / "layout.py").write_text(text + '\nKIND = "Anticipate"\n',
                                                 encoding="utf-8")
    (tmp_path / "lang" / "ir.py").write_text("x = 1\n", encoding="utf-8")
    assert naming(tmp_path) == ["lang/layout.py"]
