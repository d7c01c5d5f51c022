"""Every kind of unusable input file gets one clean error from the CLI, never a traceback."""
import subprocess
import sys

import pytest

from rubass.cli import main

from conftest import ROOT


def run_cli(*args):
    proc = subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=60)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


@pytest.mark.parametrize("content,message", [
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "s.rbs:1:1: error: spec is not UTF-8 text: invalid byte 0x89"),
    (b"const a = 1;\n\x00\x01\x02", "s.rbs:2:1: error: spec is not text: it contains a NUL byte"),
    (b"const a = 1;\nentity \xff", "s.rbs:2:8: error: spec is not UTF-8 text: invalid byte 0xff"),
])
def test_binary_junk(write, capsys, content, message):
    path = write("s.rbs", content)
    assert main(["check", path]) == 1
    assert message in capsys.readouterr().err


def test_empty_file_is_a_valid_empty_spec(write, capsys):
    assert main(["check", write("s.rbs", "")]) == 0


def test_missing_file_and_directory(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nope.rbs"), str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert f"{tmp_path}/nope.rbs: error: cannot read spec: no such file" in err
    assert f"{tmp_path}: error: cannot read spec: it is a directory" in err


def test_huge_file_is_refused_with_its_size(write, capsys):
    path = write("s.rbs", "// x\n" * (1024 * 1024))
    assert main(["check", path]) == 1
    assert "bytes is over the limit of 4194304 bytes" in capsys.readouterr().err


def test_deep_nesting_is_an_error_not_a_crash(write, capsys):
    path = write("s.rbs", "const a = " + "(" * 5000 + "1" + ")" * 5000 + ";\n")
    assert main(["check", path]) == 1
    assert "nested too deeply" in capsys.readouterr().err


def test_exit_codes_and_usage():
    assert run_cli().returncode == 2
    assert run_cli("check").returncode == 2
    assert run_cli("frobnicate").returncode == 2
    ok = run_cli("check", "config/kobuki.rbs", "config/frobit.rbs")
    assert ok.returncode == 0 and "config/kobuki.rbs: ok (4 rules" in ok.stdout
    assert run_cli("check", "config/fig2.rbs", "--actions", "config/fig2_actions.yaml").returncode == 0


def test_check_prints_errors_to_stderr_and_exits_1(write):
    path = write("s.rbs", "entity e { rules: r: topic /x.y > LIMT; }\n")
    proc = run_cli("check", path)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.startswith(f"{path}:1:35: error: undefined name 'LIMT'")


def test_fmt_check_and_write(write):
    path = write("s.rbs", "const  A=1 s ;\n")
    assert run_cli("fmt", path).stdout == "const A = 1 s;\n"
    assert run_cli("fmt", "--check", path).returncode == 1
    assert run_cli("fmt", "--write", path).returncode == 0
    assert open(path).read() == "const A = 1 s;\n"
    assert run_cli("fmt", "--check", path).returncode == 0
    assert run_cli("fmt", "--check", "--write", path).returncode == 2


def test_bad_library_file_never_tracebacks(write):
    write("lib.yaml", b"\xff\xfe junk")
    path = write("s.rbs", 'import "lib.yaml";\n')
    proc = run_cli("check", path)
    assert proc.returncode == 1 and "lib.yaml:1:1: error: action library is not UTF-8 text" in proc.stderr
