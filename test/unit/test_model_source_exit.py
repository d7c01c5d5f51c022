"""`rubass check --model`: a model file that cannot be read gives 2, as an unreadable --bag does (docs/model.md)."""
from rubass.cli import main

SPEC = """action primitive stop;
entity base { rules: fast: topic /odom.twist.twist.linear.x > 0.5 m/s; }
if (base.fast) then { stop; }
"""
LIB = "actions:\n  stop: {plugin: log, level: warn}\n"


def spec(write):
    write("lib.yaml", LIB)
    return write("robot.rbs", 'import "lib.yaml";\n' + SPEC)


def test_a_model_file_that_is_not_there_gives_2_with_a_one_line_reason(write, tmp_path, capsys):
    path = str(tmp_path / "nothere.yaml")
    assert main(["check", "--model", path, spec(write)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"rubass: error: {path}: cannot read system model: no such file"]


def test_a_model_path_that_is_a_directory_gives_2(write, tmp_path, capsys):
    (tmp_path / "dir.yaml").mkdir()
    assert main(["check", "--model", str(tmp_path / "dir.yaml"), spec(write)]) == 2
    assert "cannot read system model: it is a directory" in capsys.readouterr().err


def test_a_model_file_with_errors_still_gives_1(write, capsys):
    bad = write("bad.yaml", "topics: 3\n")
    assert main(["check", "--model", bad, spec(write)]) == 1
    err = capsys.readouterr().err
    assert "bad.yaml:1:9: error: 'topics' must be a mapping" in err and "bad.yaml: 1 error" in err
