#!/usr/bin/env python3
"""Writes meshes/stl-die.stl, the die of meshes/stl-die.toml: the lower cap of an ellipsoid with
semi-axes A = 100 (x1), B = 50 (x2), C = 50 (x3) whose lowest point touches the plate's top face
(x3 = 0.5) at the origin. Curvature radii at the touching point: A^2/C = 200 along x1 and
B^2/C = 50 along x2 (no built-in shape has them). The cap reaches 70 degrees from the pole, past the
quarter plate's corner. An open surface: N_THETA rings of N_PHI segments, a fan at the pole,
facet normals pointing out of the ellipsoid (down, to the plate). Binary STL, 3008 facets.

    python3 meshes/stl-die.py            # from the repository's root
"""
import math
import os
import struct

A, B, C = 100.0, 50.0, 50.0
TOP = 0.5                      # the plate's top face
THETA_MAX = math.radians(70.0)
N_THETA, N_PHI = 24, 64


def point(theta, phi):
    return (A * math.sin(theta) * math.cos(phi), B * math.sin(theta) * math.sin(phi), TOP + C * (1.0 - math.cos(theta)))


def outward(p):
    """The ellipsoid's outward gradient at p."""
    return (p[0] / A**2, p[1] / B**2, (p[2] - TOP - C) / C**2)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def facets():
    pole = point(0.0, 0.0)
    rings = [[point(THETA_MAX * k / N_THETA, 2.0 * math.pi * j / N_PHI) for j in range(N_PHI)] for k in range(1, N_THETA + 1)]
    out = []
    for j in range(N_PHI):
        out.append((pole, rings[0][j], rings[0][(j + 1) % N_PHI]))
    for k in range(N_THETA - 1):
        for j in range(N_PHI):
            a, b = rings[k][j], rings[k][(j + 1) % N_PHI]
            c, d = rings[k + 1][j], rings[k + 1][(j + 1) % N_PHI]
            out.append((a, c, d))
            out.append((a, d, b))
    # orient every facet so that its normal points out of the ellipsoid
    oriented = []
    for f in out:
        n = cross(sub(f[1], f[0]), sub(f[2], f[0]))
        centroid = tuple(sum(v[i] for v in f) / 3.0 for i in range(3))
        oriented.append(f if dot(n, outward(centroid)) > 0.0 else (f[0], f[2], f[1]))
    return oriented


def main():
    fs = facets()
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "stl-die.stl")
    with open(path, "wb") as f:
        f.write(b"stamp meshes/stl-die.py: ellipsoidal cap A=100 B=50 C=50".ljust(80, b" "))
        f.write(struct.pack("<I", len(fs)))
        for t in fs:
            n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
            l = math.sqrt(dot(n, n))
            f.write(struct.pack("<3f", *(x / l for x in n)))
            for v in t:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")
    print(f"{path}: {len(fs)} facets")


if __name__ == "__main__":
    main()
