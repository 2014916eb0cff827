#!/usr/bin/env bash
# One entry point for people and CI:
#   ./dev.sh run [ARGS]   set up (first time only) and open qtanimator (the demo project by default)
#   ./dev.sh test [ARGS]  set up (first time only) and run the whole test suite headless
# Setup installs the system libraries Qt and OpenGL need (Debian / Ubuntu, with apt-get),
# creates .venv beside this file and installs qtanimator into it in editable mode; `test` also
# installs the Khronos glTF validator (npm, tools/gltf-validator) that checks every glTF export.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"

# Runtime libraries for Qt offscreen / xcb and Mesa GL; Xvfb for the GL tests; venv for Python;
# node and npm for the Khronos glTF validator the tests run.
SYSTEM_PACKAGES=(python3-venv python3-pip libglib2.0-0 libgl1 libegl1 libgl1-mesa-dri libxkbcommon0
  libfontconfig1 libdbus-1-3 xvfb xauth libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1
  libxcb-render-util0 libxcb-shape0 libxkbcommon-x11-0 libxcb-xinerama0 libxcb-randr0
  libxcb-image0 libxcb-xfixes0 libxcb-xkb1 libx11-xcb1 fonts-dejavu-core)
# Installed only when there is no node / npm yet: a node from elsewhere (NodeSource's package
# ships its own npm and conflicts with Debian's) is used as it is.
NODE_PACKAGES=(nodejs npm)

node_packages() {
  if command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1; then return; fi
  echo "${NODE_PACKAGES[@]}"
}

need_system_packages() {
  command -v dpkg-query >/dev/null 2>&1 || return 1
  [ -z "$(node_packages)" ] || return 0
  local p
  for p in "${SYSTEM_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || return 0
  done
  return 1
}

install_system_packages() {
  if ! need_system_packages; then return; fi
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "dev.sh: installing system packages with apt-get" >&2
  $sudo apt-get update -qq
  # shellcheck disable=SC2046  # node_packages prints nothing or two package names
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${SYSTEM_PACKAGES[@]}" \
    $(node_packages) >/dev/null
}

setup_venv() {
  # Extras: test (pytest, linters). numba (the compiled cloth kernels) is a dependency; CI also runs
  # the cloth tests without it, QTANIMATOR_NO_NUMBA=1). Exact versions come from
  # constraints.txt; pyproject.toml holds the ranges a user's pip may choose from.
  local extras="$1"
  local python="${PYTHON:-python3}"
  if [ ! -x .venv/bin/python ]; then
    "$python" -m venv .venv
  fi
  local stamp=".venv/.qtanimator-installed-$extras"
  local want
  want="$(cat pyproject.toml setup.py constraints.txt | sha1sum | cut -d' ' -f1)"
  if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    echo "dev.sh: installing qtanimator and its dependencies into .venv" >&2
    .venv/bin/python -m pip install -q --upgrade pip
    .venv/bin/python -m pip install -q -e ".[$extras]" -c constraints.txt
    echo "$want" >"$stamp"
  fi
}

setup_gltf_validator() {
  # The Khronos glTF validator (npm package gltf-validator, pinned in package-lock.json) that
  # tests/gltf_validator.py runs on every glTF export; installed again when the lock changes.
  local dir=tools/gltf-validator
  local stamp="$dir/node_modules/.qtanimator-installed"
  local want
  want="$(sha1sum "$dir/package-lock.json" | cut -d' ' -f1)"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then return; fi
  if ! command -v npm >/dev/null 2>&1; then
    echo "dev.sh: npm not found: the glTF validator checks will be skipped (in CI they fail)" >&2
    return
  fi
  echo "dev.sh: installing the Khronos glTF validator into $dir (npm ci)" >&2
  npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error >/dev/null
  echo "$want" >"$stamp"
}

cmd="${1:-run}"
shift || true
case "$cmd" in
  run)
    install_system_packages
    setup_venv test
    exec .venv/bin/qtanimator "$@"
    ;;
  test)
    install_system_packages
    setup_venv test
    setup_gltf_validator
    exec .venv/bin/python -m pytest "$@"
    ;;
  bench)
    install_system_packages
    setup_venv "test,bench"
    exec .venv/bin/python -m benchmarks "$@"
    ;;
  *)
    echo "usage: ./dev.sh run [PATH] | ./dev.sh test [PYTEST ARGS] | ./dev.sh bench" >&2
    exit 2
    ;;
esac
