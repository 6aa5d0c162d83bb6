#!/usr/bin/python3
"""SciPy peer of one batted-ball flight (issue 34): core/flight's nathan-2016 model written as a
script would write it, integrated by scipy.integrate.solve_ivp (RK45, a Dormand-Prince 5(4) like
ours) with the landing as a terminal event. Run by bench/flight_peer.sh with Debian's
/usr/bin/python3 (`apt-get install python3-scipy`). Never needed by the service, tests or CI.

  flight [--mph V] [--la DEG] [--rtol R] [--atol A] [--repeat N] [--batch M]
      One flight (default 100 mph, 28 deg, the Statcast spin relation, 70 F, sea level, 50 %,
      29.92 inHg, calm): prints one JSON object with the distance, hang time and apex, the best
      CPU time per flight over N runs, with --batch the CPU time per flight of M flights in
      one loop (best of 3 loops), and the same flight at rtol 1e-12 (the reference).
  sheet
      Nathan's own scheme (the 3-D sheet's dt = 0.01 s steps, velocity by Euler, position with a
      half step of acceleration, the landing by linear interpolation) on the sheet's two worked
      cases: prints the distances, which should be the sheet's 421.486 and 400.550 ft: the model
      here is the sheet's, and so is core/flight's.
"""

import json
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

MPS_PER_MPH = 0.44704
FT = 0.3048
G = 9.80665
MMHG = 133.322368
# The sheet's c0 per kg/m^3, per metre (core/flight/flight.cpp, kNathanC0PerDensity).
C0_PER_DENSITY = 0.07182 * 0.06261 / FT
RADIUS_M = 9.125 * 0.0254 / (2 * math.pi)
DECAY_REFERENCE_MPS = 100 * MPS_PER_MPH


def air_density(temp_c=(70 - 32) * 5 / 9, elevation_m=0.0, rh_pct=50.0, pressure_pa=29.92 * 3386.389):
    svp = 4.5841 * math.exp((18.687 - temp_c / 234.5) * temp_c / (257.14 + temp_c))
    p = pressure_pa * math.exp(-1.217e-4 * elevation_m) / MMHG
    return 1.2929 * (273 / (temp_c + 273)) * (p - 0.3783 * rh_pct * svp / 100) / 760


def setup(mph, la, spray=0.0, backspin=None, sidespin=None, tau=30.0, rho=None, hand=1):
    if backspin is None:
        backspin = -763 + 120 * la + 21 * spray * hand
        sidespin = -849 * hand - 94 * spray
    th, ph = math.radians(la), math.radians(spray)
    rpm = math.pi / 30
    w = np.array([(backspin * math.cos(ph) - sidespin * math.sin(th) * math.sin(ph)) * rpm,
                  (-backspin * math.sin(ph) - sidespin * math.sin(th) * math.cos(ph)) * rpm,
                  sidespin * math.cos(th) * rpm])
    omega = float(np.linalg.norm(w))
    axis = w / omega if omega > 0 else w
    rho = air_density() if rho is None else rho
    v0 = mph * MPS_PER_MPH
    y0 = np.array([0.0, 2 * FT, 3 * FT,
                   v0 * math.cos(th) * math.sin(ph), v0 * math.cos(th) * math.cos(ph), v0 * math.sin(th)])
    params = dict(k=C0_PER_DENSITY * rho, omega=omega, axis=axis,
                  krpm=math.hypot(backspin, sidespin) / 1000, rate=1 / (tau * DECAY_REFERENCE_MPS))
    return y0, params


def rhs(t, s, k, omega, axis, krpm, rate):
    vx, vy, vz = s[3], s[4], s[5]
    v = math.sqrt(vx * vx + vy * vy + vz * vz)
    decay = math.exp(-t * v * rate)
    spin_factor = RADIUS_M * omega / v * decay
    cd = 0.3008 + 0.0292 * krpm * decay
    cl = 1.120 * spin_factor / (0.583 + 2.333 * spin_factor)
    drag = -k * cd * v
    lift = k * cl * v
    ux, uy, uz = axis
    return [vx, vy, vz,
            drag * vx + lift * (uy * vz - uz * vy),
            drag * vy + lift * (uz * vx - ux * vz),
            drag * vz + lift * (ux * vy - uy * vx) - G]


def ground(t, s, *args):
    return s[2]


ground.terminal = True
ground.direction = -1


