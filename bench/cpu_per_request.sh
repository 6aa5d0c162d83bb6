#!/usr/bin/env bash
# The server's CPU time per request (user + system from /proc/PID/stat) over a
# `wrk -t2 -c8` run of the contract's example POST /v1/sweet-spot: steadier than a
# rate on a loaded machine. Alternate two builds to compare them:
#
#   bench/cpu_per_request.sh [SERVER_BINARY] [SECONDS]
#
# Prints: requests, CPU seconds, microseconds per request (and its user and system parts), the
# server's voluntary and involuntary context switches per request (its threads' sums), the load
# average. SWEETSPOT_THREADS sets the light workers as for the server.
set -euo pipefail
cd "$(dirname "$0")/.."
server="${1:-build/server/sweetspot-server}"
seconds="${2:-5}"
work="$(mktemp -d)"
pid=""
cleanup() {
  if [ -n "$pid" ]; then kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
source bench/loopback_servers.sh  # (the working directory is the repository)
start_sweetspot "$server" "$work" none
cat >"$work/post.lua" <<'LUA'
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = '{"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366, "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0, "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]}'
LUA
wrk -t2 -c8 -d1s -s "$work/post.lua" "http://127.0.0.1:$port/v1/sweet-spot" >/dev/null  # warm-up
ticks() { awk '{print $14 + $15, $14}' "/proc/$pid/stat"; }
read -r before user_before <<<"$(ticks)"
read -r vol_before invol_before <<<"$(thread_switches "$pid")"
out="$(wrk -t2 -c8 -d"${seconds}s" -s "$work/post.lua" "http://127.0.0.1:$port/v1/sweet-spot")"
read -r after user_after <<<"$(ticks)"
read -r vol_after invol_after <<<"$(thread_switches "$pid")"
requests="$(echo "$out" | awk '/requests in/ {print $1}')"
non2xx="$(echo "$out" | awk '/Non-2xx/ {print $NF}')"
hz="$(getconf CLK_TCK)"
awk -v r="$requests" -v t="$((after - before))" -v u="$((user_after - user_before))" -v hz="$hz" \
    -v vol="$((vol_after - vol_before))" -v invol="$((invol_after - invol_before))" \
    -v bad="${non2xx:-0}" -v load="$(cut -d' ' -f1 /proc/loadavg)" \
  'BEGIN { printf "requests %d  cpu_s %.2f  us_per_request %.2f (user %.2f, system %.2f)  switches_per_request %.3f voluntary, %.3f involuntary  non2xx %s  load %s\n", r, t / hz, 1e6 * t / hz / r, 1e6 * u / hz / r, 1e6 * (t - u) / hz / r, vol / r, invol / r, bad, load }'
