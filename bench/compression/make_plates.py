#!/usr/bin/env python3
"""Writes the six plates of the compression benchmark (bench/compression):
square ASCII STL plates of side 2*H*1.1, each an N x N grid of squares cut
into two triangles (2 N^2 triangles; N = 13 gives 338, the size of the
user's plates that the performance issue describes), placed on the faces of
the cube [-H, H]^3 with normals pointing in.

Usage: make_plates.py DIR [H]"""
import os, sys

N = 13


def plate(axis, side, h):
    """Triangles of the plate at coordinate side*h on `axis`."""
    a = h * 1.1
    u, w = [(k) for k in range(3) if k != axis]
    tris = []
    for i in range(N):
        for j in range(N):
            def p(ii, jj):
                q = [0.0, 0.0, 0.0]
                q[axis] = side * h
                q[u] = -a + 2 * a * ii / N
                q[w] = -a + 2 * a * jj / N
                return q
            tris.append((p(i, j), p(i + 1, j), p(i + 1, j + 1)))
            tris.append((p(i, j), p(i + 1, j + 1), p(i, j + 1)))
    return tris


def write(path, tris):
    with open(path, "w") as f:
        f.write("solid plate\n")
        for t in tris:
            f.write("  facet normal 0 0 0\n    outer loop\n")
            for v in t:
                f.write(f"      vertex {v[0]:.9e} {v[1]:.9e} {v[2]:.9e}\n")
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid plate\n")


def main():
    d = sys.argv[1]
    h = float(sys.argv[2]) if len(sys.argv) > 2 else 0.05
    os.makedirs(d, exist_ok=True)
    for axis, name in enumerate("xyz"):
        for side, s in ((-1, "lo"), (1, "hi")):
            write(os.path.join(d, f"plate_{name}{s}.stl"), plate(axis, side, h))


if __name__ == "__main__":
    main()
