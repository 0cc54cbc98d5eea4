#!/usr/bin/env python3
"""A cohesive-crack reference for the 3D split cylinder: the fictitious crack of Hillerborg
et al. (1976) on the loaded diametral plane of a finite-element cylinder with free end faces,
for sppm's own softening law and lattices/split_cylinder_3d.toml's concrete.

Usage:
  python3 benchmarks/cohesive_split_cylinder_3d.py [--n N] [--nz NZ] [--b B] [--ft FT]
      [--gf GF] [--e E] [--steps S] [--volume V] [--plane] [--sliding] [--trace]

One eighth of the cylinder (D = 150 mm, H = 300 mm, nu = 0.2) in trilinear hexahedra, the
mesh of benchmarks/split_cylinder_fem.py (the quarter disc by the square-to-disc map, the
length graded towards the free end face z = 0). Symmetry planes y = 0 and z = H/2. The plane
x = 0 is the crack: each of its nodes is a cohesive spring (its lumped share of the plane's
area) that follows docs/model.md §8's law of the opening w = 2·u_x (benchmarks/cohesive_beam.py's
Law: stiff until f't, then bilinear softening, alpha = 0.1, gamma = 0.25, COD_c from G_f by
(5.4)); compression stays elastic, nothing else cracks or crushes. The bearing strip of width
b is rigid and grips: the surface nodes with x <= b/2 at the top are held in x and pushed down
by delta, free in z. With --plane every node is also held in z (plane strain, no end faces).

The body is elastic, so it is condensed once onto the crack's springs and delta (one sparse
LU of the body, one solve per spring); the crack is then solved by Newton's method on that
dense system. The control is the crack's opened volume (the sum of each spring's area times
its opening, which grows wherever the crack opens), pushed up in --steps equal steps to
--volume; delta is an unknown, so the load may fall as the crack runs.

It prints the peak load over pi·L·D·f't/2 and over (5.6) with beta = b/D, the opening at the
peak at the end face's centre and at mid-length, how far from the face the crack has passed
f't along the axis, and where and at which load the uncracked cylinder's crack plane first
reaches f't. --trace prints every step. Needs numpy and scipy.
"""
import argparse
import math
import sys

import numpy as np
import scipy.sparse.linalg as spla

from cohesive_beam import Law
from split_cylinder_fem import mesh, stiffness

NU, D, H = 0.2, 0.15, 0.30
R = D / 2


class Cylinder:
    """The eighth cylinder condensed onto its crack springs and the strip's displacement."""

    def __init__(self, n, nz, strip, e, plane, sliding=False):
        nodes, hexes, _ = mesh(n, nz, R, H / 2, 2.0)
        k, _, _ = stiffness(nodes, hexes, e, NU)
        x, y, z = nodes.T
        tol = 1e-9
        held = set(3 * np.where(y < tol)[0] + 1)
        held |= set(3 * np.where(z > H / 2 - tol)[0] + 2)
        if plane:
            held |= set(3 * np.arange(len(nodes)) + 2)
        on_arc = np.abs(np.hypot(x, y) - R) < 1e-9
        top = np.where(on_arc & (x <= strip / 2 + 1e-9))[0]
        held |= set(3 * (top if not sliding else top[x[top] < tol]))
        self.strip_y = 3 * top + 1
        face = np.where(x < tol)[0]
        spring_nodes = np.setdiff1d(face, top)
        self.springs = 3 * spring_nodes
        self.area = self._lumped_areas(nodes, hexes, spring_nodes)
        self.yz = nodes[spring_nodes][:, 1:]
        inner = np.setdiff1d(np.arange(3 * len(nodes)), np.concatenate([list(held), self.strip_y, self.springs]))
        # unit modes: each spring's u_x, then delta (the strip's y-DOFs move by -delta); the
        # inner DOFs follow in equilibrium. Only the inner rows of k are made dense.
        k_inner = k[inner]
        rhs = np.column_stack([k_inner[:, self.springs].toarray(),
                               -np.asarray(k_inner[:, self.strip_y].sum(axis=1)).ravel()])
        lu = spla.splu(k_inner[:, inner].tocsc())
        full = np.zeros((3 * len(nodes), rhs.shape[1]))
        full[inner] = lu.solve(-rhs)
        full[self.springs, np.arange(len(self.springs))] = 1.0
        full[self.strip_y, -1] = -1.0
        # the generalised forces each unit mode needs: at each spring its x-force; for delta,
        # minus the strip's y-forces
        self.s = np.vstack([k[self.springs] @ full, -(k[self.strip_y] @ full).sum(axis=0)])

    @staticmethod
    def _lumped_areas(nodes, hexes, spring_nodes):
        """Each crack node's share of the plane x = 0: a quarter of each element face it corners."""
        area = dict.fromkeys(spring_nodes.tolist(), 0.0)
        x = nodes[:, 0]
        for h in hexes:
            on = [a for a in h if x[a] < 1e-9]
            if len(on) != 4:
                continue
            p = nodes[on][:, 1:]
            # the four corners in order around the face: sort by angle about their centroid
            c = p.mean(axis=0)
            order = np.argsort(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]))
            q = p[order]
            a4 = 0.5 * abs(np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(q[:, 1], np.roll(q[:, 0], -1)))
            for a in on:
                if a in area:
                    area[a] += a4 / 4
        return np.array([area[a] for a in spring_nodes.tolist()])


