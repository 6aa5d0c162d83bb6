# Sourced by the build and test scripts: names stages, times them, and sets the
# build defaults they share.
#
#   stage "<name>" <command>...   runs the command; prints "== <name>: N s" when it ends
#                                 (also when it fails, then the script stops as before)
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

stages_report() {
  local i total=$((SECONDS - sweetspot_stages_start))
  echo "== Wall time of each stage" >&2
  for i in "${!sweetspot_stage_names[@]}"; do
    printf '%-28s %5d s\n' "${sweetspot_stage_names[$i]}" "${sweetspot_stage_seconds[$i]}" >&2
  done
  printf '%-28s %5d s (%d min %d s)\n' "total" "$total" $((total / 60)) $((total % 60)) >&2
}
