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
