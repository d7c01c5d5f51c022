#!/usr/bin/env bash
# The whole test suite, as CI runs it: installs what is missing, then
#   1. every test under test/ with Debian's Python 3 and pyparsing 3 (ROS tests start their own masters);
#   2. the pure tests again with pyparsing 2.4.7 (Ubuntu 20.04 / ROS Noetic), in a venv;
#   3. a Python 3.8 syntax check of the package (vermin), in the same venv.
# Usage: tools/test.sh [extra pytest args]
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/deps.sh
rubass_install_deps

PY=/usr/bin/python3
VENV=.venv-compat
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c 'import pyparsing, vermin; assert pyparsing.__version__ == "2.4.7"' 2>/dev/null; then
  rm -rf "$VENV"
  $PY -m venv --system-site-packages "$VENV"
  "$VENV/bin/pip" install -q --disable-pip-version-check "pyparsing==2.4.7" "vermin==1.6.0"
fi

export PYTHONDONTWRITEBYTECODE=1
echo "== Python 3.8 compatibility (vermin)"
"$VENV/bin/vermin" -q --no-tips --target=3.8- --violations --eval-annotations --backport typing \
  --exclude-regex '\.venv' rubass rubass_experiments scripts bench test

echo "== pure tests with pyparsing 2.4.7"
"$VENV/bin/python" -m pytest -q -p no:cacheprovider -m "not ros" test/unit

echo "== all tests (Debian Python $($PY -c 'import sys; print(sys.version.split()[0])'), pyparsing $($PY -c 'import pyparsing; print(pyparsing.__version__)'))"
$PY -m pytest -p no:cacheprovider "$@" test
