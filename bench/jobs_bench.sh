#!/usr/bin/env bash
# Jobs on one process against replicas sharing PostgreSQL, on this machine:
#   1. the round trip of a quick job (POST /v1/jobs of /v1/bat/properties, then
#      GET /v1/jobs/{id} until done): median and p95 over 200 jobs, with the
#      embedded SQLite store and with PostgreSQL (a throw-away cluster, as in
#      the tests);
#   2. the time to finish 8 slow jobs (the 400-design Hertz sweep of the job
#      tests) posted at once: one process with SQLite and --job-workers 2, then
#      2 replicas on PostgreSQL with --job-workers 1 each (the same 2 workers).
# Prints a table; the README's "Scaling out" quotes it.
#
# With --memory "N ...": instead, the server's peak resident memory (VmHWM of
# /proc/<pid>/status, reset through /proc/<pid>/clear_refs before each phase) while an
# N-design /v1/explore job (FORMAT: json by default, or csv or ndjson; the closed-form
# max_exit_speed over a grid of cor x bat speed) runs and while its result is fetched, with
# SQLite and with PostgreSQL, one job at a time (docs/benchmarks.md, "Issue 38: bounded job
# memory").
#
#   bench/jobs_bench.sh [--build-dir DIR] [--memory "1000000 10000000" [--format FORMAT]]
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
memory=""
format=json
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build="$2"; shift 2 ;;
    --memory) memory="$2"; shift 2 ;;
    --format) format="$2"; shift 2 ;;
    *) echo "jobs_bench.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
server="$PWD/$build/server/sweetspot-server"
[ -x "$server" ] || { echo "jobs_bench.sh: build $server first" >&2; exit 1; }
bin=$(ls -d /usr/lib/postgresql/*/bin | head -n1)
[ -x "$bin/initdb" ] || { echo "jobs_bench.sh: needs Debian's postgresql" >&2; exit 1; }

work=$(mktemp -d /tmp/sweetspot-jobs-bench-XXXXXX)
as_pg() { if [ "$(id -u)" = 0 ]; then runuser -u postgres -- "$@"; else "$@"; fi; }
# stop_all: stops every server started so far.
stop_all() {
  for f in "$work"/*.pid; do [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null; rm -f "$f"; done
  sleep 0.5
}
cleanup() {
  stop_all
  [ -f "$work/pg/postmaster.pid" ] && as_pg "$bin/pg_ctl" -D "$work/pg" -m fast stop >/dev/null 2>&1
  rm -rf "$work"
}
trap cleanup EXIT
[ "$(id -u)" = 0 ] && chown postgres "$work"
pg_port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
as_pg "$bin/initdb" -D "$work/pg" -A trust -U postgres --no-sync >/dev/null
as_pg "$bin/pg_ctl" -D "$work/pg" -w -l "$work/pg.log" start \
  -o "-p $pg_port -k $work -c listen_addresses=127.0.0.1" >/dev/null
uri="postgresql://postgres@127.0.0.1:$pg_port/postgres"

# start NAME ARGS...: starts a server on a free port, prints its port (its pid
# goes to NAME.pid: this runs in a command substitution's subshell).
start() {
  local log="$work/$1.log" pidfile="$work/$1.pid"; shift
  "$server" --port 0 --no-access-log "$@" >/dev/null 2>"$log" &
  echo $! >"$pidfile"
  for _ in $(seq 200); do
    port=$(sed -n 's/.*listening on 127.0.0.1:\([0-9]*\).*/\1/p' "$log")
    [ -n "$port" ] && { echo "$port"; return; }
    sleep 0.05
  done
  echo "jobs_bench.sh: server did not start: $(cat "$log")" >&2; exit 1
}

python_bench() {
  python3 - "$@" <<'PY'
import json, sys, time, statistics, urllib.request
mode, ports = sys.argv[1], [int(p) for p in sys.argv[2].split(",")]
def call(port, method, path, body=None):
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=300) as r:
        return json.load(r)
def wait(port, job_id):
    while True:
        s = call(port, "GET", f"/v1/jobs/{job_id}")
        if s["state"] in ("done", "failed", "cancelled"):
            return s
        time.sleep(0.002)
if mode == "quick":
    times = []
    for i in range(200):
        t = time.perf_counter()
        j = call(ports[i % len(ports)], "POST", "/v1/jobs",
                 {"path": "/v1/bat/properties", "body": {"bat": {"preset": "paper-wood"}}})
        wait(ports[(i + 1) % len(ports)], j["id"])
        times.append((time.perf_counter() - t) * 1e3)
    times.sort()
    print(f"{statistics.median(times):.1f} ms median, {times[int(0.95 * len(times))]:.1f} ms p95")
