"""Fits that keep the look: each primitive kind says what makes it look like itself
(a shiver is a tremor of 2.5 Hz at least and 1 deg wide at least), `--fit` keeps it or
refuses (C315), and `aouc measure --against` says when a motion reads as a kind its file
does not declare (R413).

Checked on every built-in arm and the vendor Gen3 URDF: the fearful stimulus and files
generated from the language's definitions (shivers that are tremors as declared, tilts),
each fitted, then measured by aou's own measurement: no episode reads as a kind the file
does not declare, the fitted shiver keeps the frequency and amplitude floors, and a
variant pair keeps its order."""

from __future__ import annotations

import functools
import math
import random

import pytest

from aou_dsl.cli.commands import main
from aou_dsl.core.robot_specs import ROBOTS
from aou_dsl.driver.builder import build_file, build_source
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.primitives import (
    KINDS,
    LOOK_SHIVER_F,
    LOOK_SLACK,
    MIN_PAUSE,
    MIN_SHIVER_F,
    VISIBLE_SHIVER,
    look_changed,
)
from aou_dsl.media.variants import make_variants
from tests.conftest import BEHAVIOURS
from tests.integration.test_fit import GEN3

FEARFUL = BEHAVIOURS / "fearful.aou"
ARMS = [*ROBOTS, GEN3]
#: The measured amplitude's tolerance [deg] (the descriptor table's).
AMPLITUDE_TOL = 0.5


def _id(robot: str) -> str:
    return "gen3-urdf" if robot == GEN3 else robot


def test_the_floors_follow_from_the_definitions():
    """A swing (half a cycle) no longer than the shortest moment a person tells apart;
    the visible floor is the language's least visible angle; both are what each kind
    module states, and the language still accepts its slower shivers."""
    assert LOOK_SHIVER_F == pytest.approx(1.0 / (2.0 * MIN_PAUSE)) == pytest.approx(2.5)
    assert MIN_SHIVER_F < LOOK_SHIVER_F
    assert math.degrees(VISIBLE_SHIVER) == pytest.approx(1.0)
    assert "2.5 Hz" in KINDS["shiver"].look and "1 deg" in KINDS["shiver"].look
    assert all(k.look for k in KINDS.values())
    assert lint_source("shiver 6deg f=1.1Hz\n", "old.aou").ok  # files written for 1 Hz


def _episodes(text: str):
    lint = lint_source(text, "k.aou")
    assert lint.ok and lint.timeline is not None, text
    return lint.timeline.episodes


def _changed(text: str, which: str, **to):
    """The episodes of ``text``, and the same with the first ``which`` episode changed."""
    import dataclasses

    eps = _episodes(text)
    k = next(i for i, e in enumerate(eps) if e.kind == which)
    e = eps[k]
    if "roll" in to:
        to = {"end": dataclasses.replace(e.end, roll=e.start.roll + to.pop("roll"))}
    return eps, [*eps[:k], dataclasses.replace(e, **to), *eps[k + 1:]]


@pytest.mark.parametrize(("text", "kind", "to", "why"), [
    ("shiver 6deg\n", "shiver", {"f": 1.1}, "slow rolls"),
    ("shiver 6deg\n", "shiver", {"amplitude": math.radians(0.6)}, "under the 1 deg"),
    ("approach a=0.1\ntilt 20deg v=20deg/s\n", "tilt", {"duration": 0.5}, "faster"),
    ("approach a=0.1\ntilt 20deg\n", "tilt", {"roll": -math.radians(20)}, "other way"),
    ("approach a=0.1\ntilt 20deg\n", "tilt", {"kind": "gaze"}, "a gaze, not a tilt"),
    ("approach a=0.1\npause 1s\ngaze horizontal 20deg\n", "gaze", {"plane": "vertical"},
     "vertical plane"),
])
def test_each_kind_refuses_a_change_that_changes_its_look(text, kind, to, why):
    declared, fitted = _changed(text, kind, **to)
    got = look_changed(declared, fitted)
    assert got is not None and why in got, got


@pytest.mark.parametrize(("text", "kind", "to"), [
    ("shiver 6deg f=4Hz\n", "shiver", {"f": 2.5}),  # still a tremor
    ("shiver 6deg\n", "shiver", {"amplitude": math.radians(1.26)}),  # narrower, seen
    ("shiver 6deg f=1.5Hz\n", "shiver", {"amplitude": math.radians(3)}),  # slow as declared
    ("approach a=0.1\ntilt 20deg v=60deg/s\n", "tilt", {"duration": 1.0}),  # slower
])
def test_each_kind_keeps_its_look_through_the_fits_it_allows(text, kind, to):
    assert look_changed(*_changed(text, kind, **to)) is None


