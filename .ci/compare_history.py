#!/usr/bin/env python3
"""Compare two history.csv files column by column: the same header, the same steps, and every
value within TOL relative to its column's scale, |a - b| <= TOL * scale, the scale being the
largest magnitude in the column (both files) and, for the displacement columns (names ending
_u1, _u2, _u3), the largest displacement of any of them: a displacement that is zero by symmetry
holds round-off (1e-17) and is judged on the size of the displacements, not on its own noise;
likewise a punch's force components (_force_x1, _x2, _x3) on the size of its force, and a
support group's reaction components (<group>_reaction_x1, _x2, _x3) on the size of the largest
force of the run, any punch force or support reaction (the supports balance the punches and the
loads: a component that is zero by symmetry, or the small share of a lightly loaded group, holds
round-off of the forces in play; at least FORCE_FLOOR, for a run with no force in play).
Prints the worst column; exit 1 on a difference."""
import csv
import sys

TOL = 1e-8
REACTION = ("_reaction_x1", "_reaction_x2", "_reaction_x3")
FORCE = ("_force", "_force_x1", "_force_x2", "_force_x3")
# the smallest force scale the reaction columns are judged on
FORCE_FLOOR = 1e-4


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def main(ref_path, new_path, tol=TOL):
    h1, r1 = read(ref_path)
    h2, r2 = read(new_path)
    if h1 != h2:
        print(f"{new_path}: header differs from {ref_path}:\n  {h1}\n  {h2}")
        return 1
    if len(r1) != len(r2):
        print(f"{new_path}: {len(r2)} steps, {ref_path}: {len(r1)}")
        return 1
    def numbers(c):
        try:
            return [float(r[c]) for r in r1 + r2]
        except ValueError:
            return []

    displacement = [c for c, name in enumerate(h1) if name.endswith(("_u1", "_u2", "_u3"))]
    u_scale = max([abs(x) for c in displacement for x in numbers(c)] + [0.0])
    forces = [c for c, name in enumerate(h1) if name.endswith(REACTION + FORCE)]
    f_scale = max([abs(x) for c in forces for x in numbers(c)] + [0.0])
    worst = (0.0, "", 0)
    for c, name in enumerate(h1):
        try:
            a = [float(r[c]) for r in r1]
            b = [float(r[c]) for r in r2]
        except ValueError:
            if [r[c] for r in r1] != [r[c] for r in r2]:
                print(f"{new_path}: column {name} differs")
                return 1
            continue
        scale = u_scale if c in displacement else max([abs(x) for x in a + b] + [0.0])
        # a punch's force components (<punch>_force_x1, _x2, _x3): judged on the size of its
        # force, as displacements are (a frictionless punch's tangential components are round-off)
        for suffix in ("_force_x1", "_force_x2", "_force_x3"):
            if name.endswith(suffix):
                punch = name[: -len(suffix)]
                scale = max([abs(x) for k, n in enumerate(h1) if n.startswith(punch + "_force") for x in numbers(k)] + [0.0])
        if name.endswith(REACTION):
            # a run with no force in play at all (a strip rolled by end couples: every reaction
            # is the round-off, 1e-16, of the couple's face forces cancelling) is judged on
            # FORCE_FLOOR: its reactions are zero to that
            scale = max(f_scale, FORCE_FLOOR)
        for k, (x, y) in enumerate(zip(a, b)):
            d = abs(x - y) / scale if scale > 0 else 0.0
            if d > worst[0]:
                worst = (d, name, k + 1)
    d, name, row = worst
    status = "ok" if d <= tol else "DIFFERS"
    print(f"{status}: {new_path} against {ref_path}: largest difference {d:.2e} of its column's scale ({name}, row {row}; tolerance {tol:.0e})")
    return 0 if d <= tol else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else TOL))
