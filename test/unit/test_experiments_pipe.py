"""`tools/demo.sh | tee log` and Ctrl-C: the signal ends tee too, so the table cannot be printed.
Acceptance finding: BrokenPipeError while printing, exit 1, and no table.json. The table is now saved
first, and a reader that is gone silences the output without changing the exit status."""
import io
import json
import os
import signal
import sys

from rubass_experiments import command, runner
from rubass_experiments.rows import ROWS


def broken_pipe():
    r, w = os.pipe()
    os.close(r)
    return io.TextIOWrapper(os.fdopen(w, "wb"), encoding="utf-8")


def test_an_interrupted_experiment_saves_its_table_and_exits_130_with_its_readers_gone(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "main_loop", lambda rows, reps, out, sup: runner.Outcome([], signal.SIGINT))
    out, err = broken_pipe(), broken_pipe()
    monkeypatch.setattr(sys, "stdout", out)
    monkeypatch.setattr(sys, "stderr", err)
    try:
        status = command._run([ROWS[0]], 2, str(tmp_path), None)
    finally:
        monkeypatch.undo()
    assert status == 130
    data = json.load(open(tmp_path / "table.json"))
    assert data["interrupted"]["signal"] == "SIGINT" and data["interrupted"]["finished_runs"] == 0
    out.close()  # the interpreter's last flush: to /dev/null now, not an error
    err.close()


def test_an_interrupted_experiment_removes_an_earlier_runs_plot(tmp_path, monkeypatch, capsys):
    """An acceptance sweep: after a full run, an interrupted one left the full run's table.png beside
    its own partial table.json (the plot disagreed with the table)."""
    (tmp_path / "table.png").write_bytes(b"\x89PNG an earlier run")
    monkeypatch.setattr(runner, "main_loop", lambda rows, reps, out, sup: runner.Outcome([], signal.SIGINT))
    assert command._run([ROWS[0]], 2, str(tmp_path), None) == 130
    assert not (tmp_path / "table.png").exists()
    assert "(not drawn: interrupted)" in capsys.readouterr().out


def test_a_stop_before_its_due_instant_is_no_negative_delay(monkeypatch):
    """An acceptance sweep: on a loaded machine the demo printed (b) = -10.3 ms: the recorder, whose
    receive times give the due instant, got the data after the base got the stop."""
    row = ROWS[0]
    result = runner.RunResult(row.name, 0, False, events=[{"event": row.until, "wall": 100.000},
                                                           {"event": row.origin, "wall": 99.000}])
    monkeypatch.setattr(runner, "_due_from_bag", lambda *a, **k: 100.0103)
    runner._measure(row, result, "spec.rbs", 99.0)
    assert result.stopped and result.a == 1.0
    assert result.b is None and "recorder received the data 10.3 ms after the stop" in result.error
    monkeypatch.setattr(runner, "_due_from_bag", lambda *a, **k: 99.998)
    result = runner.RunResult(row.name, 0, False, events=result.events)
    runner._measure(row, result, "spec.rbs", 99.0)
    assert result.b == 100.000 - 99.998 and not result.error
