#!/usr/bin/env python3
"""The capstan: a plate strip wrapped around a fixed rigid cylinder (R = 100) with Coulomb friction
and pulled at its ends with unequal tensions. At the onset of slip a belt (no bending stiffness,
no thickness) has T2 / T1 = e^(mu phi), phi the wrap angle; docs/verification/friction.md has
the table for h = 2, 1, 0.5 and why the plate departs from it.

    python3 verification/capstan.py write 1.0 > capstan-h1.toml     # the problem for h = 1
    stamp run capstan-h1.toml --out capstan-h1
    python3 verification/capstan.py table capstan-h2 capstan-h1 capstan-h05

The strip: the paper's plate (E = 2e4, nu = 0.3, plane strain, one cell across x1), x2 in
[-130, 130] (cells of 1), touching the cylinder (axis along x1, 100 above the strip's mid-plane
plus h/2) at x2 = 0 with its top face; mu = 0.3. The load path (`path` rows on `[[load]]` and
`[[boundary]]`, load factor t):

* t in [0, 0.05]: end 1 (x2 = 130, group `top`) is pulled along +x2 by T1 = 100 per unit width
  (a dead line load at the mid-surface), end 2 (x2 = -130, group `bottom`) is pinned (its bottom
  face's v2 and v3 held): a straight strip in tension, touching the cylinder at one line;
* t in [0.05, 0.5]: end 1's force turns to 45 degrees above +x2 (two dead loads, along x2 and
  x3, their factors cos and sin of the angle at 8 rows), and end 2's pin is carried along the
  mirror image of that wrap (the strip's bottom face on the tangent from the departure point at
  the same angle): the strip wraps phi = 90 degrees of the cylinder;
* t in [0.5, 1]: end 2 is pulled on along its free part by 0.6 / h: the strip slides around the
  cylinder against friction (every contact point slips), end 1 held by its constant dead load T1.

T2 is the magnitude of end 2's reaction (history.csv `bottom_reaction_x2`, `_x3`), T1 = 100; the
wrap angle phi is 45 degrees (end 1's force) plus the angle of end 2's reaction above -x2.
"""
import csv
import json
import math
import sys

R = 100.0
E = 2.0e4
NU = 0.3
MU = 0.3
T1 = 100.0
HALF = 130.0
WRAP = math.pi / 4  # on each side
ROWS = 8


def fmt(rows):
    return "[" + ", ".join(f"[{t:.6g}, {v:.12g}]" for t, v in rows) + "]"


