# Sourced by the build and test scripts: names stages, times them, and sets the
# build defaults they share.
#
#   stage "<name>" <command>...   runs the command; prints "== <name>: N s, C CPU-s" when it
#                                 ends (also when it fails, then the script stops as before)
#   stage_background "<name>" <command>...
#                                 starts the command at idle priority (SCHED_IDLE: it gets a
#                                 core only when nothing else wants it) and returns at once,
#                                 so that a build can use what a test stage leaves idle; its
#                                 output goes to stage-logs/<name>.log (shown if it fails)
#   stage_wait "<name>"           waits for that command; prints and records its wall time
#                                 from its start and its CPU time (it fails as stage does)
#   stages_report                 prints every stage's wall and CPU time and the totals
#
# CPU time is user + system time of the command and of every process it waited for (the
# compilers of a build, the tests and the servers they stop): unlike wall time it hardly
# depends on what else the machine runs, so it compares two runs on a shared machine.

# New build trees use Ninja when it is installed (an existing tree keeps its generator).
if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null 2>&1; then
  export CMAKE_GENERATOR=Ninja
fi

sweetspot_stage_names=()
sweetspot_stage_seconds=()
sweetspot_stage_cpu=()
sweetspot_stages_start=$SECONDS

# cpu_seconds_of <file>: the CPU seconds (user + system of the waited-for children) in the
# output of bash's `times` that <file> holds ("?" if there is none).
cpu_seconds_of() {
  awk 'NR == 2 {
         n = 0
         for (i = 1; i <= 2; i++) { split($i, t, /[ms]/); n += t[1] * 60 + t[2] }
         printf "%d", n + 0.5; found = 1 }
       END { if (!found) printf "?" }' "$1" 2>/dev/null || printf '?'
}

# with_cpu <file> <command>...: runs the command in a subshell that then writes `times` (its
# children's CPU time) to <file>; returns the command's status.
with_cpu() {
  local file="$1"
  shift
  ( status=0; "$@" || status=$?; times >"$file"; exit "$status" )
}

stage() {
  local name="$1"
  shift
  local start=$SECONDS status=0 cpu_file
  mkdir -p stage-logs
  cpu_file="stage-logs/$(printf '%s' "$name" | tr -c 'A-Za-z0-9' '-').cpu"
  with_cpu "$cpu_file" "$@" || status=$?
  local took=$((SECONDS - start)) cpu
  cpu=$(cpu_seconds_of "$cpu_file")
  sweetspot_stage_names+=("$name")
  sweetspot_stage_seconds+=("$took")
  sweetspot_stage_cpu+=("$cpu")
  printf '== %s: %d s, %s CPU-s%s\n' "$name" "$took" "$cpu" \
    "$([ "$status" -eq 0 ] || echo " (FAILED, status $status)")" >&2
  return "$status"
}

# The idle priority: SCHED_IDLE where the kernel allows it, else the lowest nice value.
if chrt --idle 0 true 2>/dev/null; then
  sweetspot_idle=(chrt --idle 0)
else
  sweetspot_idle=(nice -n 19)
fi
declare -A sweetspot_background_pid sweetspot_background_start sweetspot_background_log

# kill_tree <pid>: stops a process and everything it started (a build's compilers too).
kill_tree() {
  local child
  for child in $(pgrep -P "$1" 2>/dev/null); do kill_tree "$child"; done
  kill "$1" 2>/dev/null || true
}

# A script that stops (a failed stage, set -e) stops its background stages too.
stop_background_stages() {
  local name
  for name in "${!sweetspot_background_pid[@]}"; do kill_tree "${sweetspot_background_pid[$name]}"; done
}
trap stop_background_stages EXIT

stage_background() {
  local name="$1"
  shift
  local log
  log="stage-logs/$(printf '%s' "$name" | tr -c 'A-Za-z0-9' '-').log"
  mkdir -p stage-logs
  sweetspot_background_start[$name]=$SECONDS
  sweetspot_background_log[$name]=$log
  with_cpu "${log%.log}.cpu" "${sweetspot_idle[@]}" "$@" >"$log" 2>&1 &
  sweetspot_background_pid[$name]=$!
  printf '== %s: started in the background (%s), output in %s\n' "$name" \
    "${sweetspot_idle[*]}" "$log" >&2
}

stage_wait() {
  local name="$1" status=0
  wait "${sweetspot_background_pid[$name]}" || status=$?
  unset "sweetspot_background_pid[$name]"
  if [ "$status" -ne 0 ]; then
    echo "== $name failed; the end of ${sweetspot_background_log[$name]}:" >&2
    tail -n 60 "${sweetspot_background_log[$name]}" >&2
  fi
  local took=$((SECONDS - sweetspot_background_start[$name])) cpu
  cpu=$(cpu_seconds_of "${sweetspot_background_log[$name]%.log}.cpu")
  sweetspot_stage_names+=("$name")
  sweetspot_stage_seconds+=("$took")
  sweetspot_stage_cpu+=("$cpu")
  printf '== %s: %d s, %s CPU-s%s\n' "$name" "$took" "$cpu" \
    "$([ "$status" -eq 0 ] || echo " (FAILED, status $status)")" >&2
  return "$status"
}

stages_report() {
  local i total=$((SECONDS - sweetspot_stages_start)) cpu
  times >stage-logs/total.cpu
  cpu=$(cpu_seconds_of stage-logs/total.cpu)
  echo "== Wall and CPU time of each stage (a background stage overlaps the stages beside it)" >&2
  for i in "${!sweetspot_stage_names[@]}"; do
    printf '%-28s %5d s %6s CPU-s\n' "${sweetspot_stage_names[$i]}" "${sweetspot_stage_seconds[$i]}" \
      "${sweetspot_stage_cpu[$i]}" >&2
  done
  printf '%-28s %5d s %6s CPU-s (%d min %d s; load average at the end: %s)\n' "total" "$total" \
    "$cpu" $((total / 60)) $((total % 60)) "$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)" >&2
}
