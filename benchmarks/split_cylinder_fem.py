#!/usr/bin/env python3
"""Elastic split cylinder by finite elements: the strain on the loaded diameter from the end
face to mid-length, as an independent reference for the lattice and the random particles.

One eighth of a cylinder (diameter D, length H along z; x >= 0, y >= 0, z <= H/2) meshed with
trilinear hexahedra: the quarter disc by the square-to-disc map, the length graded towards the
free end face z = 0. Symmetry planes x = 0, y = 0 and z = H/2. The bearing strip (width b) is
rigid and grips: the surface nodes with x <= b/2 at y = D/2 move by (0, -delta, free z).
Prints, along the loaded diameter (x = 0) at y = 0 and y = D/4, the strain e_xx and the
stress s_xx over sigma0 = 2P/(pi D H) against the distance from the end face, and the same
at mid-length.

    python3 benchmarks/split_cylinder_fem.py [--n 20] [--nz 30] [--nu 0.2] [--b 0.0125]
"""

import argparse

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def mesh(n, nz, r, half_len, grade):
    """Nodes and hexahedra of the eighth cylinder."""
    u = np.linspace(0.0, 1.0, n + 1)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    # square [0,1]^2 -> quarter disc (elliptical grid map)
    x2 = r * uu * np.sqrt(1.0 - vv**2 / 2.0)
    y2 = r * vv * np.sqrt(1.0 - uu**2 / 2.0)
    t = np.linspace(0.0, 1.0, nz + 1)
    zs = half_len * t**grade
    nxy = (n + 1) ** 2
    nodes = np.zeros((nxy * (nz + 1), 3))
    for k, z in enumerate(zs):
        nodes[k * nxy:(k + 1) * nxy, 0] = x2.ravel()
        nodes[k * nxy:(k + 1) * nxy, 1] = y2.ravel()
        nodes[k * nxy:(k + 1) * nxy, 2] = z

    def idx(i, j, k):
        return k * nxy + i * (n + 1) + j

    hexes = []
    for k in range(nz):
        for i in range(n):
            for j in range(n):
                hexes.append([idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k),
                              idx(i, j + 1, k), idx(i, j, k + 1), idx(i + 1, j, k + 1),
                              idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)])
    return nodes, np.array(hexes), zs


def shape_derivs():
    """Derivatives of the trilinear shape functions at the 2x2x2 Gauss points."""
    sgn = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
    g = 1.0 / np.sqrt(3.0)
    pts = np.array([[a, b, c] for a in (-g, g) for b in (-g, g) for c in (-g, g)])
    dn = np.zeros((8, 8, 3))  # gauss, node, dxi
    for q, (xi, et, ze) in enumerate(pts):
        for a in range(8):
            sx, sy, sz = sgn[a]
            dn[q, a, 0] = sx * (1 + sy * et) * (1 + sz * ze) / 8
            dn[q, a, 1] = sy * (1 + sx * xi) * (1 + sz * ze) / 8
            dn[q, a, 2] = sz * (1 + sx * xi) * (1 + sy * et) / 8
    return dn


def b_matrices(nodes, hexes, dn):
    """Strain-displacement matrices (elements, gauss, 6, 24) and the Jacobian determinants."""
    xe = nodes[hexes]  # (ne, 8, 3)
    jac = np.einsum("qai,eaj->eqij", dn, xe)
    det = np.linalg.det(jac)
    dnx = np.einsum("eqij,qaj->eqai", np.linalg.inv(jac), dn)
    ne = len(hexes)
    b = np.zeros((ne, 8, 6, 24))
    for a in range(8):
        dx, dy, dz = dnx[:, :, a, 0], dnx[:, :, a, 1], dnx[:, :, a, 2]
        b[:, :, 0, 3 * a] = dx
        b[:, :, 1, 3 * a + 1] = dy
        b[:, :, 2, 3 * a + 2] = dz
        b[:, :, 3, 3 * a] = dy
        b[:, :, 3, 3 * a + 1] = dx
        b[:, :, 4, 3 * a + 1] = dz
        b[:, :, 4, 3 * a + 2] = dy
        b[:, :, 5, 3 * a] = dz
        b[:, :, 5, 3 * a + 2] = dx
    return b, det


def elasticity(e, nu):
    lam = e * nu / ((1 + nu) * (1 - 2 * nu))
    mu = e / (2 * (1 + nu))
    c = np.zeros((6, 6))
    c[:3, :3] = lam
    c[np.arange(3), np.arange(3)] += 2 * mu
    c[3:, 3:] = np.eye(3) * mu
    return c


