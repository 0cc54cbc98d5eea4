#!/usr/bin/env python3
"""A cohesive-crack reference for the three-point bending beams: the fictitious crack of
Hillerborg et al. (1976) on the mid-span plane of a plane-stress finite-element beam.

Usage:
  python3 benchmarks/cohesive_beam.py [--notch A] [--h H] [--ft FT] [--gf GF]
      [--alpha ALPHA] [--gamma GAMMA] [--steps N] [--stroke M] [--csv FILE]

It solves the beam sppm's scenes model (Grégoire et al. (2013), d = 50 mm: length 175 mm,
span 125 mm, width 50 mm; E = 37 GPa, nu = 0.2) with the softening law of docs/model.md §8:
bilinear from (0, f't) through (alpha·COD_c, gamma·f't) to (COD_c, 0), alpha = 0.1,
gamma = 0.25, COD_c = 2·G_f/(f't·(alpha + gamma)) (5.4). No lattice, no crack band, no
particles: the crack can open only on the mid-span plane (where the notch is), as a
cohesive interface whose traction follows the law of its opening w. What it gives is the
peak of the continuum that the particle models should converge to when their softening is
this law.

Half the beam by symmetry (x >= 0 from mid-span), bilinear quadrilaterals of side H
(default 0.625 mm), the notch (depth A, default 0.025 m; 0 for the unnotched beam) a
traction-free part of the mid-span plane, the ligament held by stiff elastic springs (the
uncracked plane) that follow the law once they reach f't (compression stays elastic). The
support is the bottom node at x = 62.5 mm (held in y); the load the top node at mid-span
(the scenes push one column of particles), pushed down in small steps, each solved by
Newton's method (scipy's sparse LU). It prints the peak load, the CMOD at the peak (over the notch mouth and over a 20 mm
base, as lattices/beam_3pb_*_3d.toml read it) and writes load, deflection and both CMODs to
--csv. Needs numpy and scipy.
"""
import argparse
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

E, NU, B = 37e9, 0.2, 0.05
HALF_LENGTH, DEPTH, HALF_SPAN = 0.0875, 0.05, 0.0625
ALPHA, GAMMA = 0.1, 0.25  # the knee of the softening law: concrete.alpha, concrete.gamma


def q4_stiffness(h):
    """Plane-stress stiffness of a square bilinear element of side h and thickness B
    (2×2 Gauss points), DOFs (u, v) of the corners counter-clockwise from the lower left."""
    d = E / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    k = np.zeros((8, 8))
    g = 1 / np.sqrt(3)
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    for xi in (-g, g):
        for eta in (-g, g):
            dn = np.array(
                [[c[0] * (1 + c[1] * eta) / 4 for c in corners], [c[1] * (1 + c[0] * xi) / 4 for c in corners]]
            ) * (2 / h)
            bm = np.zeros((3, 8))
            bm[0, 0::2] = dn[0]
            bm[1, 1::2] = dn[1]
            bm[2, 0::2] = dn[1]
            bm[2, 1::2] = dn[0]
            k += bm.T @ d @ bm * (h / 2) ** 2 * B
    return k


class Law:
    """Traction (Pa) against opening w (m) of the interface: elastic (stiffness kp) up to
    f't, then the bilinear softening of the inelastic opening; unloading towards the origin."""

    def __init__(self, ft, gf, kp, alpha=ALPHA, gamma=GAMMA):
        self.ft, self.kp, self.gamma = ft, kp, gamma
        self.codc = 2 * gf / (ft * (alpha + gamma))
        self.cod1 = alpha * self.codc
        self.w0 = ft / kp

    def envelope(self, w):
        """(traction, tangent) on the loading envelope."""
        if w <= self.w0:
            return self.kp * w, self.kp
        c = w - self.w0
        if c < self.cod1:
            s = (1 - self.gamma) * self.ft / self.cod1
            return self.ft - s * c, -s
        if c < self.codc:
            s = self.gamma * self.ft / (self.codc - self.cod1)
            return self.gamma * self.ft - s * (c - self.cod1), -s
        return 0.0, 0.0

    def traction(self, w, wmax):
        """(traction, tangent) at w for a spring that has opened to wmax before."""
        if w >= wmax or wmax <= self.w0:
            return self.envelope(w)
        t, _ = self.envelope(wmax)
        return t * w / wmax, t / wmax


