#!/usr/bin/env bash
# Installs the Debian packages mpmbench needs (only those missing, with
# apt-get, non-interactively) and builds build/mpmbench. Idempotent: a second
# run finds everything installed and the build up to date.
#   bash scripts/setup.sh               the program: build/ is first configured
#                                       with -DBUILD_TESTING=OFF (the tests need
#                                       GSL, which scripts/test.sh installs)
#   bash scripts/setup.sh --with-tests  the program and the tests (BUILD_TESTING=ON;
#                                       scripts/test.sh runs this)
# An existing build/ keeps its BUILD_TESTING unless --with-tests turns it on.
set -euo pipefail
cd "$(dirname "$0")/.."
with_tests=0
if [ "${1:-}" = --with-tests ]; then with_tests=1; shift; fi

# what building and running need (python3-matplotlib: `matrix report`'s
# figures; openmpi-bin: mpirun for matrices over ranks; libopenblas0: the
# BLAS CHOLMOD runs on); what only testing needs is installed by
# scripts/test.sh
packages=(build-essential cmake python3 python3-matplotlib libhypre-dev libtrilinos-ml-dev libsuitesparse-dev
          libpetsc-real3.18-dev libopenmpi-dev openmpi-bin libjansson-dev libpng-dev libopenblas0)
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

testing=OFF
[ "$with_tests" = 1 ] && testing=ON
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=$testing >/dev/null
elif [ "$with_tests" = 1 ] && ! grep -q '^BUILD_TESTING:BOOL=ON$' build/CMakeCache.txt; then
  cmake -S . -B build -DBUILD_TESTING=ON >/dev/null
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
