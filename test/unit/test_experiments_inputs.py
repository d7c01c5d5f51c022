"""`rubass experiments` with inputs it cannot use (an acceptance sweep): an --out it cannot write gave a
traceback, a table.json it could not write lost the finished runs' table, a row's missing spec broke
the runs with a traceback (Frobit) or read as a missed stop (Kobuki), and a row named twice ran twice
into one folder, its table.json pointing both runs at the second one's bag."""
import argparse
import os
import shutil

import pytest

from rubass_experiments import command, runner, table
from rubass_experiments.procs import Supervisor
from rubass_experiments.rows import row

pytestmark = pytest.mark.skipif(not os.path.exists("/usr/bin/rosmaster"), reason="`experiments` needs ROS 1")


def _args(out, *only, reps=1):
    return argparse.Namespace(reps=reps, only=list(only), out=str(out))


def test_an_out_folder_it_cannot_write_is_said_before_any_run(tmp_path, capsys, monkeypatch):
    ran = []
    monkeypatch.setattr(command, "_run", lambda *a: ran.append(a) or 0)
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert command.run(_args(afile, "Boundary")) == 1
    err = capsys.readouterr().err
    assert f"rubass experiments: error: cannot write the results to {afile} (--out): " in err, err
    assert "Traceback" not in err and ran == []
    assert command.run(_args(afile / "x", "Boundary")) == 1
    assert "Not a directory" in capsys.readouterr().err
    if os.geteuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o555)
        assert command.run(_args(ro / "out", "Boundary")) == 1
        assert "Permission denied" in capsys.readouterr().err


def test_a_table_json_it_cannot_write_still_prints_the_table_and_exits_1(tmp_path, capsys, monkeypatch):
    (tmp_path / "table.json").mkdir()  # e.g. a folder by that name
    monkeypatch.setattr(runner, "main_loop", lambda rows, reps, out, sup: runner.Outcome([]))
    monkeypatch.setattr(table, "plot", lambda data, png: None)
    assert command._run([row("Boundary")], 1, str(tmp_path), Supervisor(signals=False)) == 1
    out, err = capsys.readouterr()
    assert "Boundary" in out and "table: (not written)" in out, out
    assert f"rubass experiments: error: cannot write {tmp_path / 'table.json'}: Is a directory" in err, err


def test_a_rows_missing_or_broken_spec_is_said_before_any_run(tmp_path, capsys, monkeypatch):
    config = tmp_path / "config"
    shutil.copytree(runner.CONFIG, config)
    os.remove(config / "frobit.rbs")
    (config / "kobuki.rbs").write_text((config / "kobuki.rbs").read_text() + "\nif (nosuch.rule) then { stop; }\n")
    monkeypatch.setattr(runner, "CONFIG", str(config))
    ran = []
    monkeypatch.setattr(command, "_run", lambda *a: ran.append(a) or 0)
    assert command.run(_args(tmp_path / "out", "E_L", "Boundary", "Max speed")) == 1
    err = capsys.readouterr().err
    assert "rubass experiments: error: row E_L: config/frobit.rbs cannot be used:" in err, err
    assert "cannot read spec" in err and "no such file" in err, err
    assert "rubass experiments: error: row Boundary: config/kobuki.rbs cannot be used:" in err, err
    assert "error: " in err.split("row Boundary")[1] and "nosuch" in err, err
    assert ran == [] and "Traceback" not in err
    assert runner.spec_problems([row("Spin (0 s)")]) == []  # its own spec, untouched


def test_a_row_named_twice_runs_once(tmp_path, monkeypatch):
    ran = []
    monkeypatch.setattr(command, "_run", lambda rows, reps, out, sup: ran.append([r.name for r in rows]) or 0)
    assert command.run(_args(tmp_path / "out", "Spin (0 s)", "spin (0 S)", "Boundary")) == 0
    assert ran == [["Spin (0 s)", "Boundary"]]
