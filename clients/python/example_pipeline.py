"""A pipeline written with sweetspot_client: a sweep, a frontier, a Statcast-style flight batch.

    python3 clients/python/example_pipeline.py [http://127.0.0.1:8080] [TOKEN]

The README and docs/api.md show this code; test_sweetspot_client.py runs it against the real
server. The flight step needs a server with POST /v1/flight (it says so and is skipped
otherwise).
"""

import csv
import io
import sys

from sweetspot_client import Client, statcast_launches

# A 33 in hard-maple bat, in the trade's units; an MLB ball at 90 mph, a 70 mph swing.
BAT = {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95, "barrel_diameter_in": 2.5,
                         "taper_start_in": 11, "taper_end_in": 21}, "material": "hard-maple"}
SCENE = {"ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70}}


def sweep(client):
    """10,000 designs (barrel diameter x where the taper starts), streamed: the best exit speed
    at each weight, in whole ounces, kept as the rows go by (no row is held)."""
    rows = client.explore_rows(
        bat=BAT, **SCENE,
        parameters=[
            {"path": "three_segment.barrel_diameter_in", "min": 2.2, "max": 2.61, "count": 100},
            {"path": "three_segment.taper_start_in", "min": 8, "max": 16, "count": 100}],
        outputs=["properties", "max_exit_speed"],
        columns=["parameters.three_segment.barrel_diameter_in",
                 "parameters.three_segment.taper_start_in",
                 "properties.mass_oz", "max_exit_speed.exit_speed_mph"])
    best = {}
    for row in rows:
        ounces = round(row["properties.mass_oz"])
        if ounces not in best or (row["max_exit_speed.exit_speed_mph"]
                                  > best[ounces]["max_exit_speed.exit_speed_mph"]):
            best[ounces] = row
    print("sweep: %d designs" % rows.summary["designs_total"])
    for ounces in range(29, 33):
        row = best[ounces]
        print("  %d oz: %.1f mph, barrel %.3f in, taper from %.2f in" % (
            ounces, row["max_exit_speed.exit_speed_mph"],
            row["parameters.three_segment.barrel_diameter_in"],
            row["parameters.three_segment.taper_start_in"]))
    return best


def frontier(client):
    """The best bat at every weight: one frontier request (each weight started from its
    neighbour's answer), the swing slowing with the swing weight (objective
    max_exit_speed_swing_weight), MLB wood-bat rules; rows streamed as each weight is solved."""
    designs = {}
    rows = client.frontier(
        bat=BAT, **SCENE, objective="max_exit_speed_swing_weight",
        variables=[{"scale_paths": ["three_segment.handle_radius_m",
                                    "three_segment.barrel_radius_m"],
                    "name": "girth", "min": 0.85, "max": 1.05},
                   {"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.45}],
        constraints={"rules": "mlb-wood"}, report_units="imperial",
        frontier={"constraint": "mass_oz", "values": [29, 30, 31, 32]})
    for design in rows:
        ounces = design["mass_oz"]
        designs[ounces] = design
        shape = design["bat"]["three_segment"]
        print("frontier %d oz: %.1f mph at %.1f in from the tip; barrel %.3f in, handle %.3f in, "
              "taper from %.2f in (%s)" % (
                  ounces, design["sweet_spot"]["exit_speed_mph"],
                  design["sweet_spot"]["position_from_tip_in"], shape["barrel_diameter_in"],
                  shape["handle_diameter_in"], shape["taper_start_in"],
                  design["summary"]["termination"]))
    print("frontier: Pareto front %s" % rows.summary["pareto"])
    return designs


# Rows shaped like a Baseball Savant (Statcast) search export; made-up values.
STATCAST_CSV = """\
player_name,game_date,events,stand,launch_speed,launch_angle,hc_x,hc_y,hit_distance_sc
"Doe, John",2024-06-01,home_run,R,108.2,28,105.3,44.9,412
"Doe, John",2024-06-01,field_out,R,96.4,34,150.8,70.2,356
"Roe, Jane",2024-06-02,single,L,88.0,9,160.1,125.6,190
"Roe, Jane",2024-06-02,strikeout,L,,,,,
"""


def flight_batch(client):
    """Needs POST /v1/flight. The CSV's batted balls flown at 5,200 ft and 75 F: distances."""
    reader = csv.DictReader(io.StringIO(STATCAST_CSV))
    rows = [row for row in reader if row["launch_speed"]]
    flights = client.flights(statcast_launches(rows), chunk=1000,
                             environment={"elevation_ft": 5200, "temperature_f": 75},
                             report_units="imperial")
    results = []
    for row, flight in zip(rows, flights):
        results.append(flight)
        print("flight %s %s: %s mph at %s deg: %.0f ft (Statcast %s ft), hang %.1f s" % (
            row["player_name"], row["events"], row["launch_speed"], row["launch_angle"],
            flight["distance_ft"], row["hit_distance_sc"], flight["hang_time_s"]))
    return results


def main(url="http://127.0.0.1:8080", token=None):
    client = Client(url, token=token)
    sweep(client)
    frontier(client)
    if "/v1/flight" in client.openapi()["paths"]:
        flight_batch(client)
    else:
        print("flight: skipped, this server has no POST /v1/flight")


if __name__ == "__main__":
    main(*sys.argv[1:])
