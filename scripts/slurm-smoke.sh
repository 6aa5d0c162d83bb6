#!/usr/bin/env bash
# Runs a sharded /v1/explore sweep on a real single-node Slurm cluster and
# checks the merged result equals the unsharded sweep: the rows byte for byte,
# the summary but its timing_s. Installs Debian's slurm-wlm and munge if
# missing, starts munged, slurmctld and slurmd in a temporary folder on free
# loopback ports (nothing in /etc), submits deploy/slurm/submit.sh (an array of
# 4 shard tasks and the merge that depends on it), waits for sweep.ndjson,
# compares, and stops the daemons.
#
#   scripts/slurm-smoke.sh [--build-dir DIR] [--shards N] [--fail-shard K]
#
# --fail-shard K: shard K fails on the first submission (SWEETSPOT_CLI is a
# wrapper that exits 1 for `--shard K/N` while a marker file exists). Checks the
# other shards are written, shard K is not, and Slurm cancels the merge at once
# (--kill-on-invalid-dep) instead of leaving it pending; then removes the marker,
# re-runs shard K alone (submit.sh --only-missing: an array of that one task, N
# unchanged) with a new merge, and compares as above.
#
# Needs root (the daemons run as root here, as in a test container). Prints
# each stage's wall time; exits non-zero on any failure, with the logs, and 77
# (ctest: skipped) when slurm-wlm or munge cannot be installed. The test command
# runs it as the ctest tests Slurm.ExploreArrayMergesIntoTheSweep and, with
# --fail-shard 2, Slurm.FailedShardRerunAloneMergesIntoTheSweep.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
shards=4
fail_shard=""
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build="$2"; shift ;;
    --shards) shards="$2"; shift ;;
    --fail-shard) fail_shard="$2"; shift ;;
    *) echo "usage: scripts/slurm-smoke.sh [--build-dir DIR] [--shards N] [--fail-shard K]" >&2
       exit 2 ;;
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
  if ! { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }
  then
    echo "slurm-smoke: SKIPPED: cannot install ${missing[*]} from Debian's registry" >&2
    exit 77
  fi
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
# The scripts ask for --mem (1G a shard, 2G the merge), which needs RealMemory on the node line.
# Nothing enforces it here (no cgroups); config_overrides lets a small machine claim the 4 GiB
# the scripts' requests fit in rather than refuse them.
memory_mb=$(( $(awk '/^MemTotal:/ {print $2}' /proc/meminfo) / 1024 ))
[ "$memory_mb" -ge 4096 ] || memory_mb=4096
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
SlurmdParameters=config_overrides
NodeName=node0 NodeAddr=127.0.0.1 NodeHostname=localhost CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
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
# Waits up to $2 s for OUT/sweep.ndjson, failing when the jobs $1 all left the queue without it.
wait_for_sweep() {
  for _ in $(seq 1 $(($2 * 10))); do
    [ -f "$work/out/sweep.ndjson" ] && return
    if [ -z "$(squeue -h -j "$1" 2>/dev/null)" ]; then
      sleep 0.5
      [ -f "$work/out/sweep.ndjson" ] && return
      fail "the jobs $1 ended without sweep.ndjson"
    fi
    sleep 0.1
  done
  fail "no sweep.ndjson within $2 s"
}

if [ -n "$fail_shard" ]; then
  # The wrapper the jobs run: shard K fails while the marker exists; any other call is the CLI.
  cat >"$work/cli-failing.sh" <<EOF
#!/bin/sh
case " \$* " in
  *" --shard $fail_shard/$shards "*)
    if [ -e "$work/fail-shard" ]; then echo "slurm-smoke: shard $fail_shard made to fail" >&2; exit 1; fi ;;
