"""`aouc lint` and `aouc rules` as a user meets them: output forms and exit codes."""

import json
import subprocess
import sys

import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, main
from aou_dsl.core.diagnostics import RULES
from tests.conftest import BEHAVIOURS, INVALID


def test_shipped_behaviours_lint_clean_even_strict(capsys):
    assert main(["lint", str(BEHAVIOURS), "--strict"]) == EXIT_OK
    assert "5 files checked: 0 errors, 0 warnings" in capsys.readouterr().err


def test_text_form_has_location_code_source_line_and_caret(capsys):
    assert main(["lint", str(INVALID / "invalid_wrong_dimension.aou")]) == EXIT_ERRORS
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith("invalid_wrong_dimension.aou:2:7: V102 [error] pause duration: "
                           "expected a duration (s, ms), found a length `3m`")
    assert out[1].endswith("| pause 3m")
    assert out[2].index("^") == out[1].index("3m")


def test_json_form_is_machine_readable(capsys):
    main(["lint", str(INVALID / "invalid_unknown_robot.aou"), "--format", "json"])
    data = json.loads(capsys.readouterr().out)
    (d,) = data["files"][0]["diagnostics"]
    assert d["code"] == "V109" and d["line"] == 2 and d["col"] == 7
    assert d["fields"]["found"] == "panda2"


def test_github_form_is_an_annotation(capsys):
    main(["lint", str(INVALID / "invalid_unknown_statement.aou"), "--format", "github"])
    line = capsys.readouterr().out.strip()
    assert line.startswith("::error file=") and ",line=2,col=1," in line
    assert "title=V101 unknown-statement::" in line


def test_strict_turns_warnings_into_failure(tmp_path):
    f = tmp_path / "m.aou"
    f.write_text("behaviour m : fearful\napproach a=0.1\n")
    assert main(["lint", str(f)]) == EXIT_OK
    assert main(["lint", str(f), "--strict"]) == EXIT_ERRORS


def test_mismatch_warning_names_inferred_point_and_pulling_primitives(capsys, tmp_path):
    f = tmp_path / "m.aou"
    f.write_text("behaviour m : fearful\napproach a=0.1\n")
    main(["lint", str(f), "--format", "json"])
    (d,) = json.loads(capsys.readouterr().out)["files"][0]["diagnostics"]
    assert d["code"] == "M201" and d["fields"]["inferred"] == "confident"
    assert "approach" in d["hint"] and "C=+1.00" in d["message"]


def test_effort_line_contradicting_declared_state_warns(tmp_path):
    from aou_dsl.lang.linter import lint_file

    f = tmp_path / "e.aou"
    f.write_text("behaviour e : fearful\neffort W=-1 T=-1 S=-1 F=1\n"
                 "approach a=0.05\npause 1.25s x4\nretreat 6cm a=2\nshiver 6deg\n")
    codes = [d.code for d in lint_file(str(f)).diagnostics]
    assert "M202" in codes and "M201" not in codes


def test_missing_path_is_an_io_error_exit_2(capsys):
    assert main(["lint", "does/not/exist.aou"]) == EXIT_USAGE
    assert "I501" in capsys.readouterr().err


def test_strict_never_hides_a_2(tmp_path):
    assert main(["lint", str(BEHAVIOURS), "missing.aou", "--strict"]) == EXIT_USAGE


def test_folder_is_searched_recursively(tmp_path, capsys):
    (tmp_path / "a" / "b").mkdir(parents=True)
    (tmp_path / "a" / "b" / "deep.aou").write_text("pause 3m\n")
    (tmp_path / "top.aou").write_text("approach\n")
    assert main(["lint", str(tmp_path)]) == EXIT_ERRORS
    assert "deep.aou:1:7: V102" in capsys.readouterr().out


def test_empty_folder_is_a_usage_problem(tmp_path):
    assert main(["lint", str(tmp_path)]) == EXIT_USAGE


def test_undecodable_file_is_a_diagnostic_not_a_crash(tmp_path, capsys):
    f = tmp_path / "bin.aou"
    f.write_bytes(b"\xff\xfe\x00pause")
    assert main(["lint", str(f)]) == EXIT_USAGE
    assert "I501" in capsys.readouterr().out


def test_usage_error_exits_2():
    with pytest.raises(SystemExit) as info:
        main(["lint", "--format", "xml", "x.aou"])
    assert info.value.code == EXIT_USAGE


def test_rules_lists_every_code_and_explains_one(capsys):
    assert main(["rules"]) == EXIT_OK
    out = capsys.readouterr().out
    assert all(code in out for code in RULES)
    assert main(["rules", "v102"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "wrong-unit-dimension" in out and "what:" in out and "example:" in out
    assert main(["rules", "Z999"]) == EXIT_USAGE


def test_every_rule_has_kebab_name_and_texts():
    import re

    for code, r in RULES.items():
        assert re.fullmatch(r"[SVMCRIDEK]\d{3}", code)
        assert re.fullmatch(r"[a-z]+(-[a-z]+)*", r.name)
        assert r.what and r.why and r.example


def test_lint_imports_no_heavy_dependency():
    """`import aou_dsl`, `aouc --help` and the lint path stay clear of pinocchio, toppra, pybullet,
    matplotlib (and numpy): linting a folder in CI has to start fast."""
    code = ("import sys, aou_dsl, aou_dsl.cli.commands as c\n"
            "try:\n    c.main(['--help'])\nexcept SystemExit:\n    pass\n"
            f"c.main(['lint', r'{BEHAVIOURS}'])\n"
            "heavy = {'pinocchio', 'toppra', 'pybullet', 'matplotlib', 'numpy', 'pygls',\n"
            "         'lsprotocol'}\n"
            "heavy &= set(sys.modules)\n"
            "print(sorted(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
