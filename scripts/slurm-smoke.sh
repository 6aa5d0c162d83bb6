#!/usr/bin/env bash
# Runs a sharded /v1/explore sweep on a real single-node Slurm cluster and
# checks the merged result equals the unsharded sweep (but timing_s):
# installs Debian's slurm-wlm and munge if missing, starts munged, slurmctld
# and slurmd in a temporary folder on free loopback ports (nothing in /etc),
# submits deploy/slurm/submit.sh (an array of 4 shard tasks and the merge that
# depends on it), waits for sweep.ndjson, compares, and stops the daemons.
#
#   scripts/slurm-smoke.sh [--build-dir DIR] [--shards N]
#
# Needs root (the daemons run as root here, as in a test container). Prints
# each stage's wall time; exits non-zero on any failure, with the logs. The
# test command runs it as the ctest test Slurm.ExploreArrayMergesIntoTheSweep.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
shards=4
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build="$2"; shift ;;
    --shards) shards="$2"; shift ;;
    *) echo "usage: scripts/slurm-smoke.sh [--build-dir DIR] [--shards N]" >&2; exit 2 ;;
  esac
  shift
done
stage_start=$(date +%s.%N)
stage() {
  local now
  now=$(date +%s.%N)
  printf 'slurm-smoke: %-40s %6.1f s\n' "$1" "$(echo "$now - $stage_start" | bc)" >&2
  stage_start=$now
}

missing=()
for p in slurm-wlm munge bc; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
stage "install (${missing[*]:-nothing missing})"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
cli="$build/server/sweetspot"
if [ ! -x "$cli" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j"$(nproc)" --target sweetspot
fi
stage "sweetspot CLI"

work="$(mktemp -d /tmp/sweetspot-slurm-XXXXXX)"
chmod 755 "$work"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "slurm-smoke: $*" >&2
  for log in "$work"/*.log "$work"/out/slurm-*.out; do
    [ -f "$log" ] && { echo "--- $log" >&2; tail -n 20 "$log" >&2; }
  done
  exit 1
}
# A port nothing listens on, below the kernel's ephemeral range (32768 and up by default):
# the test suite's clients take ephemeral ports by the thousand, and a port one of them holds
# (or left in TIME_WAIT) answers no connect yet cannot be bound (measured: slurmd's "Address
# already in use" when the range was 20000-39999). $1: a port not to return.
free_port() {
  local p
  while :; do
    p=$(( 20000 + RANDOM % 12000 ))
    [ "$p" = "${1:-}" ] && continue
    (echo >"/dev/tcp/127.0.0.1/$p") 2>/dev/null || { echo "$p"; return; }
  done
}

# munge: its own key and socket.
mungekey --create --keyfile="$work/munge.key" >/dev/null 2>&1 ||
  dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 2>/dev/null
chmod 600 "$work/munge.key"
munged --foreground --force --socket="$work/munge.sock" --key-file="$work/munge.key" \
  --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge.seed" \
  >"$work/munged.stdout.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 100); do [ -S "$work/munge.sock" ] && break; sleep 0.05; done
[ -S "$work/munge.sock" ] || fail "munged did not start"

ctld_port=$(free_port)
slurmd_port=$(free_port "$ctld_port")
mkdir -p "$work/state" "$work/spool" "$work/out"
cat >"$work/slurm.conf" <<EOF
ClusterName=sweetspot-smoke
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge.sock
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
MailProg=/bin/true
NodeName=node0 NodeAddr=127.0.0.1 NodeHostname=localhost CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=node0 Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$work/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >"$work/slurmctld.stdout.log" 2>&1 &
pids+=($!)
slurmd -D -N node0 -f "$SLURM_CONF" >"$work/slurmd.stdout.log" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 1 300); do  # up to 30 s for the node
  for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null || fail "a daemon exited"; done
  state="$(sinfo -h -N -o %T 2>/dev/null | head -n1 || true)"
  [ "$state" = "idle" ] && break
  sleep 0.1
done
[ "$state" = "idle" ] || fail "node0 is not idle (state: ${state:-none})"
stage "munge, slurmctld, slurmd up"

cat >"$work/sweep.json" <<'EOF'
{"bat": {"preset": "paper-wood", "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
 "outputs": ["max_exit_speed", "properties"],
 "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 21},
                {"path": "ball.speed_mps", "min": 20, "max": 40, "count": 5}],
 "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                           {"output": "properties.mass_kg", "sense": "min"}]},
 "format": "ndjson"}
EOF
export SWEETSPOT_CLI="$cli"
read -r array merge <<<"$(deploy/slurm/submit.sh "$work/sweep.json" "$work/out" "$shards")"
echo "slurm-smoke: submitted array job $array ($shards tasks) and merge job $merge" >&2
for _ in $(seq 1 600); do  # up to 60 s
  [ -f "$work/out/sweep.ndjson" ] && break
  if [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] && [ ! -f "$work/out/sweep.ndjson" ]; then
    sleep 0.5
    [ -f "$work/out/sweep.ndjson" ] || fail "the jobs ended without sweep.ndjson"
  fi
  sleep 0.1
done
[ -f "$work/out/sweep.ndjson" ] || fail "no sweep.ndjson within 60 s"
stage "array of $shards shards and the merge"

# The unsharded sweep, and the comparison without the timings.
"$cli" explore "$work/sweep.json" >"$work/whole.ndjson"
strip() { sed -e 's/"timing_s":[^,}]*,\{0,1\}//' "$1"; }
rows=$(($(wc -l <"$work/whole.ndjson") - 1))
if ! diff <(strip "$work/whole.ndjson") <(strip "$work/out/sweep.ndjson") >"$work/diff.log"; then
  fail "the merged sweep differs from the unsharded one (diff.log)"
fi
for ((i = 0; i < shards; i++)); do
  [ -f "$work/out/shard-$i.ndjson" ] || fail "shard-$i.ndjson missing"
done
stage "compare with the unsharded sweep"
echo "slurm-smoke: ok: $shards shards of $rows designs merged by Slurm equal the unsharded sweep" >&2