def problem(h, cells_per_unit=1.0, mu=MU):
    rho = R + h / 2  # the mid-surface's radius on the cylinder
    axis = R + h / 2  # height of the axis: the top face touches at x2 = 0
    along, up = [(0.05, 1.0)], [(0.05, 0.0)]
    pin2, pin3 = [(0.05, 0.0)], [(0.05, 0.0)]
    for k in range(1, ROWS + 1):
        th = WRAP * k / ROWS
        t = 0.05 + 0.45 * k / ROWS
        # end 2 mirrors the wrap: contact up to angle th, then straight along the tangent
        dep = (-rho * math.sin(th), axis - rho * math.cos(th))
        free = HALF - rho * th
        mid = (dep[0] - free * math.cos(th), dep[1] + free * math.sin(th))
        bottom = (mid[0] - h / 2 * math.sin(th), mid[1] - h / 2 * math.cos(th))
        along.append((t, math.cos(th)))
        up.append((t, math.sin(th)))
        pin2.append((t, bottom[0] + HALF))
        pin3.append((t, bottom[1] + h / 2))
    # the pull: beyond the elastic stretch of the wrapped part that friction holds, ~ (T2 - T1) / (E h)
    pull = 0.6 / h
    pin2.append((1.0, pin2[-1][1] - pull * math.cos(WRAP)))
    pin3.append((1.0, pin3[-1][1] + pull * math.sin(WRAP)))
    n = int(round(2 * HALF * cells_per_unit))
    return f'''# The capstan (verification/capstan.py writes this file; its docstring explains the load path):
# a strip of thickness h = {h} wrapped 90 degrees around a fixed cylinder (R = 100, mu = {mu}),
# pulled at end 2 while end 1 is held by a dead load T1 = 100. At the onset of slip T2 / T1 tends
# to e^(mu phi) = {math.exp(mu * math.pi / 2):.6f} as h / R falls (docs/verification/friction.md).
title = "capstan: a strip of h = {h} wrapped around a fixed cylinder with friction, pulled at its ends"

[mesh]
rectangle = {{ x = [0.0, 1.0], y = [-{HALF}, {HALF}], n = [1, {n}] }}

[plate]
thickness = {h}
E = {E}
nu = {NU}
plane_strain = true

# end 2: pinned at its bottom face, carried along the wrap, then pulled along its free part
[[boundary]]
group = "bottom"
prescribe = {{ "v2-" = 1.0 }}
path = {fmt(pin2)}

[[boundary]]
group = "bottom"
prescribe = {{ "v3-" = 1.0 }}
path = {fmt(pin3)}

# end 1: T1 = {T1} per unit width, along +x2 first, turned to 45 degrees above it by t = 0.5
[[load]]
type = "line"
group = "top"
force = [0.0, {T1}, 0.0]
path = {fmt(along)}

[[load]]
type = "line"
group = "top"
force = [0.0, 0.0, {T1}]
path = {fmt(up)}

[[punch]]
name = "cylinder"
shape = "cylinder"
point = [0.0, 0.0, {axis!r}]
axis = [1.0, 0.0, 0.0]
radius = {R}
face = "top"
friction = {mu}

[solver]
targets = [0.05, 0.5, 1.0]
max_increment = 0.02
max_steps = 5000

[output]
vtu = false
plot = false
csv = false
'''


def ratio(out, mu=MU):
    """T2 / T1, the wrap angle, and the run's counts at the last step of the run in `out`."""
    rows = list(csv.DictReader(open(f"{out}/history.csv")))
    steps = json.load(open(f"{out}/summary.json"))["steps"]
    last = rows[-1]
    r2, r3 = float(last["bottom_reaction_x2"]), float(last["bottom_reaction_x3"])
    t2 = math.hypot(r2, r3)
    phi = WRAP + math.atan2(r3, -r2)
    cyl = steps[-1]["punches"]["cylinder"]
    return {
        "t": float(last["load_factor"]),
        "ratio": t2 / T1,
        "phi_deg": math.degrees(phi),
        "err_nominal": t2 / T1 / math.exp(mu * math.pi / 2) - 1,
        "err_phi": t2 / T1 / math.exp(mu * phi) - 1,
        "sticking": cyl.get("sticking_nodes"),
        "slipping": cyl.get("slipping_nodes"),
        "steps": len(steps),
        "newton_per_step": sum(s["newton_iterations"] for s in steps) / len(steps),
        "cutbacks": sum(s.get("cutbacks", 0) for s in steps),
    }


def main():
    if len(sys.argv) >= 3 and sys.argv[1] == "write":
        cells = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
        print(problem(float(sys.argv[2]), cells), end="")
    elif len(sys.argv) >= 3 and sys.argv[1] == "table":
        print(f"e^(mu pi/2) = {math.exp(MU * math.pi / 2):.6f}")
        print("| run | T2 / T1 | error against e^(mu pi/2) | phi (deg) | error against e^(mu phi) | slipping / sticking | steps | Newton a step | cut-backs |")
        print("|---|---|---|---|---|---|---|---|---|")
        for out in sys.argv[2:]:
            r = ratio(out)
            print(f"| {out} | {r['ratio']:.6f} | {r['err_nominal']:+.3%} | {r['phi_deg']:.3f} | {r['err_phi']:+.3%} | {r['slipping']} / {r['sticking']} | {r['steps']} | {r['newton_per_step']:.1f} | {r['cutbacks']} |")
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
