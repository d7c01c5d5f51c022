"""Usage errors of the command line name the command and the option (acceptance findings)."""
import os
import subprocess
import sys

import pytest

from conftest import ROOT


def rubass(*args):
    return subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)


def test_an_unknown_option_is_named_by_its_commands_usage():
    out = rubass("check", "--nope", "config/kobuki.rbs")
    assert out.returncode == 2
    assert "rubass check: error: unrecognized arguments: --nope" in out.stderr, out.stderr


@pytest.mark.parametrize("args,error", [
    (("--urdf", "/nonexistent.urdf"), "rubass: error: --urdf needs --bag, --live or --model"),
    (("--master", "http://localhost:1"), "rubass: error: --master needs --live (it names the master to ask)"),
])
def test_a_model_option_without_its_source_is_an_error_not_ignored(args, error):
    out = rubass("check", *args, os.path.join("config", "kobuki.rbs"))
    assert out.returncode == 2 and error in out.stderr, out.stdout + out.stderr


def test_the_top_level_help_names_every_command():
    out = rubass("--help")
    for word in ("check", "fmt", "replay", "test", "report", "model", "experiments"):
        assert word in out.stdout
    assert "rule tests" in out.stdout and "report" in out.stdout.split("positional")[0]
