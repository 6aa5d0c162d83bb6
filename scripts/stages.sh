# Sourced by the build and test scripts: names stages, times them, and sets the
# build defaults they share.
#
#   stage "<name>" <command>...   runs the command; prints "== <name>: N s" when it ends
#                                 (also when it fails, then the script stops as before)
#   stage_background "<name>" <command>...
#                                 starts the command at idle priority (SCHED_IDLE: it gets a
#                                 core only when nothing else wants it) and returns at once,
#                                 so that a build can use what a test stage leaves idle; its
#                                 output goes to stage-logs/<name>.log (shown if it fails)
#   stage_wait "<name>"           waits for that command; prints and records its wall time
#                                 from its start (it fails as stage does)
#   stages_report                 prints every stage's wall time and the total

# New build trees use Ninja when it is installed (an existing tree keeps its generator).
if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null 2>&1; then
  export CMAKE_GENERATOR=Ninja
fi

sweetspot_stage_names=()
sweetspot_stage_seconds=()
sweetspot_stages_start=$SECONDS

stage() {
  local name="$1"
  shift
  local start=$SECONDS status=0
  "$@" || status=$?
  local took=$((SECONDS - start))
  sweetspot_stage_names+=("$name")
  sweetspot_stage_seconds+=("$took")
  printf '== %s: %d s%s\n' "$name" "$took" "$([ "$status" -eq 0 ] || echo " (FAILED, status $status)")" >&2
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
  "${sweetspot_idle[@]}" "$@" >"$log" 2>&1 &
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
  local took=$((SECONDS - sweetspot_background_start[$name]))
  sweetspot_stage_names+=("$name")
  sweetspot_stage_seconds+=("$took")
  printf '== %s: %d s%s\n' "$name" "$took" "$([ "$status" -eq 0 ] || echo " (FAILED, status $status)")" >&2
  return "$status"
}

stages_report() {
  local i total=$((SECONDS - sweetspot_stages_start))
  echo "== Wall time of each stage (a background stage overlaps the stages beside it)" >&2
  for i in "${!sweetspot_stage_names[@]}"; do
    printf '%-28s %5d s\n' "${sweetspot_stage_names[$i]}" "${sweetspot_stage_seconds[$i]}" >&2
  done
  printf '%-28s %5d s (%d min %d s)\n' "total" "$total" $((total / 60)) $((total % 60)) >&2
}
