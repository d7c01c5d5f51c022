#!/usr/bin/env bash
# Installs, only when missing, the Debian packages rubass needs (as rosdep would).
# Sourced by tools/demo.sh and tools/test.sh; safe to run again.
set -euo pipefail

RUBASS_APT_PACKAGES=(
  ros-core python3-rospy python3-roslaunch python3-rosbag rosbash catkin python3-catkin-pkg
  python3-std-msgs python3-geometry-msgs python3-nav-msgs python3-sensor-msgs python3-std-srvs
  python3-diagnostic-msgs python3-pyparsing python3-psutil python3-serial python3-yaml
  python3-matplotlib python3-pytest python3-hypothesis python3-venv python3-pip socat make
  iproute2  # ip netns: the multi-host tests (test/integration/test_multihost.py)
  g++  # catkin_make: CMake's project() needs a C/C++ compiler, which cmake only recommends
  chromium  # rubass report: the report is rendered in headless Chromium by a slow test (and for docs/)
)

rubass_install_deps() {
  local missing=()
  for pkg in "${RUBASS_APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "rubass: installing missing Debian packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null; then sudo="sudo"; else
      echo "rubass: run as root, or install: apt-get install ${missing[*]}" >&2; exit 1
    fi
  fi
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
}
