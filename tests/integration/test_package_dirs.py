"""``--package-dir`` in every command that loads an arm's meshes, in this process, in a
pool of workers and on a Dask cluster.

The arm is a vendor's: Kinova's URDF and meshes from example-robot-data, laid out as a
vendor's description package ``acme_arm`` (its URDF names its meshes
``package://acme_arm/meshes/...``), the package in one folder and the URDF alone in
another. Its meshes are then found only through
``--package-dir`` (no parent folder holds the package, and ROS_PACKAGE_PATH is unset).
"""

from __future__ import annotations

import json
import os
import shutil

import pytest

from aou_dsl.cli import main
from aou_dsl.core.options import BuildOptions
from tests.conftest import BEHAVIOURS


@pytest.fixture(scope="module")
def vendor(tmp_path_factory):
    import example_robot_data as erd

    from aou_dsl.core.robot_specs import ROBOTS

    panda = os.path.join(erd.getModelPath(ROBOTS["panda"].urdf), ROBOTS["panda"].urdf)
    robots = os.path.dirname(os.path.dirname(os.path.dirname(panda)))
    root = tmp_path_factory.mktemp("vendor")
    kinova = os.path.join(robots, "kinova_description")
    shutil.copytree(os.path.join(kinova, "meshes"), root / "pkgs" / "acme_arm" / "meshes")
    (root / "robots").mkdir()
    urdf = root / "robots" / "acme.urdf"
    text = open(os.path.join(kinova, "robots", "kinova.urdf")).read()
    vendor_text = text.replace("package://example-robot-data/robots/kinova_description/",
                               "package://acme_arm/")
    assert vendor_text != text and "example-robot-data" not in vendor_text
    urdf.write_text(vendor_text)
    return root, str(urdf), str(root / "pkgs")


@pytest.fixture(autouse=True)
def _no_ros_path(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)


def _run(capsys, *argv: str) -> tuple[int, str]:
    code = main(list(argv))
    return code, capsys.readouterr().err


def test_without_the_package_dir_the_meshes_are_not_found(vendor, capsys, tmp_path):
    """The set-up holds: the URDF alone cannot find its meshes (V109)."""
    root, urdf, _ = vendor
    code, err = _run(capsys, "compile", str(BEHAVIOURS / "curious.aou"), "--robot", urdf,
                     "-o", str(tmp_path / "c.json"))
    assert code == 1 and "V109" in err, err
    assert not (tmp_path / "c.json").exists()


@pytest.mark.slow
def test_compile_check_measure_and_plot_find_the_meshes_through_it(vendor, capsys, tmp_path):
    """compile (one process and --jobs 2, the same bytes), check, measure and plot of
    the compiled file each find the meshes through --package-dir."""
    root, urdf, pkgs = vendor
    # three files: with --jobs 2 this process builds the shortest, then a worker joins
    # (with two, the second would be built here too)
    names = ("curious", "confident", "inactive")
    files = [str(BEHAVIOURS / f"{n}.aou") for n in names]
    one, two = tmp_path / "one", tmp_path / "two"
    code, err = _run(capsys, "compile", *files, "--robot", urdf, "--package-dir", pkgs,
                     "-o", str(one) + "/")
    assert code == 0, err
    code, err = _run(capsys, "compile", *files, "--robot", urdf, "--package-dir", pkgs,
                     "--jobs", "2", "-o", str(two) + "/")
    assert code == 0, err
    for n in names:
        assert (one / f"{n}.json").read_bytes() == (two / f"{n}.json").read_bytes()
    traj = str(one / "curious.json")
    code, err = _run(capsys, "check", traj, "--robot", urdf, "--package-dir", pkgs)
    assert code == 0, err
    code, err = _run(capsys, "measure", traj, "--robot", urdf, "--package-dir", pkgs,
                     "--format", "json")
    assert code == 0, err
    code, err = _run(capsys, "plot", traj, "--robot", urdf, "--package-dir", pkgs,
                     "-o", str(tmp_path / "p.png"))
    assert code == 0 and (tmp_path / "p.png").stat().st_size > 0, err


@pytest.mark.slow
def test_render_finds_the_meshes_through_it(vendor, capsys, tmp_path):
    """render draws the arm's visual meshes, found through --package-dir."""
    pytest.importorskip("PIL")
    root, urdf, pkgs = vendor
    code, err = _run(capsys, "compile", str(BEHAVIOURS / "curious.aou"), "--robot", urdf,
                     "--package-dir", pkgs, "--rate", "50", "--no-check",
                     "-o", str(tmp_path / "c.json"))
    assert code == 0, err
    code, err = _run(capsys, "render", str(tmp_path / "c.json"), "--robot", urdf,
                     "--package-dir", pkgs, "--size", "160x120", "--fps", "5",
                     "-o", str(tmp_path / "c.gif"))
    assert code == 0 and (tmp_path / "c.gif").stat().st_size > 0, err


@pytest.mark.slow
def test_a_dask_cluster_receives_the_package_dirs(vendor, tmp_path):
    """The options travel to a Dask worker process whole: the build there finds the
    meshes and gives the same document as one in this process."""
    distributed = pytest.importorskip("distributed")
    from aou_dsl.driver.builder import build_file
    from aou_dsl.driver.parallel import build_many

    root, urdf, pkgs = vendor
    opts = BuildOptions(robot=urdf, package_dirs=(pkgs,), rate=100.0)
    path = str(BEHAVIOURS / "curious.aou")
    here = build_file(path, opts)
    assert here.ok, [(d.code, d.message) for d in here.diagnostics]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        got = list(build_many([path], opts, cluster=cluster.scheduler_address))
    assert got[0].ok, [(d.code, d.message) for d in got[0].diagnostics]
    assert json.dumps(got[0].document) == json.dumps(here.document)


def test_build_options_are_one_frozen_picklable_value(tmp_path):
    """BuildOptions pickles whole, keeps its package folders absolute and in the scene,
    and refuses a field it does not have."""
    import pickle

    opts = BuildOptions(robot="panda", package_dirs=("pkgs",), rate=100.0)
    again = pickle.loads(pickle.dumps(opts))
    assert again == opts and again.package_dirs == (os.path.abspath("pkgs"),)
    assert again.scene.package_dirs == again.package_dirs
    with pytest.raises(TypeError):
        opts.replace(robots="ur5")
    with pytest.raises(ValueError):
        BuildOptions(rate=-1.0)