esac
exec "$cli" "\$@"
EOF
  chmod 755 "$work/cli-failing.sh"
  touch "$work/fail-shard"
  export SWEETSPOT_CLI="$work/cli-failing.sh"
  read -r array merge <<<"$(deploy/slurm/submit.sh "$work/sweep.json" "$work/out" "$shards")"
  echo "slurm-smoke: submitted array job $array ($shards tasks, shard $fail_shard failing)" \
       "and merge job $merge" >&2
  for _ in $(seq 1 300); do  # up to 30 s for every task to end and the merge to leave the queue
    [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] && break
    sleep 0.1
  done
  [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] ||
    fail "jobs still queued 30 s after a shard failed: $(squeue -h -j "$array,$merge" -o '%i %T %r')"
  merge_state="$(scontrol -o show job "$merge" | grep -o 'JobState=[A-Z_]*' || true)"
  [ "$merge_state" = "JobState=CANCELLED" ] ||
    fail "the merge after a failed shard is '${merge_state:-gone}', not JobState=CANCELLED"
  [ ! -e "$work/out/sweep.ndjson" ] || fail "sweep.ndjson written although shard $fail_shard failed"
  [ ! -e "$work/out/shard-$fail_shard.ndjson" ] || fail "shard-$fail_shard.ndjson written although it failed"
  for ((i = 0; i < shards; i++)); do
    [ "$i" = "$fail_shard" ] || [ -f "$work/out/shard-$i.ndjson" ] || fail "shard-$i.ndjson missing"
  done
  stage "shard $fail_shard failed, the merge cancelled"
  rm "$work/fail-shard"
  read -r array merge <<<"$(deploy/slurm/submit.sh --only-missing "$work/sweep.json" "$work/out" "$shards")"
  echo "slurm-smoke: re-submitted shard $fail_shard alone as array job $array, merge job $merge" >&2
  wait_for_sweep "$array,$merge" 60
  ran="$(cd "$work/out" && ls slurm-"${array}"_*.out)"
  [ "$ran" = "slurm-${array}_$fail_shard.out" ] || fail "the re-run ran tasks: $ran"
  grep -q "shard $fail_shard made to fail" "$work/out"/slurm-*_"$fail_shard".out ||
    fail "the first run of shard $fail_shard did not fail as made to"
  stage "shard $fail_shard re-run alone and the merge"
else
  read -r array merge <<<"$(deploy/slurm/submit.sh "$work/sweep.json" "$work/out" "$shards")"
  echo "slurm-smoke: submitted array job $array ($shards tasks) and merge job $merge" >&2
  wait_for_sweep "$array,$merge" 60
  stage "array of $shards shards and the merge"
fi

# The unsharded sweep: the rows byte for byte, the summary but its timing_s (the shards' sum).
"$cli" explore "$work/sweep.json" >"$work/whole.ndjson"
rows=$(($(wc -l <"$work/whole.ndjson") - 1))
cmp <(head -n "$rows" "$work/whole.ndjson") <(head -n "$rows" "$work/out/sweep.ndjson") \
  >"$work/diff.log" 2>&1 || fail "the merged rows differ from the unsharded sweep's (diff.log)"
strip() { tail -n +"$((rows + 1))" "$1" | sed -e 's/"timing_s":[^,}]*,\{0,1\}//'; }
if ! diff <(strip "$work/whole.ndjson") <(strip "$work/out/sweep.ndjson") >"$work/diff.log"; then
  fail "the merged summary differs from the unsharded one (diff.log)"
fi
[ "$(wc -l <"$work/out/sweep.ndjson")" = "$((rows + 1))" ] || fail "sweep.ndjson has extra lines"
for ((i = 0; i < shards; i++)); do
  [ -f "$work/out/shard-$i.ndjson" ] || fail "shard-$i.ndjson missing"
done
stage "compare with the unsharded sweep"
echo "slurm-smoke: ok: $shards shards of $rows designs merged by Slurm equal the unsharded sweep" \
     "${fail_shard:+(shard $fail_shard failed, then re-run alone)}" >&2