def _reads_clean(res) -> None:
    """The fitted build measures with no episode of a kind its file does not declare,
    and its shivers keep the floors."""
    declared = {e.kind for e in res.lint.timeline.episodes}
    for e in res.measured.episodes:
        reads = KINDS[e.kind].reads_as(e.values, e.t_end - e.t_start)
        assert reads in declared, (e.kind, reads, dict(e.values), res.fitted_source)
        if e.kind == "shiver":
            assert e.values["frequency"] >= LOOK_SHIVER_F * (1 - LOOK_SLACK), dict(e.values)
            assert e.values["amplitude"] >= math.degrees(VISIBLE_SHIVER) - AMPLITUDE_TOL
    for c in (res.header or {}).get("fitted", []):
        if c["key"] == "f":
            assert float(c["fitted"]) >= LOOK_SHIVER_F, c
        if c["descriptor"] == "shiver_amplitude":
            assert float(c["fitted"]) >= math.degrees(VISIBLE_SHIVER), c


def _fit_or_refuse(res, original: str) -> None:
    """A fitted build reads clean; a refused one never made a shiver slower than a tremor
    and, if a shiver was what it could not fit, said why (C315)."""
    slowed = [d for d in res.diagnostics if d.code == "C314" and d.fields.get("key") == "f"
              and float(d.fields["fitted"]) < LOOK_SHIVER_F]
    assert not slowed, [d.message for d in slowed]
    if res.ok:
        _reads_clean(res)
    elif any(d.code == "C308" and d.fields.get("look") for d in res.diagnostics):
        assert [d for d in res.diagnostics if d.code == "C315"], original


@functools.cache
def _fearful(robot: str):
    return build_file(str(FEARFUL), robot=robot, fit=True, check=False)


@pytest.mark.parametrize("robot", ARMS, ids=_id)
def test_fearful_fitted_on_every_arm_never_reads_as_another_kind(robot):
    """Fitted to each arm, the fearful stimulus either keeps its tremor (2.5 Hz at least,
    1 deg at least, no episode read as a kind it does not declare) or is refused with
    the reason; it is never slowed into rolls."""
    res = _fearful(robot)
    _fit_or_refuse(res, FEARFUL.read_text())
    if robot in ("panda", "xarm7"):  # their wrists give it as declared
        assert res.ok and res.measured.descriptors["shiver_amplitude"] == pytest.approx(
            6.0, abs=AMPLITUDE_TOL)
    else:
        assert not res.ok, robot  # too narrow at 2.5 Hz to stay fearful: refused
        (c,) = [d for d in res.diagnostics if d.code == "C315"]
        assert "`hesitant`, not `fearful`" in c.message and "slow rolls" in c.message


def generated(n: int, seed: int) -> list[str]:
    """Files with a shiver (a tremor as declared: 2.5 to 6 Hz, 2 to 12 deg, often more
    than a small wrist follows) and a tilt, in the descriptor form, with no state (so
    the fit is held to the look alone)."""
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        amp, f = rng.choice([2, 3, 4, 6, 8, 12]), rng.choice([2.5, 3, 4, 6])
        dur = rng.choice(["", " for 1.5s"])
        tilt, v = rng.choice([8, 15, 25]), rng.choice([15, 30, 60])
        out.append(f"behaviour g\napproach a=0.1\npause 1s x2\nshiver {amp}deg f={f}Hz{dur}\n"
                   f"tilt {tilt}deg v={v}deg/s x{rng.choice([1, 2])}\n")
    return out


@pytest.mark.parametrize("robot", ARMS, ids=_id)
def test_generated_shivers_and_tilts_fitted_on_every_arm_keep_their_kinds(robot):
    """Two generated files per arm (a different pair on each), fitted and measured."""
    for text in generated(2, seed=ARMS.index(robot)):
        res = build_source(text, "g.aou", robot=robot, fit=True, check=False)
        _fit_or_refuse(res, text)
        assert res.ok or [d for d in res.diagnostics if d.code == "C315"], (
            text, [(d.code, d.message) for d in res.diagnostics])


@pytest.mark.slow
@pytest.mark.parametrize("robot", ARMS, ids=_id)
def test_more_generated_shivers_and_tilts_keep_their_kinds(robot):
    for text in generated(12, seed=100 + ARMS.index(robot)):
        res = build_source(text, "g.aou", robot=robot, fit=True, check=False)
        _fit_or_refuse(res, text)


