"""The benchmarks run (in a short smoke mode) and print the JSON they promise."""
import json
import os
import subprocess
import sys

from conftest import ROOT


def test_parse_check_bench_smoke():
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "parse_check.py"), "--rules", "50",
                          "--repeat", "1"], capture_output=True, text=True, timeout=120, check=True).stdout
    figures = json.loads(out)
    assert figures["rules"] == 50 and figures["parse_and_check_s_median"] > 0
