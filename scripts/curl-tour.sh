#!/usr/bin/env bash
# A curl tour of every endpoint against a running server (default
# http://127.0.0.1:8080; first argument overrides). README.md pastes its output.
set -uo pipefail
base="${1:-http://127.0.0.1:8080}"
run() {
  echo "\$ $*"
  "$@"
  echo
}
post() {  # post PATH JSON
  echo "\$ curl -s -X POST $base$1 -d '$2'"
  curl -s -X POST "$base$1" -H 'Content-Type: application/json' -d "$2"
  echo
}
run curl -s "$base/health"
run curl -s "$base/v1/version"
run curl -s "$base/v1/speed-vs-error"
run curl -s "$base/v1/materials"
run curl -s "$base/v1/presets"
run curl -s "$base/v1/balls"
post /v1/bat/properties '{"bat": {"preset": "paper-wood"}, "inertia_model": "slender_rod"}'
post /v1/bat/properties '{"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55}, "material": "ash"}, "pivot_from_knob_m": 0.1524}'
post /v1/bat/fit '{"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}}'
post /v1/bat/fit '{"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.885, "balance_point_m": 0.564}}'
post /v1/bat/fit '{"bat": {"preset": "wood-34-ash"}, "unknowns": [{"path": "material.density_kg_m3", "min": 400, "max": 900}], "targets": {"mass_oz": 30}}'
post /v1/sweet-spot '{"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone"]}'
post /v1/sweet-spot '{"bat": {"preset": "paper-wood"}, "outputs": ["exit_speed_curve"], "options": {"curve_samples": 3}}'
post /v1/sweet-spot '{"bat": {"preset": "paper-wood"}, "outputs": ["vibration_node"]}'
post /v1/sweet-spot '{"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mps": 40}, "swing": {"angular_speed_rad_s": 45}}'
post /v1/sweet-spot '{"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mps": 40}, "swing": {"angular_speed_rad_s": 45}, "options": {"model": "rigid_pivot"}}'
post /v1/sweet-spot '{"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95, "barrel_diameter_in": 2.5, "taper_start_in": 11, "taper_end_in": 21}, "material": "hard-maple"}, "ball": {"speed_mph": 90}, "swing": {"angular_speed_rad_s": 40}, "report_units": "imperial"}'
post /v1/sweet-spot '{"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70}}'
post /v1/sweet-spot '{"bat": {"preset": "bbcor-33-aluminium"}, "ball": {"preset": "ncaa-nfhs"}, "outputs": ["barrel", "bbcor"]}'
post /v1/sweet-spot '{"bat": {"preset": "bbcor-33-aluminium"}, "outputs": ["bbcor", "bbcor_scan"]}'
post /v1/collision '{"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "hertz"}'
post /v1/collision '{"bat": {"preset": "bbcor-33-aluminium"}, "impact_from_knob_m": 0.70, "model": "free_bat"}'
post /v1/compare '{"baseline": {"preset": "paper-wood"}, "variants": [{"name": "cork-320", "bat": {"preset": "paper-wood", "fill": {"material": {"density_kg_m3": 320, "youngs_modulus_pa": 2e7}, "diameter_m": 0.0254, "depth_m": 0.254}}}]}'
post /v1/compare '{"baseline": {"preset": "wood-34-ash"}, "variants": [{"name": "alloy", "bat": {"preset": "bbcor-33-aluminium"}}], "ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70, "speed_model": "swing_weight"}, "outputs": ["max_exit_speed"], "report_units": "imperial"}'
post /v1/optimize '{"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55}, "material": "ash"}, "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}, {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}], "constraints": {"mass_kg": 0.88, "balance_point_m": {"min": 0.56, "max": 0.60}, "moi_six_inch_kg_m2": {"max": 0.20}, "rules": "mlb-wood"}, "objective": "max_exit_speed", "cor": 0.5, "options": {"max_time_s": 10, "starts": 4, "seed": 1}}'
post /v1/optimize '{"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95, "barrel_diameter_in": 2.5, "taper_start_in": 11, "taper_end_in": 21}, "material": "hard-maple"}, "ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70}, "variables": [{"scale_paths": ["three_segment.handle_radius_m", "three_segment.barrel_radius_m"], "name": "girth", "min": 0.9, "max": 1.05}, {"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.4}], "constraints": {"mass_oz": {"min": 29, "max": 31}, "rules": "mlb-wood"}, "objective": "max_exit_speed"}'
post /v1/optimize '{"bat": {"preset": "bbcor-33-aluminium"}, "ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70}, "variables": [{"path": "wall_thickness_m", "min": 0.0015, "max": 0.004}, {"path": "material.density_kg_m3", "min": 2000, "max": 4000}, {"paths": ["profile.knots[4].radius_m", "profile.knots[5].radius_m"], "min": 0.0105, "max": 0.0135}], "constraints": {"mass_oz": {"min": 29, "max": 31}, "rules": "bbcor"}, "objective": "max_exit_speed"}'
post /v1/explore '{"bat": {"preset": "paper-wood", "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}}, "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 4}], "outputs": ["max_exit_speed"], "shard": {"index": 0, "count": 1}}'
echo "\$ curl -sN -X POST $base/v1/explore -d '{… the same sweep …, \"format\": \"ndjson\"}'"
curl -sN -X POST "$base/v1/explore" -H 'Content-Type: application/json' -d '{"bat": {"preset": "paper-wood", "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}}, "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 4}], "outputs": ["max_exit_speed"], "format": "ndjson"}'
echo
job='{"path": "/v1/compare", "body": {"baseline": {"preset": "paper-wood"}, "variants": [{"name": "ash", "bat": {"preset": "paper-wood", "material": "ash"}}]}}'
echo "\$ curl -s -X POST $base/v1/jobs -d '$job'"
submitted=$(curl -s -X POST "$base/v1/jobs" -H 'Content-Type: application/json' -d "$job")
echo "$submitted"
echo
id=$(echo "$submitted" | sed -n 's/.*"id":"\([0-9a-f]*\)".*/\1/p')
sleep 0.2
run curl -s "$base/v1/jobs/$id"
run curl -s "$base/v1/jobs/$id/result"
run curl -s "$base/v1/jobs?state=done&limit=1"
post /v1/jobs '{"path": "/v1/optimize", "body": {"bat": {"preset": "paper-wood"}, "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}], "options": {"starts": 500}}}'
run curl -s -X DELETE "$base/v1/jobs/$id"
run curl -s "$base/metrics"
post /v1/sweet-spot '{"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": -1}}'
post /v1/sweet-spot '{"bat": {"preset": "paper-wood"}, "ball": {"mass": 0.145}}'