def solve(cyl, law, steps, volume, trace=False):
    """Load against delta, the crack's opened volume (the sum of area × opening over the
    plane, which grows whichever part opens) pushed to `volume` in `steps` equal steps."""
    s, area = cyl.s, cyl.area
    m = len(area)
    centre = int(np.argmin(np.hypot(cyl.yz[:, 0], cyl.yz[:, 1])))
    mid = int(np.argmin(np.hypot(cyl.yz[:, 0], cyl.yz[:, 1] - H / 2)))
    v = np.zeros(m + 1)  # the springs' u_x, then delta
    wmax = np.zeros(m)
    jac = np.zeros((m + 1, m + 1))
    jac[m, :m] = 2 * area
    out = []
    for step in range(1, steps + 1):
        target = volume * step / steps
        for _ in range(100):
            w = 2 * v[:m]
            tt = np.array([law.traction(wi, wm) for wi, wm in zip(w, wmax)])
            r = np.append(s[:m] @ v + tt[:, 0] * area, area @ w - target)
            norm = np.linalg.norm(r[:m])
            if norm < 1e-9 * (abs(s[m] @ v) + 1.0) and abs(r[m]) < 1e-9 * target:
                break
            jac[:m] = s[:m]
            jac[np.arange(m), np.arange(m)] += 2 * tt[:, 1] * area
            v -= np.linalg.solve(jac, r)
        else:
            print(f"step {step}: Newton did not converge (residual {norm:.3e} N); stopped", file=sys.stderr)
            break
        w = 2 * v[:m]
        wmax = np.maximum(wmax, w)
        load = 4 * (s[m] @ v)
        top = int(np.argmax(w))
        cracked = wmax > law.w0
        axis = cracked & (cyl.yz[:, 0] < 1e-9)
        reach = cyl.yz[axis, 1].max() if axis.any() else 0.0
        out.append((v[m], load, w[centre], w[mid], int(cracked.sum()), reach))
        if trace:
            print(f"{step:4d} delta {v[m] * 1e3:.5f} mm load {load / 1e3:8.2f} kN face {w[centre] * 1e6:7.3f} um "
                  f"mid {w[mid] * 1e6:7.3f} um widest {w[top] * 1e6:7.3f} um at y {cyl.yz[top][0] * 1e3:5.1f} "
                  f"z {cyl.yz[top][1] * 1e3:5.1f} mm, {out[-1][4]} past f't, on the axis to z {reach * 1e3:5.1f} mm")
    return out


def elastic_cracking_load(cyl, law, ft):
    """The load at which the uncracked cylinder's crack plane first carries f't, and where."""
    s, area = cyl.s, cyl.area
    m = len(area)
    a = s[:m, :m] + np.diag(2 * law.kp * area)
    ux = np.linalg.solve(a, -s[:m, m])
    traction = 2 * law.kp * ux
    load = 4 * (s[m, :m] @ ux + s[m, m])
    top = int(np.argmax(traction))
    return ft / traction[top] * load, cyl.yz[top]


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--n", type=int, default=16)
    a.add_argument("--nz", type=int, default=24)
    a.add_argument("--b", type=float, default=0.0125)
    a.add_argument("--ft", type=float, default=3.1990232759e6)
    a.add_argument("--gf", type=float, default=102.20591546)
    a.add_argument("--e", type=float, default=30.727184107e9)
    a.add_argument("--steps", type=int, default=100)
    a.add_argument("--volume", type=float, default=2e-8, help="the eighth's crack volume at the end (m^3)")
    a.add_argument("--trace", action="store_true")
    a.add_argument("--sliding", action="store_true", help="the strip pushes in y only, free to slide in x")
    a.add_argument("--plane", action="store_true")
    o = a.parse_args()
    cyl = Cylinder(o.n, o.nz, o.b, o.e, o.plane, o.sliding)
    law = Law(o.ft, o.gf, kp=1e3 * o.e / (R / o.n))
    out = solve(cyl, law, o.steps, o.volume, o.trace)
    i = max(range(len(out)), key=lambda k: out[k][1])
    split = math.pi * H * D * o.ft / 2
    p56 = split / (1 - (o.b / D) ** 2) ** 1.5
    first, where = elastic_cracking_load(cyl, law, o.ft)
    print(
        f"n {o.n}, nz {o.nz}{' plane strain' if o.plane else ''}, {'sliding' if o.sliding else 'gripping'} strip {o.b * 1e3:g} mm, "
        f"f't {o.ft:.4g} Pa, G_f {o.gf:g} N/m: peak {out[i][1] / 1e3:.2f} kN = {out[i][1] / split:.4f} x pi·L·D·f't/2 "
        f"= {out[i][1] / p56:.4f} x (5.6), at delta {out[i][0] * 1e3:.4f} mm; opening at the peak "
        f"{out[i][2] * 1e6:.2f} um at the face, {out[i][3] * 1e6:.2f} um at mid-length, {out[i][4]} of "
        f"{len(cyl.area)} springs past f't, on the axis from the face to z = {out[i][5] * 1e3:.1f} mm; {len(out)} of {o.steps} steps, last load {out[-1][1] / 1e3:.2f} kN"
    )
    print(
        f"elastic: f't first reached at {first / 1e3:.2f} kN = {first / split:.4f} x pi·L·D·f't/2, "
        f"at y = {where[0] * 1e3:.1f} mm, z = {where[1] * 1e3:.1f} mm from the end face"
    )


if __name__ == "__main__":
    main()
