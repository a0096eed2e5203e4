"""``package://`` mesh paths resolve only inside a package that exists, and a mesh is
handed to PyBullet only under a size bound.

The promises (aou_dsl/robot/urdf.py, docs/robots.md): a ``package://NAME/...`` path is
found in a folder named NAME on the search path (the folders given, the URDF's folder and
its parents, ROS_PACKAGE_PATH), or in the package holding the URDF copied under another
name; the file, links resolved, lies inside that package. A mesh larger than the bound
of a mesh file (``AOU_MAX_INPUT_MB``) is V132, named before PyBullet reads a byte.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main
from aou_dsl.core.diagnostics import AouError
from aou_dsl.robot.urdf import read_urdf, resolve_uri, scene_xml
from tests.conftest import fails_with

ONE_JOINT = """<?xml version="1.0"?>
<robot name="one">
  <link name="base"/>
  <link name="l1"><collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="2" effort="50"/></joint>
</robot>
"""


@pytest.fixture
def ws(tmp_path, monkeypatch):
    """pkgs/pkg: a package with a mesh, a folder `etc` linking to /etc and a link to a
    file outside it; urdf/: a URDF alone."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = tmp_path / "pkgs" / "pkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "meshes" / "a.stl").write_text("solid a\nendsolid a\n")
    (pkg / "etc").symlink_to("/etc")
    (tmp_path / "secret.stl").write_text("solid s\nendsolid s\n")
    (pkg / "meshes" / "out.stl").symlink_to(tmp_path / "secret.stl")
    (pkg / "meshes" / "in.stl").symlink_to("a.stl")  # a link inside the package: fine
    (tmp_path / "deep" / "er" / "urdf").mkdir(parents=True)
    return tmp_path


ESCAPES = ["package://../etc/passwd", "package://nopkg/etc/passwd",
           "package://pkg/etc/passwd", "package://pkg/../../etc/passwd",
           "package:///etc/passwd", "package://./etc/passwd", "package://pkg//etc/passwd",
           "package://pkg/meshes/out.stl", "package://nopkg/pkgs/pkg/etc/passwd",
           "package://nopkg/secret.stl", "package://etc/passwd", "package:////etc/passwd"]


@pytest.mark.parametrize("uri", ESCAPES)
def test_a_package_path_resolves_only_inside_a_package_that_exists(ws, uri):
    folder = str(ws / "deep" / "er" / "urdf")
    for dirs in ([str(ws / "pkgs")], [str(ws)], []):
        got = resolve_uri(uri, folder, dirs)
        assert got is None or os.path.realpath(got).startswith(
            os.path.realpath(ws / "pkgs" / "pkg") + os.sep), (uri, dirs, got)
    assert resolve_uri(uri, folder, [str(ws / "pkgs")]) is None, uri


def test_paths_inside_a_package_still_resolve(ws):
    folder = str(ws / "deep" / "er" / "urdf")
    mesh = str(ws / "pkgs" / "pkg" / "meshes" / "a.stl")
    assert resolve_uri("package://pkg/meshes/a.stl", folder, [str(ws / "pkgs")]) == mesh
    assert resolve_uri("package://pkg/meshes/in.stl", folder, [str(ws / "pkgs")]) == \
        str(ws / "pkgs" / "pkg" / "meshes" / "in.stl")
    assert resolve_uri("package://pkg/meshes/a.stl", folder) is None  # not on the path
    # vendors write package:///NAME/... (example-robot-data's Talos) for package://NAME/
    assert resolve_uri("package:///pkg/meshes/a.stl", folder, [str(ws / "pkgs")]) == mesh


@pytest.mark.parametrize("uri", ["package://../etc/passwd", "package:////etc/passwd",
                                 "package://./etc/passwd", "package:///../etc/passwd"])
def test_a_package_path_naming_no_package_is_v131(tmp_path, uri):
    path = tmp_path / "one.urdf"
    path.write_text(ONE_JOINT.format(mesh=uri))
    d = fails_with("V131", read_urdf, str(path))
    assert d.span.path == str(path)


@pytest.mark.parametrize("uri", ESCAPES[1:3] + ESCAPES[-5:-1])
def test_an_escaping_mesh_never_reaches_pybullet(ws, uri, capsys):
    """The copy PyBullet loads names no file outside the package; the command says the
    mesh is not found, with a code."""
    path = ws / "deep" / "er" / "urdf" / "one.urdf"
    path.write_text(ONE_JOINT.format(mesh=uri))
    text, missing = scene_xml(read_urdf(str(path)), [str(ws / "pkgs")], None, visuals=False)
    assert missing == [uri] and "/etc/passwd" not in text.replace(uri, "")
    assert "secret" not in text.replace(uri, "")
    code = main(["robot", str(path), "--package-dir", str(ws / "pkgs")])
    err = capsys.readouterr().err
    assert "V109" in err and "not found" in err and "internal error" not in err, err
    assert code in (0, 1)


def test_a_mesh_over_the_bound_is_v132_before_it_is_read(tmp_path, monkeypatch, capsys):
    """A 95 MB STL (sparse: it costs no disk) is refused with the bound and the variable
    that raises it; with the bound raised it is handed on."""
    big = tmp_path / "big.stl"
    with open(big, "wb") as fh:
        fh.truncate(95 << 20)
    path = tmp_path / "one.urdf"
    path.write_text(ONE_JOINT.format(mesh="big.stl"))
    with pytest.raises(AouError) as err:
        scene_xml(read_urdf(str(path)), [], None, visuals=False)
    (d,) = err.value.diagnostics
    assert d.code == "V132" and "95.0 MB" in d.message and "mesh" in d.message
    assert d.fields["variable"] == "AOU_MAX_INPUT_MB" and "AOU_MAX_INPUT_MB" in d.hint
    code = main(["robot", str(path)])
    out = capsys.readouterr().err
    assert code == 2 or code == 1
    assert "V132" in out and "internal error" not in out, out
    monkeypatch.setenv("AOU_MAX_INPUT_MB", "200")
    text, missing = scene_xml(read_urdf(str(path)), [], None, visuals=False)
    assert missing == [] and str(big) in text


def test_a_one_joint_urdf_whose_mesh_is_a_folder_gets_a_diagnostic(tmp_path, capsys):
    (tmp_path / "pk" / "pkg" / "m.stl").mkdir(parents=True)
    path = tmp_path / "one.urdf"
    path.write_text(ONE_JOINT.format(mesh="package://pkg/m.stl"))
    main(["robot", str(path), "--package-dir", str(tmp_path / "pk")])
    err = capsys.readouterr().err
    assert "internal error" not in err and "Traceback" not in err, err
    assert " V109 " in err and "package://pkg/m.stl" in err, err
    assert Path(path).read_text() == ONE_JOINT.format(mesh="package://pkg/m.stl")
