#!/usr/bin/env bash
# Installs the Debian packages U4D needs. Safe to run twice: installs only
# what is missing. Needs root (or sudo) when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libopencv-dev libopencv-contrib-dev libeigen3-dev libopen3d-dev libtbb-dev
  nlohmann-json3-dev libcli11-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev libboost-graph-dev
  libcpp-httplib-dev chromium zlib1g-dev
  python3-matplotlib  # scripts/results.sh's scaling plot
  clang libclang-rt-14-dev  # the libFuzzer targets (scripts/fuzz.sh, run by CI)
)
# The web viewer (viewer/) needs node and npm; any recent node (>= 18) will
# do, so Debian's packages are installed only when no npm is on the PATH.
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)

# The viewer's npm packages (three.js, esbuild, playwright-core), from
# viewer/package-lock.json; skipped when already installed.
install_viewer_deps() {
  local root
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  if [ -d "$root/viewer/node_modules" ]; then
    echo "setup: viewer npm packages present"
  elif command -v npm >/dev/null 2>&1; then
    echo "setup: installing the viewer's npm packages"
    (cd "$root/viewer" && npm ci --no-audit --no-fund)
  fi
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  install_viewer_deps
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
install_viewer_deps
