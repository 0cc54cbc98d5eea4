#!/usr/bin/env python3
"""A cohesive-crack reference for the 2D split cylinder: the fictitious crack of Hillerborg
et al. (1976) on the loaded diameter of a plane-stress finite-element disc, the analysis of
Rocco et al. (1999, "Size effect and boundary conditions in the Brazilian test: theoretical
analysis") for sppm's own concrete, strips and size.

Usage:
  python3 benchmarks/cohesive_split_cylinder.py [--n N] [--strip B] [--ft FT] [--gf GF]
      [--e E] [--steps S] [--opening W] [--elastic]

It solves lattices/split_cylinder.toml's cylinder (D = 150 mm, H = 300 mm, plane stress,
nu = 0.2; f't, G_f and E as that scene derives them: 3.199 MPa, 102.2 N/m, 30.73 GPa) with the
softening law of docs/model.md §8 (bilinear, alpha = 0.1, gamma = 0.25; the law is
benchmarks/cohesive_beam.py's). The crack can open only on the loaded diameter, as a
cohesive interface; everything else is elastic (no crushing under the strips). A quarter of
the disc by symmetry: x >= 0 (the crack plane x = 0, its springs opening by w = 2·u_x) and
y >= 0 (u_y = 0 on y = 0). The unit square is mapped onto the quarter disc
(x = R·u·sqrt(1 − v²/2), y = R·v·sqrt(1 − u²/2)) with N × N bilinear quadrilaterals; the
arc's nodes with x <= b/2 are the strip, held in x and pushed down in small steps (as the
scene grips its strip particles), each solved by Newton's method.

It prints the peak load and its ratio to (5.6), P = (pi/2)·f't·D·H/(1 − beta²)^1.5 with
beta = b/D (docs/validation.md). --elastic instead prints the centre's sigma_xx per unit
load against (5.6)'s, the check of the mesh and the strip. Needs numpy and scipy.
"""
import argparse
import math
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cohesive_beam import Law

NU, D, H = 0.2, 0.15, 0.30
R = D / 2


def mapped(u, v):
    """The unit square's point (u, v) on the quarter disc (m)."""
    return R * u * math.sqrt(1 - v * v / 2), R * v * math.sqrt(1 - u * u / 2)


def q4(xy, e):
    """Plane-stress stiffness (8×8) and the centre's strain–displacement matrix of the
    bilinear quadrilateral with corners xy (4×2, counter-clockwise), thickness H."""
    d = e / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]

    def b_matrix(xi, eta):
        dn = np.array(
            [[c[0] * (1 + c[1] * eta) / 4 for c in corners], [c[1] * (1 + c[0] * xi) / 4 for c in corners]]
        )
        jac = dn @ xy
        dx = np.linalg.solve(jac, dn)
        bm = np.zeros((3, 8))
        bm[0, 0::2] = dx[0]
        bm[1, 1::2] = dx[1]
        bm[2, 0::2] = dx[1]
        bm[2, 1::2] = dx[0]
        return bm, np.linalg.det(jac)

    k = np.zeros((8, 8))
    g = 1 / math.sqrt(3)
    for xi in (-g, g):
        for eta in (-g, g):
            bm, det = b_matrix(xi, eta)
            k += bm.T @ d @ bm * det * H
    return k, d @ b_matrix(0.0, 0.0)[0]


class Disc:
    """The quarter disc's mesh, stiffness, crack springs and strip."""

    def __init__(self, n, strip, e):
        node = lambda i, j: j * (n + 1) + i
        pts = np.array([mapped(i / n, j / n) for j in range(n + 1) for i in range(n + 1)])
        nn = len(pts)
        rows, cols, vals = [], [], []
        self.centre_stress = None
        for j in range(n):
            for i in range(n):
                c = [node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]
                ke, sb = q4(pts[c], e)
                dofs = np.array([[2 * a, 2 * a + 1] for a in c]).ravel()
                rows.append(np.repeat(dofs, 8))
                cols.append(np.tile(dofs, 8))
                vals.append(ke.ravel())
                if i == 0 and j == 0:
                    self.centre_stress = (sb, dofs)
        self.k = sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * nn, 2 * nn)
        )
        # the crack plane x = 0: nodes (0, j), tributary lengths along y
        ys = pts[[node(0, j) for j in range(n + 1)], 1]
        lo = np.concatenate([[0.0], (ys[:-1] + ys[1:]) / 2])
        hi = np.concatenate([(ys[:-1] + ys[1:]) / 2, [R]])
        area = (hi - lo) * H
        self.crack = np.array([2 * node(0, j) for j in range(n + 1)])
        # the strip: the arc's nodes (edge v = 1) with x <= b/2
        top = [node(i, n) for i in range(n + 1) if pts[node(i, n), 0] <= strip / 2 + 1e-12]
        self.strip_y = np.array([2 * a + 1 for a in top])
        strip_x = np.array([2 * a for a in top])
        sym_y = np.array([2 * node(i, 0) + 1 for i in range(n + 1)])
        self.fixed = np.unique(np.concatenate([self.strip_y, strip_x, sym_y]))
        self.free = np.setdiff1d(np.arange(2 * nn), self.fixed)
        # the crack node under the strip is held in x with the strip: not a spring
        spring = ~np.isin(self.crack, strip_x)
        self.springs, self.spring_area = self.crack[spring], area[spring]


