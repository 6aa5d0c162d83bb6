#!/usr/bin/env bash
# HTTP round trips on loopback, with the server's defaults: POST /v1/sweet-spot
# (the contract's example scene) with keep-alive at 1, 8, 64 and 256
# connections, measured by wrk (Debian's package) against the Release
# sweetspot-server; side by side in the same run, Debian's nginx serving the
# same JSON answer as a static file (GET, keep-alive) at 8, 64 and 256
# connections; then the fairness runs (64 and 256 keep-alive clients for 10 s
# each: answers per client and waits, from tests/server/serving_test.cpp).
# Prints everything, and with --write also docs/http-bench.md. With --pairs N, N more
# alternated pairs at 8 connections (sweetspot, then nginx, each `seconds` long) and their
# median ratio: on a shared machine nginx's rate moves with the load from run to run.
#
#   bench/http_bench.sh [--write] [--seconds N] [--pairs N] [--build-dir DIR]
#
# The server and wrk share the machine (2 cores here), so the figures are a
# lower bound of what a dedicated server does; run it on an idle machine.
# Targets (issue 8): >= 10,000 requests/s at 8 connections with p99 <= 5 ms;
# (issue 14): at 8 connections at least half of nginx's static rate, and at 256
# connections p99 <= 20 ms with no connection starved.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=10
build=build
write=0
pairs=0
while [ $# -gt 0 ]; do
  case "$1" in
    --write) write=1 ;;
    --seconds) seconds="$2"; shift ;;
    --pairs) pairs="$2"; shift ;;
    --build-dir) build="$2"; shift ;;
    *) echo "usage: bench/http_bench.sh [--write] [--seconds N] [--pairs N] [--build-dir DIR]" >&2; exit 2 ;;
  esac
  shift
done
command -v wrk >/dev/null || { echo "http_bench.sh: needs wrk (scripts/install-deps.sh)" >&2; exit 1; }
[ -x /usr/sbin/nginx ] || { echo "http_bench.sh: needs nginx (scripts/install-deps.sh)" >&2; exit 1; }
server="$build/server/sweetspot-server"
tests="$build/tests/server_tests"
if [ ! -x "$server" ] || [ ! -x "$tests" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j"$(nproc)" --target sweetspot-server server_tests
fi

work="$(mktemp -d)"
chmod 755 "$work"  # nginx's workers run as an unprivileged user
pid=""
nginx_pid=""
cleanup() {
  if [ -n "$pid" ]; then kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; fi
  if [ -n "$nginx_pid" ]; then
    kill -QUIT "$nginx_pid" 2>/dev/null || true
    wait "$nginx_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT
cat >"$work/post.lua" <<'EOF'
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = '{"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366, "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0, "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]}'
-- Count non-2xx answers: they must be zero.
local bad = 0
response = function(status, headers, body)
  if status ~= 200 then bad = bad + 1 end
end
done = function(summary, latency, requests)
  io.write(string.format("RESULT %d %.1f %.3f %.3f %.3f %d %d\n",
    summary.requests, summary.requests / (summary.duration / 1e6),
    latency:percentile(50) / 1000, latency:percentile(90) / 1000,
    latency:percentile(99) / 1000, summary.errors.status + summary.errors.connect +
    summary.errors.read + summary.errors.write + summary.errors.timeout, bad))
end
EOF

# The server's defaults (8 light workers, one compute worker per core, 256
# connections) but one: wrk is one client address, so it may hold all 256 connections;
# only the access log is off, as wrk's millions of lines would measure the terminal.
source bench/loopback_servers.sh  # (the working directory is the repository)
start_sweetspot "$server" "$work" "$work/jobs.db"
url="http://127.0.0.1:$port/v1/sweet-spot"
wrk -t1 -c1 -d1s -s "$work/post.lua" "$url" >/dev/null  # warm-up

# nginx: the same JSON answer as a static file, keep-alive, no access log.
body="$(sed -n "s/^wrk.body = '\(.*\)'$/\1/p" "$work/post.lua")"
start_nginx_static "$work" "$body" "$url"
sed -e 's/^wrk.method.*//' -e 's/^wrk.headers.*//' -e 's/^wrk.body.*//' "$work/post.lua" >"$work/get.lua"
wrk -t1 -c1 -d1s -s "$work/get.lua" "$static_url" >/dev/null  # warm-up

# One wrk run of `seconds`: prints "requests/s p50 p90 p99 errors non_200".
measure() {
  local c="$1" script="$2" target="$3" threads
  threads=$(( c < 2 ? 1 : 2 ))
  wrk -t"$threads" -c"$c" -d"${seconds}s" -s "$script" "$target" | grep '^RESULT' | cut -d' ' -f3-
}

rows=()
declare -A service_rps static_rps service_p99 static_p99
# Measures `c` connections of one server, prints the row and keeps it for the file.
run_row() {
  local label="$1" title="$2" c="$3" script="$4" target="$5"
  read -r rps p50 p90 p99 errors bad <<<"$(measure "$c" "$script" "$target")"
  printf '%-10s  %11d  %10.0f  %6.3f  %6.3f  %6.3f  %6d  %7d\n' \
    "$label" "$c" "$rps" "$p50" "$p90" "$p99" "$errors" "$bad"
  rows+=("| $title | $c | $(printf '%.0f' "$rps") | $p50 | $p90 | $p99 | $errors | $bad |")
}
echo "server      connections  requests/s  p50_ms  p90_ms  p99_ms  errors  non_200"
for c in 1 8 64 256; do
  run_row sweetspot "sweetspot, POST /v1/sweet-spot" "$c" "$work/post.lua" "$url"
  service_rps[$c]="$rps"
  service_p99[$c]="$p99"
  if [ "$c" -ge 8 ]; then
    run_row nginx "nginx, GET of the same answer as a file" "$c" "$work/get.lua" "$static_url"
    static_rps[$c]="$rps"
    static_p99[$c]="$p99"
  fi
done
ratios=()
for c in 8 64 256; do
  ratio="$(awk -v a="${service_rps[$c]}" -v b="${static_rps[$c]}" 'BEGIN { printf "%.2f", a / b }')"
  echo "sweetspot / nginx static at $c connections: $ratio"
  ratios+=("| $c | $(printf '%.0f' "${service_rps[$c]}") | $(printf '%.0f' "${static_rps[$c]}") | $ratio | ${service_p99[$c]} | ${static_p99[$c]} |")
done

# Alternated pairs at 8 connections: sweetspot, then nginx, `pairs` times; the median ratio.
pair_rows=()
pair_ratios=()
for i in $(seq 1 "$pairs"); do
  load="$(cut -d' ' -f1 /proc/loadavg)"
  read -r a _ <<<"$(measure 8 "$work/post.lua" "$url")"
  read -r b _ <<<"$(measure 8 "$work/get.lua" "$static_url")"
  ratio="$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", a / b }')"
  echo "pair $i at 8 connections: sweetspot $(printf '%.0f' "$a")/s, nginx $(printf '%.0f' "$b")/s, ratio $ratio, load $load"
  pair_rows+=("| $i | $(printf '%.0f' "$a") | $(printf '%.0f' "$b") | $ratio | $load |")
  pair_ratios+=("$ratio")
done
median=""
if [ "$pairs" -gt 0 ]; then
  median="$(printf '%s\n' "${pair_ratios[@]}" | sort -n |
    awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else printf "%.2f", (v[NR / 2] + v[NR / 2 + 1]) / 2 }')"
  echo "median ratio of $pairs alternated pairs at 8 connections: $median"