def fly(y0, params, rtol, atol):
    args = tuple(params[n] for n in ("k", "omega", "axis", "krpm", "rate"))
    sol = solve_ivp(rhs, (0.0, 30.0), y0, method="RK45", rtol=rtol, atol=atol, events=ground, args=args)
    t_land = float(sol.t_events[0][0])
    s = sol.y_events[0][0]
    apex = float(np.max(sol.y[2]))
    return dict(distance_m=math.hypot(s[0], s[1]), hang_time_s=t_land, apex_m_at_steps=apex,
                steps=int(sol.t.size - 1), evaluations=int(sol.nfev))


def sheet_case(mph, la, backspin, sidespin, tau, rho):
    """The sheet's own fixed-step scheme in feet, as its cells write it."""
    y0, p = setup(mph, la, 0.0, backspin, sidespin, tau, rho)
    x, y, z = 0.0, 2.0, 3.0
    # The sheet converts with 1.467 ft/s per mph (exact: 1.46667), which moves it 0.1 ft.
    vx, vy, vz = (y0[3:] / (mph * MPS_PER_MPH)) * mph * 1.467
    c0 = 0.07182 * rho * 0.06261
    romega = (9.125 / 2 / math.pi) * p["omega"] / 12
    ux, uy, uz = p["axis"]
    t, dt = 0.0, 0.01

    def acc(t, vx, vy, vz):
        v = math.sqrt(vx * vx + vy * vy + vz * vz)
        decay = math.exp(-t / (tau * 146.7 / v))
        s = romega / v * decay
        cd = 0.3008 + 0.0292 * p["krpm"] * decay
        cl = 1.120 * s / (0.583 + 2.333 * s)
        return (-c0 * cd * v * vx + c0 * cl * v * (uy * vz - uz * vy),
                -c0 * cd * v * vy + c0 * cl * v * (uz * vx - ux * vz),
                -c0 * cd * v * vz + c0 * cl * v * (ux * vy - uy * vx) - 32.174)

    prev = None
    while z > 0:
        ax, ay, az = acc(t, vx, vy, vz)
        prev = (t, x, y, z)
        x += vx * dt + 0.5 * ax * dt * dt
        y += vy * dt + 0.5 * ay * dt * dt
        z += vz * dt + 0.5 * az * dt * dt
        vx, vy, vz = vx + ax * dt, vy + ay * dt, vz + az * dt
        t += dt
    f = z / (z - prev[3])
    xf, yf = x - f * (x - prev[1]), y - f * (y - prev[2])
    return dict(distance_ft=math.hypot(xf, yf), hang_time_s=t - f * dt)


def main(argv):
    if not argv or argv[0] not in ("flight", "sheet"):
        print(__doc__, file=sys.stderr)
        return 2
    if argv[0] == "sheet":
        rho = 1.2929 * (273 / (21.111111111111111 + 273) * (29.92 * 1000 / 39.37 * math.exp(-1.217e-4 * 15 / 3.2808)
                                                           - 0.3783 * 50 * 18.794410804467137 / 100) / 760)
        print(json.dumps({"BattedBallTrajectory-2": sheet_case(103, 27.5, 2500, 0, 30, rho),
                          "BattedBallTrajectory-1": sheet_case(100, 27.5, 2537, -849, 10000, rho),
                          "sheet_says_ft": [421.48556894099829, 400.5498324603609]}))
        return 0
    opts = dict(mph=100.0, la=28.0, rtol=1e-6, atol=1e-4, repeat=200, batch=0)
    i = 1
    while i < len(argv):
        key = argv[i].lstrip("-")
        opts[key] = int(argv[i + 1]) if key in ("repeat", "batch") else float(argv[i + 1])
        i += 2
    y0, params = setup(opts["mph"], opts["la"])
    best = float("inf")
    for _ in range(opts["repeat"]):
        start = time.process_time()
        r = fly(y0, params, opts["rtol"], opts["atol"])
        best = min(best, time.process_time() - start)
    # The batched workload (the same flight `batch` times in one loop, best of 3 loops): what
    # a script does with a list of launches, the peer of sweetspot's FlyMany figure.
    batch = int(opts["batch"])
    batch_best = float("nan")
    if batch > 0:
        batch_best = float("inf")
        for _ in range(3):
            start = time.process_time()
            for _ in range(batch):
                fly(y0, params, opts["rtol"], opts["atol"])
            batch_best = min(batch_best, (time.process_time() - start) / batch)
    ref = fly(y0, params, 1e-12, 1e-12)
    r.update(cpu_s_per_flight=best, batch_cpu_s_per_flight=batch_best, batch=batch,
             rtol=opts["rtol"], atol=opts["atol"],
             reference_distance_m=ref["distance_m"], reference_hang_time_s=ref["hang_time_s"],
             err_ft=abs(r["distance_m"] - ref["distance_m"]) / FT,
             distance_ft=r["distance_m"] / FT)
    print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
