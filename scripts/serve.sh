#!/usr/bin/env bash
# Installs what is missing, builds a Release build and starts the server in
# the foreground on 127.0.0.1:8080 with its defaults (Ctrl-C stops it).
# Extra arguments go to sweetspot-server (see `--help`).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs" --target sweetspot-server sweetspot
exec build/server/sweetspot-server "$@"
