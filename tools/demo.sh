#!/usr/bin/env bash
# The demo: installs what is missing, then checks and pretty-prints the example specs.
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/deps.sh
rubass_install_deps
export PYTHONDONTWRITEBYTECODE=1
PY=/usr/bin/python3
for spec in config/kobuki.rbs config/frobit.rbs; do
  echo "== rubass check $spec"
  $PY -m rubass check "$spec"
  echo "== rubass fmt $spec"
  $PY -m rubass fmt "$spec"
done
echo "== rubass check config/fig2.rbs --actions config/fig2_actions.yaml"
$PY -m rubass check config/fig2.rbs --actions config/fig2_actions.yaml
