#!/usr/bin/env bash
# The demo: installs what is missing, then reproduces the paper's experiments (Table 1) on the
# simulated Kobuki-like and Frobit-like robots, in quick mode (2 runs per row instead of the
# paper's 10: about 3 minutes), prints the table beside the paper's figures and names the plot.
# For the full run: /usr/bin/python3 -m rubass experiments --reps 10
set -euo pipefail
# A signal before the experiments start ends the demo with 128 + the signal once the running step
# returns (apt/dpkg is never cut short). The experiments are exec'd, so they receive the signals
# sent to this script themselves, and stop every process they started (docs/experiments.md).
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP
cd "$(dirname "$0")/.."
source tools/deps.sh
rubass_install_deps
export PYTHONDONTWRITEBYTECODE=1
PY=/usr/bin/python3
echo "== rubass check config/kobuki.rbs config/frobit.rbs"
$PY -m rubass check config/kobuki.rbs config/frobit.rbs
echo "== rubass test config/tests/*.test.yaml (the rule tests of both robots, with coverage)"
$PY -m rubass test config/tests/kobuki.test.yaml config/tests/frobit.test.yaml --coverage
mkdir -p out/report
for robot in kobuki frobit; do
  $PY -m rubass report "config/$robot.rbs" --tests "config/tests/$robot.test.yaml" \
    --hazards "config/${robot}_hazards.yaml" -o "out/report/$robot.html"
done
echo "evidence for a certifier (hazards, rules, tests, reaction; docs/report.md): $PWD/out/report/kobuki.html and $PWD/out/report/frobit.html"
echo "  (after the experiments, add a run's timeline and explained stops: --bag out/experiments/runs/ROW/0/run.bag)"
echo "== rubass experiments --reps ${REPS:-2} (quick mode)"
exec $PY -m rubass experiments --reps "${REPS:-2}" --out out/experiments
