#!/usr/bin/env bash
# Installs the Debian packages mpmbench needs (only those missing, with
# apt-get, non-interactively) and builds build/mpmbench. Idempotent: a second
# run finds everything installed and the build up to date.
set -euo pipefail
cd "$(dirname "$0")/.."

# what building and running need (python3-matplotlib: `matrix report`'s
# figures); what only testing needs is installed by scripts/test.sh
packages=(build-essential cmake pkg-config python3 python3-matplotlib libhypre-dev libtrilinos-ml-dev libsuitesparse-dev libgsl-dev
          libopenmpi-dev openmpi-bin libjansson-dev libpng-dev libopenblas0)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "setup: installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
# quiet when clean; compiler warnings (there should be none) and failures are shown
log=build/build.log
if ! cmake --build build -j"$(nproc)" -- --no-print-directory >"$log" 2>&1; then
  cat "$log" >&2
  echo "setup: build failed (log: $log)" >&2
  exit 1
fi
if grep -q "warning:" "$log"; then
  grep -A3 "warning:" "$log" >&2
  echo "setup: the build has compiler warnings (log: $log)" >&2
fi
echo "setup: build/mpmbench is ready" >&2
