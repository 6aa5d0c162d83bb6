#!/usr/bin/env bash
# CPU time per request of the server and of the load generator, for sweetspot-server's
# example POST /v1/sweet-spot and for Debian's nginx serving the same answer as a static file
# (as bench/http_bench.sh), each under `wrk -t2 -c8` for SECONDS after a 1 s warm-up: the
# server's user + system time from /proc/PID/stat (nginx's workers summed), wrk's from
# /usr/bin/time. With both on the same saturated cores the ratio of the rates tends to the
# inverse ratio of the sums (server + wrk), which moves far less with the machine's load
# than the rates do.
#
#   bench/cpu_vs_nginx.sh [SERVER_BINARY] [SECONDS]
#
# Prints one line per server: requests/s, server and wrk microseconds per request, their sum,
# and the server's voluntary and involuntary context switches per request (its threads or
# workers summed); then the ratio of the rates and of the sums, and the load average.
set -euo pipefail
cd "$(dirname "$0")/.."
server="${1:-build/server/sweetspot-server}"
seconds="${2:-5}"
[ -x /usr/sbin/nginx ] || { echo "cpu_vs_nginx.sh: needs nginx (scripts/install-deps.sh)" >&2; exit 1; }
work="$(mktemp -d)"
chmod 755 "$work"  # nginx's workers run as an unprivileged user
pid=""
nginx_pid=""
cleanup() {
  if [ -n "$pid" ]; then kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; fi
  if [ -n "$nginx_pid" ]; then kill -QUIT "$nginx_pid" 2>/dev/null || true; wait "$nginx_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
body='{"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366, "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0, "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]}'
cat >"$work/post.lua" <<LUA
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = '$body'
LUA
: >"$work/get.lua"
source bench/loopback_servers.sh  # (the working directory is the repository)
start_sweetspot "$server" "$work" none
url="http://127.0.0.1:$port/v1/sweet-spot"
start_nginx_static "$work" "$body" "$url"
ticks() {
  local total=0 p
  for p in "$@"; do total=$((total + $(awk '{print $14 + $15}' "/proc/$p/stat"))); done
  echo "$total"
}
# One measured run: prints "requests/s server_us wrk_us voluntary/request involuntary/request".
measure() {
  local target="$1" script="$2" before after out requests wrk_s v0 n0 v1 n1
  shift 2
  wrk -t2 -c8 -d1s -s "$script" "$target" >/dev/null  # warm-up
  before="$(ticks "$@")"
  read -r v0 n0 <<<"$(thread_switches "$@")"
  out="$({ /usr/bin/time -f "WRK_CPU %U %S" wrk -t2 -c8 -d"${seconds}s" -s "$script" "$target"; } 2>&1)"
  after="$(ticks "$@")"
  read -r v1 n1 <<<"$(thread_switches "$@")"
  requests="$(echo "$out" | awk '/requests in/ {print $1}')"
  wrk_s="$(echo "$out" | awk '/WRK_CPU/ {print $2 + $3}')"
  awk -v r="$requests" -v t="$((after - before))" -v hz="$(getconf CLK_TCK)" -v w="$wrk_s" \
      -v s="$seconds" -v v="$((v1 - v0))" -v n="$((n1 - n0))" \
      'BEGIN { printf "%.0f %.2f %.2f %.3f %.3f\n", r / s, 1e6 * t / hz / r, 1e6 * w / r, v / r, n / r }'
}
read -r s_rps s_us s_wrk s_vol s_inv <<<"$(measure "$url" "$work/post.lua" "$pid")"
# shellcheck disable=SC2046
read -r n_rps n_us n_wrk n_vol n_inv <<<"$(measure "$static_url" "$work/get.lua" $(pgrep -P "$nginx_pid"))"
awk -v a="$s_rps" -v b="$s_us" -v c="$s_wrk" -v d="$n_rps" -v e="$n_us" -v f="$n_wrk" \
    -v sv="$s_vol" -v si="$s_inv" -v nv="$n_vol" -v ni="$n_inv" \
    -v load="$(cut -d' ' -f1 /proc/loadavg)" 'BEGIN {
  printf "sweetspot  requests/s %6d  server_us %6.2f  wrk_us %5.2f  sum %6.2f  switches/request %.3f + %.3f\n", a, b, c, b + c, sv, si
  printf "nginx      requests/s %6d  server_us %6.2f  wrk_us %5.2f  sum %6.2f  switches/request %.3f + %.3f\n", d, e, f, e + f, nv, ni
  printf "rate ratio %.2f  inverse ratio of the sums %.2f  load %s\n", a / d, (e + f) / (b + c), load
}'