def stiffness(nodes, hexes, e, nu):
    """The global stiffness (sparse), the elasticity matrix and the elements' B matrices."""
    b, det = b_matrices(nodes, hexes, shape_derivs())
    c = elasticity(e, nu)
    ke = np.einsum("eqki,kl,eqlj,eq->eij", b, c, b, det)
    dofs = (3 * hexes[:, :, None] + np.arange(3)[None, None, :]).reshape(len(hexes), 24)
    rows = np.repeat(dofs, 24, axis=1).ravel()
    cols = np.tile(dofs, (1, 24)).ravel()
    ndof = 3 * len(nodes)
    return sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(ndof, ndof)), c, b


def solve(args):
    r, half_len = args.diameter / 2, args.length / 2
    nodes, hexes, zs = mesh(args.n, args.nz, r, half_len, args.grade)
    k, c, b = stiffness(nodes, hexes, args.e, args.nu)
    ndof = 3 * len(nodes)

    x, y, z = nodes.T
    tol = 1e-9
    fixed = {}
    for i in np.where(x < tol)[0]:
        fixed[3 * i] = 0.0
    for i in np.where(y < tol)[0]:
        fixed[3 * i + 1] = 0.0
    for i in np.where(z > half_len - tol)[0]:
        fixed[3 * i + 2] = 0.0
    on_surface = np.abs(np.hypot(x, y) - r) < 1e-9 * r + 1e-12
    strip = np.where(on_surface & (x <= args.b / 2 + 1e-9))[0]
    delta = 1e-5
    for i in strip:
        fixed[3 * i] = 0.0
        fixed[3 * i + 1] = -delta
    fd = np.array(sorted(fixed))
    fv = np.array([fixed[d] for d in fd])
    free = np.setdiff1d(np.arange(ndof), fd)
    u = np.zeros(ndof)
    u[fd] = fv
    rhs = -k[free][:, fd] @ fv
    u[free] = spla.spsolve(k[free][:, free].tocsc(), rhs)
    reaction = k @ u
    # force on the strip of one eighth: the whole strip carries 4x (two halves in x, in z)
    p = -4.0 * reaction[3 * strip + 1].sum()
    return nodes, hexes, zs, u, p, c, b


def nearest_element(nodes, hexes, point):
    """The element whose centroid is nearest to `point`."""
    cent = nodes[hexes].mean(axis=1)
    return int(np.argmin(np.linalg.norm(cent - point, axis=1)))


def strain_of(nodes, hexes, u, b, e):
    """Strain of element `e` (mean of its Gauss points) and its centroid."""
    ue = u[(3 * hexes[e][:, None] + np.arange(3)).ravel()]
    return np.einsum("qij,j->qi", b[e], ue).mean(axis=0), nodes[hexes[e]].mean(axis=0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--nz", type=int, default=30)
    ap.add_argument("--grade", type=float, default=2.0)
    ap.add_argument("--nu", type=float, default=0.2)
    ap.add_argument("--e", type=float, default=30.727e9)
    ap.add_argument("--b", type=float, default=0.0125)
    ap.add_argument("--diameter", type=float, default=0.15)
    ap.add_argument("--length", type=float, default=0.30)
    args = ap.parse_args()
    nodes, hexes, zs, u, p, c, b = solve(args)
    sigma0 = 2 * p / (np.pi * args.diameter * args.length)
    print(f"n={args.n} nz={args.nz} nu={args.nu} b={args.b}: P = {p / 1e3:.2f} kN, "
          f"sigma0 = {sigma0 / 1e6:.4f} MPa")
    zc = 0.5 * (zs[1:] + zs[:-1])
    for yfrac in (0.0, 0.25):
        y0 = yfrac * args.diameter
        print(f"loaded diameter x = 0, y = {y0 * 1e3:.1f} mm:")
        print(" z (mm)   e_xx/P (ustrain/MN)   s_xx/sigma0   s_zz/sigma0")
        depths = list(zc[:8]) + [0.02, 0.03, 0.05, 0.075, 0.1, 0.15]
        elements = [nearest_element(nodes, hexes, np.array([0.0, y0, zq])) for zq in depths]
        for e in dict.fromkeys(elements):  # each element once, in order of depth
            eps, cen = strain_of(nodes, hexes, u, b, e)
            sig = c @ eps
            print(f" {cen[2] * 1e3:6.2f}   {eps[0] / p * 1e12:8.1f}"
                  f"            {sig[0] / sigma0:6.3f}        {sig[2] / sigma0:6.3f}")


if __name__ == "__main__":
    main()
