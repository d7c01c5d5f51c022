"""Offline replay: the engine run over a recording, with a report, JSON lines and a plot."""
