#!/usr/bin/env python3
"""How short one flight's chain of dependent right-hand sides can get with Gragg-Bulirsch-Stoer
extrapolation, whose sequences (modified midpoint with n = 2, 4, 6, ... substeps) are independent
and could each run in a vector lane: the depth counted is what one flight would wait for (the
longest sequence per step, plus the step's first evaluation, plus the landing found by secant
steps on the last step's length), against Dormand-Prince 5(4)'s 37 evaluations for the same
flight to 7.5e-4 ft (core/flight, BM_FlightNathan/5).

The model and the flight are bench/scipy_flight_peer.py's (nathan-2016, 100 mph at 28 degrees,
the Statcast spin relation); the reference is solve_ivp at tolerance 1e-12. Fixed big steps H
tuned to this one flight, with no error estimate: a bound in GBS's favour, not a usable
integrator. Prints the configurations within 0.1 ft, the shallowest first.

    /usr/bin/python3 bench/flight_extrapolation.py      # needs python3-scipy; about 10 s
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scipy_flight_peer as peer  # noqa: E402

Y0, PARAMS = peer.setup(100, 28)
ARGS = tuple(PARAMS[n] for n in ("k", "omega", "axis", "krpm", "rate"))
FT = 0.3048


def f(t, s):
    return np.array(peer.rhs(t, s, *ARGS))


def midpoint(t, y, big_h, n, f0):
    """Gragg's modified midpoint rule over big_h in n substeps, with the smoothing step."""
    h = big_h / n
    z0, z1 = y, y + h * f0
    for m in range(1, n):
        z0, z1 = z1, z0 + 2 * h * f(t + m * h, z1)
    return 0.5 * (z0 + z1 + h * f(t + big_h, z1))


def gbs_step(t, y, big_h, seq):
    """One extrapolated step (Aitken-Neville in h^2); depth: f(y), then seq[-1] evaluations."""
    f0 = f(t, y)
    table = []
    for j, n in enumerate(seq):
        row = [midpoint(t, y, big_h, n, f0)]
        for k in range(1, j + 1):
            ratio = (seq[j] / seq[j - k]) ** 2
            row.append(row[k - 1] + (row[k - 1] - table[j - 1][k - 1]) / (ratio - 1))
        table.append(row)
    return table[-1][-1], 1 + seq[-1]


def fly(big_h, seq, secants):
    t, y, depth = 0.0, Y0.copy(), 0
    while True:
        y_next, d = gbs_step(t, y, big_h, seq)
        depth += d
        if y_next[2] < 0:
            break
        t, y = t + big_h, y_next
    a, za, b, zb, yb = 0.0, y[2], big_h, y_next[2], y_next
    for _ in range(secants):
        c = b - zb * (b - a) / (zb - za)
        yc, d = gbs_step(t, y, c, seq)
        depth += d
        a, za, b, zb, yb = b, zb, c, yc[2], yc
    return math.hypot(yb[0], yb[1]), depth


def main():
    reference = peer.fly(Y0, PARAMS, 1e-12, 1e-12)["distance_m"]
    rows = []
    for seq in ([2, 4, 6], [2, 4, 6, 8], [2, 4, 6, 8, 10, 12], [2, 4, 6, 8, 10, 12, 14, 16]):
        for big_h in (0.5, 1.0, 1.5, 2.0, 2.7, 3.0):
            for secants in (1, 2, 3):
                distance, depth = fly(big_h, seq, secants)
                error_ft = abs(distance - reference) / FT
                if error_ft <= 0.1:
                    rows.append((depth, error_ft, len(seq), seq[-1], big_h, secants))
    print("depth  error_ft  lanes  longest_sequence  step_s  secant_steps")
    for depth, error_ft, lanes, longest, big_h, secants in sorted(rows)[:10]:
        print(f"{depth:5d}  {error_ft:8.2e}  {lanes:5d}  {longest:16d}  {big_h:6.1f}  {secants:12d}")


if __name__ == "__main__":
    main()
