#!/usr/bin/python3
"""SciPy peers of two sweetspot benchmarks (issue 17): what a script would do.

Run by bench/peers.sh with Debian's interpreter, /usr/bin/python3 (numpy and SciPy from
`apt-get install python3-scipy`). Never needed by the service, the tests or CI.

  design16 [--repeat N]    (= design --knots 16)
  design [--knots N] [--repeat R]   (the same family with N knots, N - 2 free)
      The 16-knot design of bench/core_optimize.cpp (SixteenKnotProblem): the radii of knots
      1..14 of a solid ash bat in [0.0110, 0.0332] m, maximising the rigid-pivot exit speed
      (closed form) with the mass equal to the base bat's, the balance point at most 0.60 m,
      every diameter at most 2.61 in and at least 0.9 in, and a non-decreasing taper; solved
      by scipy.optimize.minimize(method="SLSQP") with finite-difference gradients (no jac).
      Prints one JSON object: the best time of N solves, the optimum, the problem's request
      for `sweetspot optimize` (so peers.sh can solve the same problem with our service).
  sweep REQUEST.json ROWS.ndjson [--limit N] [--variant bounded|root]
      For each row of `sweetspot explore REQUEST.json` (NDJSON; a three-segment bat swept over
      three_segment.* parameters; the first N designs with --limit), the mass properties with numpy and the max-exit-speed point
      by scipy.optimize.minimize_scalar(method="bounded") on [0, L] (the paper's approach;
      --variant root: brentq on the stationarity condition instead, see ROOT_XTOL_M).
      Prints one JSON object: the loop's time per design and the largest differences from
      sweetspot's answers (exit speed and position).
"""

import json
import math
import sys
import time

import numpy as np
from scipy.optimize import brentq, minimize, minimize_scalar

# The scene's defaults (core/scene/scene.hpp) and the ash of core/bat/material.cpp.
BALL_MASS_KG = 0.145
BALL_SPEED_MPS = 27.7
OMEGA_RAD_S = 17.288
PIVOT_FROM_KNOB_M = 0.0
ASH_DENSITY_KG_M3 = 672.0000000000001  # 0.60 specific gravity at 12 % moisture (GET materials)
ASH_COR = 0.5

# The bounded search's position tolerance. SciPy's default xatol (1e-5 m) leaves the position
# 1e-5 m off. Tighter does not reach 1e-9 m: Brent's method stops within
# sqrt(machine epsilon) |x| + xatol / 3 (about 1.2e-8 m at 0.8 m), and no search on values alone
# can do better, since the exit speed changes by less than its round-off that close to its
# maximum. The "root" variant therefore solves the stationarity condition dv2/dx = 0 instead
# (scipy.optimize.brentq, xtol 1e-13 m).
SWEEP_XATOL_M = 1e-10
ROOT_XTOL_M = 1e-13


def mass_properties(x, r, density):
    """Solid piecewise-conical bat: mass (kg), balance point (m from the knob), moment of inertia
    about the centroid (kg m^2, rigid body: the discs' own moments included). The exact integrals
    of core/bat/geometry_integrals.hpp, about each segment's midpoint."""
    x = np.asarray(x, dtype=float)
    r = np.asarray(r, dtype=float)
    half = 0.5 * (x[1:] - x[:-1])
    mid = 0.5 * (x[1:] + x[:-1])
    r_m = 0.5 * (r[:-1] + r[1:])
    dr = 0.5 * (r[1:] - r[:-1])
    a0 = r_m * r_m
    a1 = 2.0 * r_m * dr
    a2 = dr * dr
    volume = (math.pi * half) * (2.0 * a0 + (2.0 / 3.0) * a2)
    first = (math.pi * half * half) * ((2.0 / 3.0) * a1)
    second = (math.pi * half * half * half) * ((2.0 / 3.0) * a0 + 0.4 * a2)
    disk = (0.25 * math.pi * half) * (2.0 * (a0 * a0) + 4.0 * (a0 * a2) + 0.4 * (a2 * a2))
    mass = density * volume.sum()
    balance = density * (mid * volume + first).sum() / mass
    d = mid - balance
    q1 = d * volume + first
    moi_centroid = density * (d * (q1 + first) + second + disk).sum()
    return mass, balance, moi_centroid


def exit_speed(x_from_pivot, moi_pivot, cor):
    """The rigid-pivot model's exit speed (paper-notes.md section 3)."""
    u, w, m = BALL_SPEED_MPS, OMEGA_RAD_S, BALL_MASS_KG
    return -u + moi_pivot * (1.0 + cor) * (u + w * x_from_pivot) / (moi_pivot + m * x_from_pivot**2)


