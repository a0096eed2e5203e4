"""``aouc studio --fit``: the motion shown is the one ``aouc compile --fit`` makes, the
values fitted to the arm are listed in the page, slider moves are fitted again, and Save
writes the values of the sliders, not the fitted ones.

The fearful stimulus with a 4 Hz shiver, on a UR5 whose wrist (pinned at 18 rad/s^2)
follows it at 2.8 Hz, still a tremor, needs fitting: its 2 m/s^2 retreat is more than
the shoulder gives, and its shiver too fast (a C308 error without ``--fit``).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

from aou_dsl.api import compile as aou_compile
from aou_dsl.studio.app import Studio

ROOT = str(Path(__file__).resolve().parents[2])


def _fitted(studio) -> dict[str, str]:
    """The page's list of fitted values: key -> fitted value."""
    import re

    return dict(re.findall(r'data-key="(\w+)" data-line="\d+" data-fitted="([^"]+)"',
                           studio.fitted.content))


def test_fit_shows_the_fitted_motion_and_save_keeps_the_sliders_values(tmp_path):
    path = tmp_path / "fearful.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "fearful.aou"), path)
    path.write_text(path.read_text().replace("shiver 6deg for 1.25s",
                                             "shiver 6deg f=4Hz for 0.8s"))
    arm = tmp_path.parent / f"{tmp_path.name}-ur5.toml"  # beside: the folder stays one file
    arm.write_text('robot = "ur5"\njoint_accel = [5, 5, 5, 5, 5, 18]\n')
    ur5 = str(arm)
    before = path.read_text()
    assert not aou_compile(str(path), robot=ur5, check=False).ok  # it needs fitting
    studio = Studio(str(path), robot=ur5, port=0, watch=False, fit=True).start()
    try:
        first = studio.shown
        fitted = _fitted(studio)
        assert {"a", "f", "for"} <= set(fitted)
        assert float(fitted["a"]) < 2.0  # the retreat's acceleration, what the wrist gives
        assert studio.sliders.values()["retreat_acceleration"] == 2.0  # the file's value
        fit = aou_compile(str(path), robot=ur5, fit=True)
        assert fit.ok and np.array_equal(fit.trajectory.q, first.trajectory.q)
        # a slider move is fitted again, and the page says so
        m = studio.set_values({**studio.sliders.values(), "retreat_acceleration": 3.0,
                               "pause_duration": 1.5})
        assert m.ok and studio.shown is m and m.fitted is not None
        assert "retreat 0.06m a=3\n" in m.text
        assert "pause 1.5s x4" in m.text and "f=4Hz for 0.8s" in m.text
        assert float(_fitted(studio)["a"]) < 2.0
        studio.save()
    finally:
        studio.close()
    saved = path.read_text()
    assert saved == before.replace("a=2", "a=3").replace("1.25s x4", "1.5s x4")
    again = aou_compile(str(path), robot=ur5, fit=True)  # the saved file, with --fit
    assert again.ok
    assert np.array_equal(again.trajectory.t, m.trajectory.t)
    assert np.array_equal(again.trajectory.q, m.trajectory.q)
    assert again.measured.descriptors["pause_duration"] == pytest.approx(1.5, abs=0.05)
    assert sorted(os.listdir(tmp_path)) == ["fearful.aou"]


def test_without_fit_nothing_is_listed_as_fitted(tmp_path):
    path = tmp_path / "hesitant.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    studio = Studio(str(path), port=0, watch=False).start()
    try:
        assert studio.fitted.content == "" and studio.shown.fitted is None
    finally:
        studio.close()