fi

# Fairness: the serving tests' 64- and 256-client runs, against the same build.
kill "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
pid=""
fairness="$("$tests" --gtest_filter='ServingTest.SixtyFour*:ServingTest.TwoHundredFiftySix*' 2>&1 |
  sed -n 's/^fairness: //p')"
echo "$fairness"

if [ "$write" -eq 1 ]; then
  {
    echo "# HTTP round trips on loopback: sweetspot-server against nginx"
    echo
    echo "Generated by \`bench/http_bench.sh --write --seconds $seconds$( [ "$pairs" -gt 0 ] && echo " --pairs $pairs")\` on $(date -u +%Y-%m-%d)"
    echo "($(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), one run:"
    echo "sweetspot-server Release with its defaults (8 light workers, one compute worker per core,"
    echo "256 connections; \`--access-log 0\`), and Debian's nginx $(/usr/sbin/nginx -v 2>&1 | sed 's/.*nginx\///')"
    echo "(\`worker_processes auto\`, no access log) serving the service's answer to the same request as a"
    echo "static file. wrk (Debian) with 1 thread for 1 connection and 2 threads otherwise, keep-alive,"
    echo "${seconds} s per row, after a 1 s warm-up. The body is the contract's example scene asking for"
    echo "\`max_exit_speed\`. Server and load generator share the machine's cores."
    echo
    echo "| server | connections | requests/s | p50 ms | p90 ms | p99 ms | socket errors | non-200 |"
    echo "|---|---|---|---|---|---|---|---|"
    printf '%s\n' "${rows[@]}"
    echo
    echo "## Against nginx serving the answer as a file"
    echo
    echo "| connections | sweetspot requests/s | nginx requests/s | ratio | sweetspot p99 ms | nginx p99 ms |"
    echo "|---|---|---|---|---|---|"
    printf '%s\n' "${ratios[@]}"
    echo
    if [ "$pairs" -gt 0 ]; then
      echo "## Alternated pairs at 8 connections"
      echo
      echo "\`--pairs $pairs\`: sweetspot, then nginx, ${seconds} s each, $pairs times (load average when each"
      echo "pair began); the median ratio is $median."
      echo
      echo "| pair | sweetspot requests/s | nginx requests/s | ratio | load average |"
      echo "|---|---|---|---|---|"
      printf '%s\n' "${pair_rows[@]}"
      echo
    fi
    echo "## Fairness: every keep-alive client served"
    echo
    echo "From \`ServingTest.SixtyFourKeepAliveClientsAreServedFairly\` and"
    echo "\`ServingTest.TwoHundredFiftySixKeepAliveClientsAreAllServedWithinASecond\` (httplib clients in"
    echo "one process, a thread and a keep-alive connection each, posting the example scene in a loop"
    echo "for 10 s; the server with its defaults):"
    echo
    while IFS= read -r line; do echo "- $line"; done <<<"$fairness"
    echo
    echo "Targets: (issue 8) at least 10,000 requests/s at 8 connections with p99 at most 5 ms;"
    echo "(issue 14) at 8 connections at least half of nginx's static rate; at 256 connections p99"
    echo "at most 20 ms with no connection starved (the least served client gets at least a quarter"
    echo "of the mean, every first answer within 100 ms at 64 clients, no wait over 1 s at 256)."
  } >docs/http-bench.md
  echo "wrote docs/http-bench.md" >&2
fi