def solve(notch, h, ft, gf, steps, stroke, alpha=ALPHA, gamma=GAMMA):
    nx, ny = round(HALF_LENGTH / h), round(DEPTH / h)
    node = lambda i, j: j * (nx + 1) + i
    n = (nx + 1) * (ny + 1)
    ke = q4_stiffness(h)
    rows, cols, vals = [], [], []
    for j in range(ny):
        for i in range(nx):
            corners = [node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]
            dofs = np.array([[2 * c, 2 * c + 1] for c in corners]).ravel()
            rows.append(np.repeat(dofs, 8))
            cols.append(np.tile(dofs, 8))
            vals.append(ke.ravel())
    k = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * n, 2 * n))
    # the mid-span plane: ligament springs (u at x = 0, y >= notch), tributary areas
    lig = [j for j in range(ny + 1) if j * h >= notch - 1e-12]
    area = np.array([B * (min(j * h + h / 2, DEPTH) - max(j * h - h / 2, notch)) for j in lig])
    lig_dof = np.array([2 * node(0, j) for j in lig])
    law = Law(ft, gf, kp=1e3 * E / h, alpha=alpha, gamma=gamma)
    support = 2 * node(round(HALF_SPAN / h), 0) + 1
    loaded = np.array([2 * node(0, ny) + 1])
    fixed = np.concatenate([[support], loaded])
    free = np.setdiff1d(np.arange(2 * n), fixed)
    u = np.zeros(2 * n)
    wmax = np.zeros(len(lig))
    mouth, base = 2 * node(0, 0), 2 * node(round(0.010 / h), 0)
    out = []
    for step in range(1, steps + 1):
        delta = stroke * step / steps
        u[loaded] = -delta
        for it in range(60):
            w = 2 * u[lig_dof]
            tt = np.array([law.traction(wi, wm) for wi, wm in zip(w, wmax)])
            f = k @ u
            f[lig_dof] += tt[:, 0] * area
            r = f[free]
            kt = k + sp.csr_matrix((2 * tt[:, 1] * area, (lig_dof, lig_dof)), shape=k.shape)
            norm = np.linalg.norm(r)
            scale = np.linalg.norm((k @ u)[fixed]) + 1.0
            if norm < 1e-8 * scale:
                break
            du = spla.spsolve(kt[free][:, free].tocsc(), -r)
            u[free] += du
        else:
            print(f"step {step}: Newton did not converge (residual {norm:.3e} N)", file=sys.stderr)
        wmax = np.maximum(wmax, 2 * u[lig_dof])
        reaction = -(k @ u)[loaded].sum()
        load = 2 * reaction
        out.append((delta, load, 2 * u[mouth], 2 * u[base]))
    return out, law


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--notch", type=float, default=0.025)
    a.add_argument("--h", type=float, default=0.000625)
    a.add_argument("--ft", type=float, default=3.9e6)
    a.add_argument("--gf", type=float, default=143.2)
    a.add_argument("--alpha", type=float, default=ALPHA)
    a.add_argument("--gamma", type=float, default=GAMMA)
    a.add_argument("--steps", type=int, default=150)
    a.add_argument("--stroke", type=float, default=6e-5)
    a.add_argument("--csv")
    o = a.parse_args()
    out, law = solve(o.notch, o.h, o.ft, o.gf, o.steps, o.stroke, o.alpha, o.gamma)
    i = max(range(len(out)), key=lambda k: out[k][1])
    print(
        f"notch {o.notch * 1e3:g} mm, h {o.h * 1e3:g} mm, f't {o.ft:.4g} Pa, G_f {o.gf:g} N/m "
        f"(alpha {o.alpha:g}, gamma {o.gamma:g}, COD_c {law.codc:.4g} m): peak {out[i][1]:.1f} N at a deflection of {out[i][0] * 1e3:.4f} mm, "
        f"CMOD {out[i][2] * 1e3:.4f} mm at the mouth, {out[i][3] * 1e3:.4f} mm over 20 mm"
    )
    if o.csv:
        with open(o.csv, "w") as f:
            f.write("deflection_m,load_N,cmod_mouth_m,cmod_20mm_m\n")
            for r in out:
                f.write(",".join(f"{v:.8e}" for v in r) + "\n")


if __name__ == "__main__":
    main()