def exit_speed_slope(x, moi_pivot, cor):
    """d v2 / dx, up to the positive factor J (1 + e) / (J + m x^2)^2."""
    u, w, m = BALL_SPEED_MPS, OMEGA_RAD_S, BALL_MASS_KG
    return w * (moi_pivot + m * x * x) - 2.0 * m * x * (u + w * x)


def max_exit_speed_closed_form(moi_pivot, length, cor):
    """Its maximum on the bat, in closed form (the maximiser clamped to the tip)."""
    u, w, m = BALL_SPEED_MPS, OMEGA_RAD_S, BALL_MASS_KG
    s = math.sqrt(u * u + w * w * moi_pivot / m)
    x = w * moi_pivot / (m * (u + s))
    if x <= length - PIVOT_FROM_KNOB_M:
        return ((1.0 + cor) * s - (1.0 - cor) * u) / 2.0
    return exit_speed(length - PIVOT_FROM_KNOB_M, moi_pivot, cor)


# ------------------------------------------------------------------------------------------
# The 16-knot design.

def knot_bat(n=16):
    length = 0.86
    xs, rs = [], []
    for i in range(n):
        x = length * i / (n - 1)
        s = x / length
        xs.append(x)
        rs.append(0.0125 + 0.020 / (1.0 + math.exp(-14.0 * (s - 0.55))))
    return np.array(xs), np.array(rs)


def design(n, repeat):
    """The n-knot design (design16 generalised: knots 1..n-2 free)."""
    xs, r_base = knot_bat(n)
    length = xs[-1]
    lo, hi = 0.0110, 0.0332
    max_r = 0.5 * 2.61 * 0.0254
    min_r = 0.5 * 0.9 * 0.0254
    mass0, _, _ = mass_properties(xs, r_base, ASH_DENSITY_KG_M3)

    def radii(v):
        r = r_base.copy()
        r[1:n - 1] = v
        return r

    def objective(v):
        mass, balance, moi_c = mass_properties(xs, radii(v), ASH_DENSITY_KG_M3)
        d = PIVOT_FROM_KNOB_M - balance
        return -max_exit_speed_closed_form(moi_c + mass * d * d, length, ASH_COR)

    def equality(v):
        return np.array([mass_properties(xs, radii(v), ASH_DENSITY_KG_M3)[0] - mass0])

    def inequalities(v):  # >= 0
        r = radii(v)
        balance = mass_properties(xs, r, ASH_DENSITY_KG_M3)[1]
        return np.concatenate(([0.60 - balance], max_r - r, r - min_r, r[1:] - r[:-1]))

    v0 = r_base[1:n - 1].copy()
    constraints = [{"type": "eq", "fun": equality}, {"type": "ineq", "fun": inequalities}]
    bounds = [(lo, hi)] * (n - 2)
    best = best_cpu = math.inf
    result = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        c0 = time.process_time()
        result = minimize(objective, v0, method="SLSQP", bounds=bounds, constraints=constraints,
                          options={"ftol": 1e-10, "maxiter": 300})
        best_cpu = min(best_cpu, time.process_time() - c0)
        best = min(best, time.perf_counter() - t0)
    r_opt = radii(result.x)
    mass, balance, _ = mass_properties(xs, r_opt, ASH_DENSITY_KG_M3)
    request = {
        "bat": {"profile": {"knots": [{"x_m": float(x), "radius_m": float(r)}
                                      for x, r in zip(xs, r_base)]},
                "material": "ash"},
        "variables": [{"path": f"profile.knots[{i}].radius_m", "min": lo, "max": hi}
                      for i in range(1, n - 1)],
        "constraints": {"mass_kg": float(mass0), "balance_point_m": {"max": 0.60},
                        "max_barrel_diameter_m": 2.61 * 0.0254,
                        "min_handle_diameter_m": 0.9 * 0.0254, "taper": "non_decreasing"},
        "objective": "max_exit_speed",
    }
    return {
        "peer": "scipy.optimize.minimize SLSQP, finite-difference gradients, ftol 1e-10",
        "knots": n,
        "time_s": best,
        "cpu_s": best_cpu,
        "repeat": repeat,
        "success": bool(result.success),
        "message": str(result.message),
        "iterations": int(result.nit),
        "function_evaluations": int(result.nfev),
        "objective_mps": -float(result.fun),
        "radii_m": [float(r) for r in r_opt],
        "mass_kg": float(mass),
        "mass_error_kg": float(mass - mass0),
        "balance_point_m": float(balance),
        "request": request,
    }