@pytest.mark.parametrize("robot", ["ur5", "kinova"])
def test_a_variant_pair_keeps_its_order_after_fitting(robot):
    """`aouc variants` of a shiver's amplitude: both too wide for the wrist at a tremor's
    rate, both narrowed, in the same order, neither slowed under 2.5 Hz."""
    base = "behaviour g\napproach a=0.1\npause 1s x2\nshiver 8deg f=4Hz\n"
    pair = make_variants(lint_source(base, "g.aou").behaviour, base, "shiver_amplitude",
                         8.0, 12.0, "g-shiver_amplitude")
    got = []
    for v in pair:
        res = build_source(v.text, v.path, robot=robot, fit=True, check=False)
        assert res.ok, [(d.code, d.message) for d in res.diagnostics]
        _reads_clean(res)
        (amp,) = [c for c in res.header["fitted"] if c["descriptor"] == "shiver_amplitude"]
        got.append(float(amp["fitted"]))
    assert got[0] < got[1], got


def test_a_wrist_too_weak_for_a_visible_tremor_is_refused_with_c315(tmp_path, capsys):
    """A robot description pins the Gen3's wrist at 0.5 rad/s^2: at 2.5 Hz it follows
    0.2 deg, under the 1 deg a person sees; slower would be rolls. `aouc compile --fit`
    refuses with C315 and writes nothing."""
    desc = tmp_path / "weak.toml"
    desc.write_text(f'urdf = "{GEN3}"\njoint_accel = 0.5\njoint_jerk = 1000\n')
    src = tmp_path / "s.aou"
    src.write_text("behaviour s\napproach a=0.05\npause 1s\nshiver 6deg\n")
    out = tmp_path / "s.json"
    assert main(["compile", str(src), "--robot", str(desc), "--fit", "--no-check",
                 "-o", str(out)]) != 0
    err = capsys.readouterr().err
    assert " C315 " in err and "under the 1 deg a person sees" in err, err
    assert not out.exists()


SLOW = "behaviour s\napproach a=0.1\npause 1s\nshiver 6deg f=1.1Hz\n"
QUICK = "behaviour s\napproach a=0.1\npause 1s\nshiver 6deg\n"
TILTED = "behaviour s\napproach a=0.1\npause 1s\ntilt 20deg\n"


@pytest.fixture(scope="module")
def motions(tmp_path_factory):
    """The three files, each compiled once for the Panda (as the language allows)."""
    folder = tmp_path_factory.mktemp("look")
    out = {}
    for name, text in (("slow", SLOW), ("quick", QUICK), ("tilted", TILTED)):
        (folder / f"{name}.aou").write_text(text)
        out[name] = folder / f"{name}.json"
        assert main(["compile", str(folder / f"{name}.aou"), "--no-check", "-o",
                     str(out[name])]) == 0
    out["folder"] = folder
    return out


def _against(motions, name: str, against: str, capsys) -> tuple[int, list[dict]]:
    import json

    code = main(["measure", str(motions[name]), "--against",
                 str(motions["folder"] / f"{against}.aou"), "--format", "json"])
    return code, json.loads(capsys.readouterr().out)["diagnostics"]


def test_a_shiver_slower_than_a_tremor_reads_as_rolls_r413(motions, capsys):
    """Its amplitude passes (R408 has nothing to say), but a 1.1 Hz shiver reads as a
    tilt, which the file does not declare: R413, with the episode's time and frequency."""
    code, diags = _against(motions, "slow", "quick", capsys)
    (d,) = [d for d in diags if d["code"] == "R413"]
    assert d["severity"] == "warning" and d["fields"]["kind"] == "tilt"
    assert "measured as a shiver" in d["message"] and "slower than a tremor" in d["message"]
    assert not [d for d in diags if d["code"] == "R408"] and code == 0


def test_a_tremor_reads_as_the_shiver_its_file_declares(motions, capsys):
    code, diags = _against(motions, "quick", "quick", capsys)
    assert code == 0 and not [d for d in diags if d["code"] == "R413"], diags


def test_a_tilt_the_file_does_not_declare_is_named_r413(motions, capsys):
    code, diags = _against(motions, "tilted", "quick", capsys)
    (d,) = [d for d in diags if d["code"] == "R413"]
    assert d["fields"]["kind"] == "tilt" and [e[0] for e in d["fields"]["episodes"]] == ["tilt"]
    assert code == 1  # its tilt_angle, declared absent, fails too (R408)