def p56(ft, strip):
    """(5.6): the load at which the disc's centre reaches f't under strips of width b."""
    beta = strip / D
    return math.pi / 2 * ft * D * H / (1 - beta**2) ** 1.5


def elastic_check(disc, strip):
    """The centre's sigma_xx (in the crack plane's first element) per unit load, over (5.6)'s."""
    u = np.zeros(disc.k.shape[0])
    u[disc.strip_y] = -1e-5
    free = np.setdiff1d(disc.free, disc.crack)  # uncracked: the diameter is a symmetry plane
    kf = disc.k[free][:, free].tocsc()
    u[free] = spla.spsolve(kf, -(disc.k @ u)[free])
    load = 2 * -(disc.k @ u)[disc.strip_y].sum()
    sb, dofs = disc.centre_stress
    sxx = (sb @ u[dofs])[0]
    beta = strip / D
    theory = 2 * load / (math.pi * D * H) * (1 - beta**2) ** 1.5
    return sxx, theory


def solve(disc, law, steps, opening):
    """Load against strip displacement, the centre's crack opening w_c pushed up in `steps`
    equal steps to `opening` (indirect control: the strip's displacement is the unknown that
    keeps the centre node in equilibrium, so the load may fall as the crack runs)."""
    k, dof, area = disc.k, disc.springs, disc.spring_area
    centre = disc.crack[0]
    unknown = np.setdiff1d(disc.free, [centre])  # the displacements solved for, and delta
    rows = disc.free  # the equilibrium equations: every free node, the centre's included
    g = np.zeros(k.shape[0])
    g[disc.strip_y] = -1.0  # d u / d delta
    u = np.zeros(k.shape[0])
    delta = 0.0
    wmax = np.zeros(len(dof))
    out = []
    for step in range(1, steps + 1):
        u[centre] = opening * step / steps / 2
        for _ in range(80):
            u[disc.strip_y] = -delta
            w = 2 * u[dof]
            tt = np.array([law.traction(wi, wm) for wi, wm in zip(w, wmax)])
            f = k @ u
            f[dof] += tt[:, 0] * area
            r = f[rows]
            norm = np.linalg.norm(r)
            if norm < 1e-8 * (np.linalg.norm(f[disc.strip_y]) + 1.0):
                break
            kt = (k + sp.csr_matrix((2 * tt[:, 1] * area, (dof, dof)), shape=k.shape)).tocsr()
            col = (kt @ g)[rows]
            jac = sp.hstack([kt[rows][:, unknown], sp.csr_matrix(col).T]).tocsc()
            step_ = spla.spsolve(jac, -r)
            u[unknown] += step_[:-1]
            delta += step_[-1]
        else:
            print(f"step {step}: Newton did not converge (residual {norm:.3e} N); stopped", file=sys.stderr)
            break
        wmax = np.maximum(wmax, 2 * u[dof])
        load = 2 * -(k @ u)[disc.strip_y].sum()
        out.append((delta, load, 2 * u[centre]))
    return out


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--n", type=int, default=60)
    a.add_argument("--strip", type=float, default=0.025)
    a.add_argument("--ft", type=float, default=3.1990232759e6)
    a.add_argument("--gf", type=float, default=102.20591546)
    a.add_argument("--e", type=float, default=30.727184107e9)
    a.add_argument("--steps", type=int, default=200)
    a.add_argument("--opening", type=float, default=1e-4)
    a.add_argument("--elastic", action="store_true")
    o = a.parse_args()
    disc = Disc(o.n, o.strip, o.e)
    if o.elastic:
        sxx, theory = elastic_check(disc, o.strip)
        print(f"n {o.n}, strip {o.strip * 1e3:g} mm: centre sigma_xx {sxx:.5e} Pa, (5.6)'s {theory:.5e} Pa, ratio {sxx / theory:.4f}")
        return
    law = Law(o.ft, o.gf, kp=1e3 * o.e / (R / o.n))
    out = solve(disc, law, o.steps, o.opening)
    i = max(range(len(out)), key=lambda k: out[k][1])
    lch = o.e * o.gf / o.ft**2
    print(
        f"n {o.n}, strip {o.strip * 1e3:g} mm, f't {o.ft:.4g} Pa, G_f {o.gf:g} N/m, l_ch {lch * 1e3:.0f} mm "
        f"(D/l_ch {D / lch:.3f}): peak {out[i][1] / 1e3:.2f} kN at a strip displacement of {out[i][0] * 1e3:.4f} mm, "
        f"centre opening {out[i][2] * 1e6:.2f} um; (5.6) {p56(o.ft, o.strip) / 1e3:.2f} kN, ratio {out[i][1] / p56(o.ft, o.strip):.4f}; "
        f"{len(out)} of {o.steps} steps, last load {out[-1][1] / 1e3:.2f} kN"
    )


if __name__ == "__main__":
    main()
