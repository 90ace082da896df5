# pip install scikit-fem meshio scipy numpy
"""Solve an exported contact problem with scikit-fem and write the solutions `grade` reads.

    contact-rates export --study rates-exact --levels 0-4 --out EXPORT_DIR
    python3 examples/grade_skfem.py EXPORT_DIR OUT_DIR
    contact-rates grade --study rates-exact --solutions OUT_DIR --levels 0-4 --name skfem

(`contact-rates` is the project's binary: `cargo install --path .` puts it on PATH, or
use `cargo run --release --` in its place from the checkout.)

Per level L of EXPORT_DIR (every mesh_L.msh): P1 plane-stress elasticity assembled by
scikit-fem on both bodies, the nodal loads of loads_L.csv, the supports of problem.toml
as Dirichlet conditions, and frictionless unilateral contact discretized node-to-segment
(every slave node against the master edge it projects onto), solved exactly by a
primal-dual active set on the KKT system. Writes OUT_DIR/level_L.pvd and one .vtu per step
with point data `displacement` and `pressure`, cell data `body` and `stress`.
"""

import re
import sys
import time
import tomllib
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm
from skfem.models.elasticity import linear_elasticity

COMPONENTS = {"clamp": [0, 1], "roller x": [0], "roller y": [1]}


def read_mesh(path):
    """meshio keeps the file's node order and merges no coincident points (the two bodies
    touch at the ends of Gamma_C but share no node). Returns points (N, 2), triangles,
    each triangle's physical name, and the lines of every physical curve."""
    m = meshio.read(path, file_format="gmsh")  # .msh alone is ambiguous to meshio
    check_node_tags(path, len(m.points))
    name_of = {int(v[0]): k for k, v in m.field_data.items()}
    tris, tri_names, curves = [], [], {}
    for block, tags in zip(m.cells, m.cell_data["gmsh:physical"]):
        names = [name_of[int(g)] for g in tags]
        if block.type == "triangle":
            tris.append(block.data)
            tri_names += names
        elif block.type == "line":
            for line, name in zip(block.data, names):
                curves.setdefault(name, []).append(line)
    curves = {k: np.array(v) for k, v in curves.items()}
    return m.points[:, :2], np.vstack(tris), np.array(tri_names), curves


def check_node_tags(path, n):
    """loads_L.csv names nodes by tag; meshio numbers them in file order. The export writes
    tags 1..N in order, so tag - 1 is meshio's index: check it rather than trust it."""
    text = Path(path).read_text()
    lines = text[text.index("$Nodes") :].splitlines()[1:]
    blocks, k, tags = int(lines[0].split()[0]), 1, []
    for _ in range(blocks):
        count = int(lines[k].split()[3])
        tags += [int(s) for s in lines[k + 1 : k + 1 + count]]
        k += 1 + 2 * count
    if tags != list(range(1, n + 1)):
        sys.exit(f"{path}: $Nodes: node tags are not 1..{n} in file order; re-export the mesh")