# ------------------------------------------------------------------------------------------
# The sweep.

def three_segment_knots(shape):
    length = shape["length_m"]
    r1, r2 = shape["handle_radius_m"], shape["barrel_radius_m"]
    x1, x2 = shape["taper_start_m"], shape["taper_end_m"]
    # Four knots; a zero-length segment (x1 = 0, x1 = x2 or x2 = L) contributes nothing.
    return np.array([0.0, x1, x2, length]), np.array([r1, r1, r2, r2])


def bounded_search(moi_pivot, length, cor):
    """The paper's approach: a bounded scalar search of the exit speed over the bat."""
    res = minimize_scalar(lambda x: -exit_speed(x - PIVOT_FROM_KNOB_M, moi_pivot, cor),
                          bounds=(0.0, length), method="bounded", options={"xatol": SWEEP_XATOL_M})
    return -res.fun, res.x


def root_search(moi_pivot, length, cor):
    """The stationarity condition's root on the bat (an end when the slope keeps its sign)."""
    a, b = -PIVOT_FROM_KNOB_M, length - PIVOT_FROM_KNOB_M
    sa, sb = exit_speed_slope(a, moi_pivot, cor), exit_speed_slope(b, moi_pivot, cor)
    if sa <= 0.0:
        x = a
    elif sb >= 0.0:
        x = b
    else:
        x = brentq(exit_speed_slope, a, b, args=(moi_pivot, cor), xtol=ROOT_XTOL_M)
    return exit_speed(x, moi_pivot, cor), x + PIVOT_FROM_KNOB_M


def sweep(request_path, rows_path, limit, variant):
    with open(request_path) as f:
        template = json.load(f)
    designs = []
    with open(rows_path) as f:
        for line in f:
            row = json.loads(line)
            if "summary" in row:
                continue
            if not row.get("feasible", False):
                continue
            shape = dict(template["bat"]["three_segment"])
            for path, value in row["parameters"].items():
                shape[path.split(".", 1)[1]] = value
            designs.append((shape, row["max_exit_speed"]))
            if limit and len(designs) >= limit:
                break
    density = ASH_DENSITY_KG_M3
    cor = template.get("cor", ASH_COR)
    prepared = [three_segment_knots(shape) for shape, _ in designs]
    search = bounded_search if variant == "bounded" else root_search
    answers = []
    t0 = time.perf_counter()
    c0 = time.process_time()
    for xs, rs in prepared:
        mass, balance, moi_c = mass_properties(xs, rs, density)
        d = PIVOT_FROM_KNOB_M - balance
        answers.append(search(moi_c + mass * d * d, xs[-1], cor))
    cpu = time.process_time() - c0
    elapsed = time.perf_counter() - t0
    d_speed = max(abs(a[0] - ref["exit_speed_mps"]) for a, (_, ref) in zip(answers, designs))
    d_pos = max(abs(a[1] - ref["position_from_knob_m"]) for a, (_, ref) in zip(answers, designs))
    return {
        "peer": ("numpy mass properties + scipy.optimize.minimize_scalar(bounded, xatol "
                 f"{SWEEP_XATOL_M:g} m) per design" if variant == "bounded" else
                 "numpy mass properties + scipy.optimize.brentq on dv2/dx "
                 f"(xtol {ROOT_XTOL_M:g} m) per design"),
        "variant": variant,
        "designs": len(designs),
        "time_s": elapsed,
        "cpu_s": cpu,
        "us_per_design": 1e6 * elapsed / len(designs),
        "cpu_us_per_design": 1e6 * cpu / len(designs),
        "max_abs_diff_exit_speed_mps": d_speed,
        "max_abs_diff_position_m": d_pos,
    }


def main(argv):
    if len(argv) >= 2 and argv[1] in ("design16", "design"):
        repeat = int(argv[argv.index("--repeat") + 1]) if "--repeat" in argv else 5
        n = int(argv[argv.index("--knots") + 1]) if "--knots" in argv else 16
        print(json.dumps(design(n, repeat)))
        return 0
    if len(argv) >= 4 and argv[1] == "sweep":
        limit = int(argv[argv.index("--limit") + 1]) if "--limit" in argv else 0
        variant = argv[argv.index("--variant") + 1] if "--variant" in argv else "bounded"
        print(json.dumps(sweep(argv[2], argv[3], limit, variant)))
        return 0
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