else:
    sweep = {"bat": {"preset": "paper-wood",
                     "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
             "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 20},
                            {"path": "fill.diameter_m", "min": 0.01, "max": 0.03, "count": 20}],
             "outputs": ["max_exit_speed"], "options": {"model": "hertz"}}
    t = time.perf_counter()
    ids = [call(ports[0], "POST", "/v1/jobs", {"path": "/v1/explore", "body": sweep})["id"]
           for _ in range(8)]
    for job_id in ids:
        assert wait(ports[-1], job_id)["state"] == "done"
    print(f"{time.perf_counter() - t:.2f} s for 8 sweeps")
PY
}

# memory_bench PORT PID DESIGNS: one explore job, its result fetched; prints the table's cells.
memory_bench() {
  python3 - "$@" "$format" <<'PY'
import json, sys, time, urllib.request
port, pid, n, fmt = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
def peak_mb():
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmHWM:"): return int(line.split()[1]) / 1024
def reset():  # the peak back to the current resident memory (Linux >= 4.0)
    with open(f"/proc/{pid}/clear_refs", "w") as f: f.write("5")
    return peak_mb()
def call(method, path, body=None):
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=3600) as r: return json.load(r)
side = 1000
sweep = {"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed"], "format": fmt,
         "parameters": [{"path": "cor", "min": 0.4, "max": 0.6, "count": side},
                        {"path": "swing.bat_speed_mps", "min": 25, "max": 35, "count": n // side}]}
idle = reset(); t = time.time()
job = call("POST", "/v1/jobs", {"path": "/v1/explore", "body": sweep})
while (state := call("GET", f"/v1/jobs/{job['id']}"))["state"] in ("queued", "running"):
    time.sleep(0.5)
assert state["state"] == "done", state
run_s, run_peak = time.time() - t, peak_mb()
reset(); t = time.time(); size = 0
with urllib.request.urlopen(f"http://127.0.0.1:{port}/v1/jobs/{job['id']}/result", timeout=3600) as r:
    while (piece := r.read(1 << 20)): size += len(piece)
fetch_s, fetch_peak = time.time() - t, peak_mb()
call("DELETE", f"/v1/jobs/{job['id']}")
print(f"{size / 1e6:.0f} MB | {idle:.0f} MB | {run_peak:.0f} MB ({run_s:.1f} s) | "
      f"{fetch_peak:.0f} MB ({fetch_s:.1f} s)")
PY
}

if [ -n "$memory" ]; then
  echo "| designs ($format) | store | result | VmRSS idle | VmHWM running (time) | VmHWM fetching (time) |"
  echo "|---|---|---|---|---|---|"
  for n in $memory; do
    limits=(--max-batch-samples "$n" --job-max-result-bytes 1000000000000 --job-max-time-s 36000)
    p=$(start sqlite --jobs-db "$work/jobs.db" --jobs-db-max-bytes 0 "${limits[@]}")
    echo "| $n | SQLite | $(memory_bench "$p" "$(cat "$work/sqlite.pid")" "$n") |"
    stop_all; rm -f "$work"/jobs.db*
    p=$(start pg --jobs-db "$uri" "${limits[@]}")
    echo "| $n | PostgreSQL | $(memory_bench "$p" "$(cat "$work/pg.pid")" "$n") |"
    stop_all
  done
  echo "(cores: $(nproc); $(date -u +%Y-%m-%d); $(git rev-parse --short HEAD))"
  exit 0
fi

echo "| setup | quick job round trip (200 jobs) | 8 slow sweeps posted at once |"
echo "|---|---|---|"
p=$(start sqlite --jobs-db "$work/jobs.db" --job-workers 2)
quick=$(python_bench quick "$p"); slow=$(python_bench slow "$p"); stop_all
echo "| 1 process, SQLite, --job-workers 2 | $quick | $slow |"
p1=$(start pg1 --jobs-db "$uri" --job-workers 1); p2=$(start pg2 --jobs-db "$uri" --job-workers 1)
quick=$(python_bench quick "$p1,$p2"); slow=$(python_bench slow "$p1,$p2"); stop_all
echo "| 2 replicas, PostgreSQL, --job-workers 1 each | $quick | $slow |"
echo "(cores: $(nproc); $(date -u +%Y-%m-%d))"