def contact_rows(points, curves, slave, master, normal, ndofs, dof):
    """Node-to-segment: row i of B gives [u.nu] = (u^1(x_i) - u^2(proj x_i)) . nu^1 at slave
    node i, with u^2 interpolated linearly on the master edge closest to x_i.
    Non-penetration is B u <= 0. Also returns the slave nodes and their lumped weights
    (half the length of the slave edges at the node) that turn a nodal force into p."""
    slave_lines, master_lines = curves[slave], curves[master]
    nodes = np.unique(slave_lines)
    weight = np.zeros(len(points))
    np.add.at(
        weight,
        slave_lines.ravel(),
        np.repeat(0.5 * np.linalg.norm(np.diff(points[slave_lines], axis=1)[:, 0], axis=1), 2),
    )
    a, b = points[master_lines[:, 0]], points[master_lines[:, 1]]
    rows, cols, vals = [], [], []
    for i, n in enumerate(nodes):
        x = points[n]
        theta = np.clip(
            np.einsum("ij,ij->i", x - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1
        )
        e = np.argmin(np.linalg.norm(a + theta[:, None] * (b - a) - x, axis=1))
        for node, coef in [
            (n, 1.0),
            (master_lines[e, 0], theta[e] - 1.0),
            (master_lines[e, 1], -theta[e]),
        ]:
            for c in range(2):
                rows.append(i), cols.append(dof[c, node]), vals.append(coef * normal[c])
    B = sp.csr_matrix((vals, (rows, cols)), shape=(len(nodes), ndofs))
    return B, nodes, weight[nodes]


def solve_contact(K, f, B, free, active, tol=1e-12, max_iter=100):
    """min 1/2 u'Ku - f'u subject to B u <= 0 (u = 0 off `free`), by the primal-dual active
    set method (semismooth Newton on lambda = max(0, lambda + c B u)): each iteration solves
    the KKT system with the active rows as equalities, until the active set repeats. The
    start `active` must hold body 1 in y (it rests on contact alone there: K is singular)."""
    Kf, Bf, ff = K[free][:, free], B[:, free], f[free]
    c = Kf.diagonal().mean()  # lambda is a force, B u a length: c makes them comparable
    for it in range(1, max_iter + 1):
        if not active.any():
            sys.exit("no contact node is active: body 1 is free in y and K is singular")
        BA = Bf[active]
        kkt = sp.bmat([[Kf, BA.T], [BA, None]], format="csc")
        x = spsolve(kkt, np.concatenate([ff, np.zeros(BA.shape[0])]))
        u = np.zeros(len(f))
        u[free] = x[: len(free)]
        lam = np.zeros(B.shape[0])
        lam[active] = x[len(free) :]
        new = lam + c * (B @ u) > tol * c * np.abs(u).max()
        if np.array_equal(new, active):
            return u, lam, active, it
        active = new
    sys.exit(f"the active set did not settle in {max_iter} iterations")


def stress_p0(basis, u, lam_of, mu_of):
    """sigma = lambda* tr(eps) I + 2 mu eps per triangle; eps(u_h) is constant on a P1
    triangle, so the first quadrature point's gradient is the cell's."""
    g = basis.interpolate(u).grad[:, :, :, 0]  # (component, derivative, cell)
    exx, eyy, exy = g[0, 0], g[1, 1], 0.5 * (g[0, 1] + g[1, 0])
    tr = exx + eyy
    return np.column_stack(
        [lam_of * tr + 2 * mu_of * exx, lam_of * tr + 2 * mu_of * eyy, 2 * mu_of * exy]
    )


def solve_level(export, out, level, problem):
    t0 = time.perf_counter()
    points, tris, tri_names, curves = read_mesh(export / f"mesh_{level}.msh")
    surfaces = {b["number"]: b for b in problem["bodies"]}
    body_of = np.zeros(len(tris), dtype=int)
    for number, b in surfaces.items():
        body_of[tri_names == b["surface"]] = number
    # One mesh holds both bodies: they share no node, so they are coupled only by B.
    # scikit-fem sorts each triangle's nodes (flipping some orientations) but keeps the cell
    # order, so the output writes the file's own triangles with the cell data in that order.
    mesh = MeshTri(points.T.copy(), tris.T.copy())
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    K = sum(
        asm(
            linear_elasticity(b["lambda_star"], b["mu"]),
            basis.with_elements(np.flatnonzero(body_of == number)),
        )
        for number, b in surfaces.items()
    )
    dof = basis.nodal_dofs  # dof[c, node]: component c of the node's displacement
    for s in problem["supports"]:
        if s["kind"] not in COMPONENTS or s["curve"] not in curves:
            sys.exit(
                f"{export}/problem.toml: supports: kind {s['kind']!r} on curve {s['curve']!r}: this script "
                f"knows kinds {list(COMPONENTS)} on the physical curves of mesh_{level}.msh; re-export"
            )
    supported = [(s["curve"], c) for s in problem["supports"] for c in COMPONENTS[s["kind"]]]
    fixed = np.unique(np.concatenate([dof[c, np.unique(curves[k])] for k, c in supported]))
    free = np.setdiff1d(np.arange(basis.N), fixed)
    pieces = problem["contact"]["pieces"]
    if len({tuple(p["slave_normal"]) for p in pieces}) != 1:
        sys.exit(
            "problem.toml: contact.pieces: this script handles one straight Gamma_C (one slave_normal)"
        )
    contact = problem["contact"]
    normal = np.array(pieces[0]["slave_normal"], float)
    B, slave_nodes, weight = contact_rows(
        points, curves, contact["slave_curve"], contact["master_curve"], normal, basis.N, dof
    )
    if not (export / f"loads_{level}.csv").is_file():
        sys.exit(f"{export}/loads_{level}.csv: not found; re-export with this level")
    loads = np.loadtxt(export / f"loads_{level}.csv", delimiter=",", skiprows=1, ndmin=2)
    lam_of = np.array([surfaces[b]["lambda_star"] for b in body_of])
    mu_of = np.array([surfaces[b]["mu"] for b in body_of])
    datasets, worst, iters = [], 0.0, []
    # Start fully active (a bilateral tie, nonsingular); each later step starts from the
    # previous step's active set, which the loads, growing with t, mostly keep.
    active = np.ones(B.shape[0], dtype=bool)
    setup_s, solve_s = time.perf_counter() - t0, 0.0
    for step, t in enumerate(problem["time"]["times"], start=1):
        rows = loads[loads[:, 0] == step]
        if len(rows) == 0 or abs(rows[0, 1] - t) > 1e-9 * problem["time"]["final_time"]:
            sys.exit(f"{export}/loads_{level}.csv: no rows for step {step} at t = {t}; re-export")
        f = np.zeros(basis.N)
        node = rows[:, 2].astype(int) - 1  # tags are 1..N in meshio's order (checked)
        np.add.at(f, dof[0, node], rows[:, 3])
        np.add.at(f, dof[1, node], rows[:, 4])
        t1 = time.perf_counter()
        u, lam, active, it = solve_contact(K, f, B, free, active)
        solve_s += time.perf_counter() - t1
        iters.append(it)
        # Complementarity: gap B u <= 0, lambda >= 0, lambda * gap = 0 (forces relative to the
        # largest, gaps to max |u|).
        gap, scale_u, scale_l = B @ u, np.abs(u).max(), max(lam.max(), 1e-300)
        worst = max(
            worst,
            gap.max() / scale_u,
            -lam.min() / scale_l,
            np.abs(lam * gap).max() / (scale_l * scale_u),
        )
        pressure = np.zeros(len(points))
        pressure[slave_nodes] = lam / weight
        disp = np.column_stack([u[dof[0]], u[dof[1]]])
        name = f"level_{level}_step_{step}.vtu"
        meshio.write(
            out / name,
            meshio.Mesh(
                np.column_stack([points, np.zeros(len(points))]),
                [("triangle", tris)],
                point_data={"displacement": disp, "pressure": pressure},
                cell_data={"body": [body_of], "stress": [stress_p0(basis, u, lam_of, mu_of)]},
            ),
        )
        datasets.append(f'<DataSet timestep="{t!r}" file="{name}"/>')
    (out / f"level_{level}.pvd").write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
        + "\n".join(datasets)
        + "\n</Collection>\n</VTKFile>\n"
    )
    print(
        f"level {level}: {len(points)} nodes, {len(free)} free dofs, {B.shape[0]} contact nodes, "
        f"active-set iterations {iters}, max complementarity violation {worst:.1e}, "
        f"read + assembly {setup_s:.2f} s, contact solves {solve_s:.2f} s"
    )


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: python3 examples/grade_skfem.py EXPORT_DIR OUT_DIR")
    export, out = Path(sys.argv[1]), Path(sys.argv[2])
    if not (export / "problem.toml").is_file():
        sys.exit(
            f"{export}/problem.toml: not found; run `contact-rates export --study ... --out {export}` first"
        )
    problem = tomllib.loads((export / "problem.toml").read_text())
    levels = sorted(
        int(m.group(1))
        for p in export.glob("mesh_*.msh")
        if (m := re.fullmatch(r"mesh_(\d+)\.msh", p.name))
    )
    if not levels:
        sys.exit(f"{export}: no mesh_L.msh files")
    out.mkdir(parents=True, exist_ok=True)
    for level in levels:
        solve_level(export, out, level, problem)


if __name__ == "__main__":
    main()
