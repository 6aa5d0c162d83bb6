#!/usr/bin/env bash
# Installs the Debian 12 packages sweetspot needs to build, run and test.
# Idempotent: runs `apt-get update` and `apt-get install` only when a package
# is missing, and does nothing at all when everything is present.
# Must run as root (or with sudo available) on Debian 12 (bookworm).
#
#   scripts/install-deps.sh            build, test and run (the default)
#   scripts/install-deps.sh --runtime  only what the built executables need
set -euo pipefail

if [ "${1:-}" = "--runtime" ]; then
  packages=(ca-certificates curl libnlopt-cxx0 coinor-libipopt1v5 libcpp-httplib0.11 libsqlite3-0 libpq5)
else
  packages=(
    cmake g++ make pkg-config ca-certificates curl
    # faster builds (cmake/BuildSpeed.cmake): Ninja, ccache for every compilation, lld links
    ninja-build ccache lld
    libeigen3-dev libnlopt-cxx-dev coinor-libipopt-dev
    libcpp-httplib-dev nlohmann-json3-dev
    libgtest-dev libgmock-dev libbenchmark-dev libboost-dev libsqlite3-dev
    # jobs shared by replicas (libpq), and a throw-away PostgreSQL server for its tests
    libpq-dev postgresql
    # fuzzing (scripts/fuzz.sh): clang with libFuzzer and its sanitizer runtimes
    clang clang-14 libclang-rt-14-dev llvm-14
    # HTTP benchmark (bench/http_bench.sh); nginx also for the test of docker/nginx.conf
    wrk nginx
    # a single-node Slurm for the sharded-sweep test (scripts/slurm-smoke.sh)
    slurm-wlm munge bc
    # the Python client's test (clients/python/): the interpreter and its standard library
    python3
    # browser tests of the design explorer (headless, driven by playwright-core)
    chromium
  )
  # The explorer's bundle is built with Node.js and npm. Use the machine's own
  # if it has one (e.g. NodeSource's nodejs ships npm); otherwise Debian's.
  if ! command -v npm >/dev/null 2>&1; then
    packages+=(nodejs npm)
  fi
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
