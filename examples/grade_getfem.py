"""apt-get install -y python3-getfem   (GetFEM 5.4, numpy, scipy; run with Debian's /usr/bin/python3)

Solve an exported contact problem with GetFEM's contact bricks and write the solutions
`grade` reads.

    contact-rates export --study rates-exact --levels 0-4 --out EXPORT_DIR
    /usr/bin/python3 examples/grade_getfem.py EXPORT_DIR OUT_DIR --brick integral   # or nodal
    contact-rates grade --study rates-exact --solutions OUT_DIR --levels 0-4 --name getfem-integral

(`contact-rates` is the project's binary: `cargo install --path .` puts it on PATH, or
use `cargo run --release --` in its place from the checkout.)

Per level L of EXPORT_DIR (every mesh_L.msh22.msh, or --levels A-B): the mesh imported by
GetFEM's gmsh importer, P1 Lagrange plane-stress elasticity on each body (GetFEM's isotropic
linearized elasticity brick with lambda = lambda_star), the supports of problem.toml as
nodal constraints, the loads (--loads exported: the nodal loads of loads_L.csv as an explicit
right-hand side; --loads getfem: problem.toml's body forces and tractions as GWFL expressions,
integrated by GetFEM's source term brick with --load-rule, as a user would write them), and
frictionless unilateral contact between the slave curve (body 1) and the master curve with
one of GetFEM's contact bricks, solved at every t_n by GetFEM's Newton:

  --brick integral  add_integral_contact_between_nonmatching_meshes_brick: the small-sliding
                    integral (mortar-type) brick, Alart-Curnier, with a P1 multiplier on the
                    slave curve; the master displacement is projected onto the slave curve
                    once, in the reference configuration (a fixed interface); r = 100 E / h;
  --brick nodal     add_nodal_contact_between_nonmatching_meshes_brick: node-on-segment, one
                    multiplier (a nodal force) per slave node, master segments found once in
                    the reference configuration.

With --loads getfem the loads are GetFEM's quadrature of the expressions, not the exported
integrals: `grade` reads the difference as an equilibrium residual against loads_L.csv and prints
the energy bound it puts on the error beside each level (docs/verify-your-code.md, "Your own
load integration").

Each step is checked: GetFEM's Newton, then single Newton iterations until one moves u by
less than 1e-10 of max |u|, and a backward error below 1e-13; the script exits non-zero
otherwise. Writes OUT_DIR/level_L.pvd and one .vtu per step with point data `displacement`
and `pressure` (force per length, positive in compression, at the slave curve's nodes),
cell data `body` and `stress` (the P0 elastic stress; for a viscoplastic scene it is right
only where the stress is statically determinate, as in `patch`).
"""

import argparse
import ast
import sys
import time
import tomllib
from pathlib import Path

import getfem as gf
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

COMPONENTS = {"clamp": [0, 1], "roller x": [0], "roller y": [1]}
P1 = "FEM_PK(2,1)"
# Elasticity of P1 triangles: constant strain, a degree-2 rule is exact.
BULK_RULE = "IM_TRIANGLE(2)"
# The integral brick integrates over the slave edges a product of the slave P1 multiplier and
# the master field projected onto the slave edge, which is piecewise linear with kinks where
# master nodes project, and the positive part of the augmented multiplier, which kinks where
# contact ends. No rule is exact across those kinks: each slave edge is cut in 16 pieces, with
# IM_TRIANGLE(6)'s edge rule on each. With r = E, on rates-exact level 4, the distance to
# mortar's solution (grade's cone_distance) is 7.4e-6 with this rule, 3.0e-5 with 4 pieces and
# 5.8e-4 with IM_TRIANGLE(6) alone, for ~25% more Newton time than 4 pieces (1.5e-6 with
# this rule and r = R_FACTOR E / h).
CONTACT_RULE = "IM_STRUCTURED_COMPOSITE(IM_TRIANGLE(6),16)"
# The integral brick's discrete problem depends on Alart-Curnier's r: its multiplier equation
# is lambda = min(0, lambda - r [u.nu]) tested against the P1 multipliers (integrated, not
# node by node), not the mortar conditions. r = c E / h (a traction per gap, as Nitsche's
# gamma) keeps it near mortar: on regularity/beta-0.75 (a singular pressure) levels 2-4, the
# distance to mortar D is 0.08 (c = 10) and 0.008 (c = 100) of mortar's error, falling at
# mortar's rate. With GetFEM's advice r = E, D falls at 0.68 against mortar's 0.79 (0.35 of
# mortar's error at level 5); a fixed r of 10 E to 1000 E does not follow the mesh either (D
# falls slower than mortar's error, or grows at 1000 E).
R_FACTOR = 100.0
# Newton: GetFEM 5.4 stops when |R|_1 / approx_external_load_norm < max_res (or when the
# step is small), R the whole residual (force, constraint and contact rows); that norm is 1
# here (an explicit rhs brick is not an external load to GetFEM), so max_res is passed as
# NEWTON_TOL |f|_1. Round-off alone leaves |R|_1 / |f|_1 between 1e-15 and 1e-10 on the
# exported problems (it grows with the mesh, and where the loads are tractions only), so
# NEWTON_TOL is not the test: each step is then continued one Newton iteration at a time until
# one moves u by less than CHECK_TOL of max |u| (at most MAX_CHECK), and the backward error
# |R|_1 / (| |K| |x| |_1 + |f|_1) must be below ETA_TOL.
NEWTON_TOL, MAX_ITER = 1e-8, 100
# The linear solver, named: GetFEM's "auto" turned to gmres with an ILUT preconditioner on
# crossover level 5 (115,000 unknowns), whose pivots failed ("pivot too small").
LSOLVER = "mumps"
CHECK_TOL, MAX_CHECK, ETA_TOL = 1e-10, 20, 1e-13
# --loads getfem: the loads' expressions (abs and signum terms, which jump or kink across
# triangles) integrated by a plain GetFEM rule, as a user would write them. IM_TRIANGLE(6), the
# contact rule's base: on rates-exact levels 0-3 `grade` grades every level, the residual
# bound at most 0.063 of the error, the theorem rate 0.967 against mortar's 0.968.
# IM_TRIANGLE(2), the elasticity's rule: every level graded, bound up to 0.23 of the error,
# the error 1-2% from the field without the residual, the theorem rate not yet settled
# (rising: 0.913, 1.011, 1.027). Measured with `--load-rule`.
LOAD_RULE = "IM_TRIANGLE(6)"

# problem.toml's expression syntax as GWFL (GetFEM's weak form language): x, y are X(1), X(2),
# t is model data, ^ is pow, signum is sign (they differ at 0 only, a set of measure zero).
GWFL_CALLS = {"sin": "sin", "cos": "cos", "tan": "tan", "exp": "exp", "log": "log", "sqrt": "sqrt",
              "abs": "abs", "signum": "sign"}
GWFL_NAMES = {"x": "X(1)", "y": "X(2)", "t": "t", "pi": "pi"}


def gwfl(text):
    """One expression of problem.toml in GWFL, through Python's parser (^ read as a power)."""
    def emit(node):
        if isinstance(node, ast.Expression):
            return emit(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return repr(float(node.value))
        if isinstance(node, ast.Name) and node.id in GWFL_NAMES:
            return GWFL_NAMES[node.id]
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            return f"({'-' if isinstance(node.op, ast.USub) else ''}{emit(node.operand)})"
        if isinstance(node, ast.BinOp):
            a, b = emit(node.left), emit(node.right)
            if isinstance(node.op, ast.Pow):
                return f"pow({a},{b})"
            op = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}.get(type(node.op))
            if op:
                return f"({a}{op}{b})"
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in GWFL_CALLS and len(node.args) == 1):
            return f"{GWFL_CALLS[node.func.id]}({emit(node.args[0])})"
        fail(f"problem.toml: expression {text[:60]!r}...: {ast.dump(node)[:60]} is not in its syntax")
    return emit(ast.parse(text.replace("^", "**"), mode="eval"))


def fail(msg):
    sys.exit(f"grade_getfem.py: {msg}")


def read_msh22(path):
    """The export's MSH 2.2 file, read as written: points (N, 2) in node-tag order (tags
    1..N, checked), triangles (M, 3) with their physical tags, and the lines of every
    physical curve as node-index pairs. GetFEM's own import is used for the solve; this
    reading gives the file's own nodes (the output is written on them) and its curves."""
    lines = Path(path).read_text().splitlines()
    at = {s: i for i, s in enumerate(lines) if s.startswith("$")}
    if lines[at["$MeshFormat"] + 1].split()[0] != "2.2":
        fail(f"{path}: $MeshFormat: not MSH 2.2")
    names = {}
    for s in lines[at["$PhysicalNames"] + 2 : at["$EndPhysicalNames"]]:
        dim, tag, name = s.split(maxsplit=2)
        names[name.strip('"')] = (int(dim), int(tag))
    start = at["$Nodes"]
    n = int(lines[start + 1])
    rows = [s.split() for s in lines[start + 2 : start + 2 + n]]
    if [int(r[0]) for r in rows] != list(range(1, n + 1)):
        fail(f"{path}: $Nodes: node tags are not 1..{n} in file order; re-export the mesh")
    points = np.array([[float(r[1]), float(r[2])] for r in rows])
    start = at["$Elements"]
    tris, tri_tag, curves = [], [], {}
    for s in lines[start + 2 : start + 2 + int(lines[start + 1])]:
        e = [int(v) for v in s.split()]
        kind, ntags = e[1], e[2]
        phys, nodes = e[3], [v - 1 for v in e[3 + ntags :]]
        if kind == 2:
            tris.append(nodes)
            tri_tag.append(phys)
        elif kind == 1:
            curves.setdefault(phys, []).append(nodes)
        else:
            fail(f"{path}: $Elements: element type {kind}: only P1 triangles and lines")
    return names, points, np.array(tris), np.array(tri_tag), {k: np.array(v) for k, v in curves.items()}


class Level:
    """One level: the file's mesh, GetFEM's mesh and one P1 vector mesh_fem per body on it."""

    def __init__(self, export, level, problem):
        path = export / f"mesh_{level}.msh22.msh"
        if not path.is_file():
            fail(f"{path}: not found; re-export with this level")
        self.names, self.points, self.tris, tri_tag, curves = read_msh22(path)
        self.curves = {}
        for name, (dim, tag) in self.names.items():
            if dim == 1:
                self.curves[name] = curves.get(tag, np.zeros((0, 2), int))
        self.bodies = {b["number"]: b for b in problem["bodies"]}
        self.body_of_tri = np.zeros(len(self.tris), dtype=int)
        self.region_of = {}
        for number, b in self.bodies.items():
            dim, tag = self.names[b["surface"]]
            self.body_of_tri[tri_tag == tag] = number
            self.region_of[number] = tag
        if (self.body_of_tri == 0).any():
            fail(f"{path}: a triangle is in no body of problem.toml")
        self.body_of_node = np.zeros(len(self.points), dtype=int)
        for number in self.bodies:
            self.body_of_node[self.tris[self.body_of_tri == number].ravel()] = number

        # GetFEM's gmsh importer merges coincident points: the two bodies' corners at the
        # ends of Gamma_C become one GetFEM point. That glues nothing here, because each body
        # has its own mesh_fem (fem set on its own triangles only) and its own variable: a
        # merged point carries a dof of u1 and a separate dof of u2.
        self.mesh = gf.Mesh("import", "gmsh", str(path))
        self.mf = {}
        self.dof = {}  # dof[b][file node] = first GetFEM dof of u_b at that node (-1 elsewhere)
        scale = np.abs(self.points).max()
        for number in self.bodies:
            cvs = np.unique(self.mesh.region(self.region_of[number])[0])
            mf = gf.MeshFem(self.mesh, 2)
            mf.set_fem(gf.Fem(P1), cvs)
            self.mf[number] = mf
            xy = mf.basic_dof_nodes().T  # (ndof, 2), components interleaved
            own = np.flatnonzero(self.body_of_node == number)
            dist, k = cKDTree(self.points[own]).query(xy[::2])
            if dist.max() > 1e-10 * scale or len(np.unique(k)) != len(own):
                fail(f"{path}: body {number}: GetFEM's dofs do not match the file's nodes")
            dof = np.full(len(self.points), -1)
            dof[own[k]] = 2 * np.arange(len(k))
            self.dof[number] = dof
        self.mim = gf.MeshIm(self.mesh, gf.Integ(BULK_RULE))


def build_model(lv, problem, brick, r, load_source, load_rule):
    """The model: u1, u2 (one per body), their elasticity, constraints and loads, and the
    contact brick. Returns the model and the explicit-rhs brick index of each body (its
    right-hand side stays zero with `load_source` "getfem", whose loads are source term bricks)."""
    md = gf.Model("real")
    rhs_brick, fixed = {}, {}
    md.add_initialized_data("t", [0.0])
    for number, b in lv.bodies.items():
        u = f"u{number}"
        md.add_fem_variable(u, lv.mf[number])
        md.add_initialized_data(f"lambda_star{number}", [b["lambda_star"]])
        md.add_initialized_data(f"mu{number}", [b["mu"]])
        md.add_isotropic_linearized_elasticity_brick(
            lv.mim, u, f"lambda_star{number}", f"mu{number}", lv.region_of[number]
        )
        fixed[number] = set()
    for s in problem["supports"]:
        if s["kind"] not in COMPONENTS or s["curve"] not in lv.curves:
            fail(
                f"problem.toml: supports: kind {s['kind']!r} on curve {s['curve']!r}: this script "
                f"knows kinds {list(COMPONENTS)} on the mesh's physical curves"
            )
        nodes = np.unique(lv.curves[s["curve"]])
        d = lv.dof[s["body"]][nodes]
        if (d < 0).any():
            fail(f"problem.toml: supports: curve {s['curve']!r} is not on body {s['body']}")
        for c in COMPONENTS[s["kind"]]:
            fixed[s["body"]].update((d + c).tolist())
    for number in lv.bodies:
        u, ndof = f"u{number}", lv.mf[number].nbdof()
        # Supports as nodal constraints u_j = 0 with multipliers (one row per fixed dof; a
        # corner shared by two supports is fixed once). GetFEM's Dirichlet bricks prescribe
        # all components of a vector field or a weak (integral) condition; a roller fixes one
        # component at the nodes, which this does exactly.
        fx = sorted(fixed[number])
        fixed[number] = np.array(fx, dtype=int)
        if fx:
            B = gf.Spmat("empty", len(fx), ndof)
            B.add(list(range(len(fx))), fx, np.eye(len(fx)))
            md.add_variable(f"support{number}", len(fx))
            md.add_constraint_with_multipliers(u, f"support{number}", B, np.zeros(len(fx)))
        rhs_brick[number] = md.add_explicit_rhs(u, np.zeros(ndof))
    if load_source == "getfem":
        add_expression_loads(md, lv, problem, load_rule)

    contact = problem["contact"]
    slave = lv.names[contact["slave_curve"]][1]
    master = lv.names[contact["master_curve"]][1]
    md.add_initialized_data("r", [r])
    if brick == "integral":
        # Multiplier: P1 on body 1, filtered to the dofs on the slave curve. GetFEM's
        # convention: it is the normal traction on body 1, negative in compression.
        mfl = gf.MeshFem(lv.mesh, 1)
        mfl.set_fem(gf.Fem(P1), np.unique(lv.mesh.region(lv.region_of[1])[0]))
        md.add_filtered_fem_variable("lambda", mfl, slave)
        mim_c = gf.MeshIm(lv.mesh, gf.Integ(CONTACT_RULE))
        # option 1: the non-symmetric Alart-Curnier formulation.
        md.add_integral_contact_between_nonmatching_meshes_brick(
            mim_c, "u1", "u2", "lambda", "r", slave, master, 1
        )
        lv.mfl = mfl
    else:
        # One multiplier per slave node (a nodal force), in the order of u1's dofs on the
        # slave curve; slave1 = 1, slave2 = 0: only body 1's nodes carry rows. (GetFEM 5.4's
        # interface prints "ok here" here: a debug line left in gf_model_set.cc.)
        md.add_nodal_contact_between_nonmatching_meshes_brick(
            lv.mim, lv.mim, "u1", "u2", "lambda", "r", slave, master, 1, 0
        )
    return md, rhs_brick, fixed


def add_expression_loads(md, lv, problem, load_rule):
    """problem.toml's body forces and tractions as GWFL expressions in X and the data t, each
    integrated by GetFEM's source term brick with `load_rule` on its body or its curve (the
    curve's rule is the triangle rule's face rule)."""
    mim = gf.MeshIm(lv.mesh, gf.Integ(load_rule))
    for b in problem["bodies"]:
        if "body_force" in b:
            fx, fy = (gwfl(e) for e in b["body_force"])
            md.add_source_term_brick(mim, f"u{b['number']}", f"[{fx};{fy}]", lv.region_of[b["number"]])
    for tr in problem.get("tractions", []):
        if tr["curve"] not in lv.names:
            fail(f"problem.toml: tractions: curve {tr['curve']!r} is not a physical curve of the mesh")
        gx, gy = (gwfl(e) for e in tr["traction"])
        md.add_source_term_brick(mim, f"u{tr['body']}", f"[{gx};{gy}]", lv.names[tr["curve"]][1])


def slave_data(lv, problem):
    """Slave curve's nodes (file indices), their weights w_i (half the length of the slave
    edges at node i), nu^1 and the longest slave edge."""
    pieces = problem["contact"]["pieces"]
    if len({tuple(p["slave_normal"]) for p in pieces}) != 1:
        fail("problem.toml: contact.pieces: this script handles one straight Gamma_C")
    nu = np.array(pieces[0]["slave_normal"], float)
    edges = lv.curves[problem["contact"]["slave_curve"]]
    length = np.linalg.norm(lv.points[edges[:, 1]] - lv.points[edges[:, 0]], axis=1)
    w = np.zeros(len(lv.points))
    np.add.at(w, edges.ravel(), np.repeat(0.5 * length, 2))
    nodes = np.unique(edges)
    return nodes, w[nodes], nu, length.max()


def pressure_of(lv, md, brick, nodes, w, nu):
    """Point data `pressure` (force per length, positive in compression; 0 off the slave
    curve), by the export README's rule."""
    p = np.zeros(len(lv.points))
    lam = md.variable("lambda")
    if brick == "integral":
        # A P1 multiplier that is a traction: p = lambda, sign flipped (GetFEM's lambda_N is
        # the normal stress on the slave side, negative in compression).
        dofs = lv.mfl.basic_dof_on_region(lv.slave_region)
        xy = lv.mfl.basic_dof_nodes(dofs).T
        dist, k = cKDTree(lv.points[nodes]).query(xy)
        if dist.max() > 1e-10 * np.abs(lv.points).max() or len(np.unique(k)) != len(nodes):
            fail("the multiplier's dofs are not the slave curve's nodes")
        p[nodes[k]] = -lam
    else:
        # A nodal force: the brick's row i is [u.nu] at the i-th slave node (in u1's dof
        # order), and the force it puts on that node is F_i = -lambda_i n^2 = lambda_i nu^1
        # (n^2, the master edge's outward normal, is -nu^1 on a straight Gamma_C; lambda_i <= 0
        # in compression). So p_i = |F_i . nu^1| / w_i = |lambda_i| / w_i.
        d1 = lv.dof[1][nodes]
        order = np.argsort(d1)
        if len(lam) != len(nodes):
            fail(f"the nodal brick has {len(lam)} multipliers for {len(nodes)} slave nodes")
        F = np.outer(lam, nu)
        p[nodes[order]] = np.abs(F @ nu) / w[order]
    return p


def stress_p0(lv, disp):
    """sigma = lambda* tr(eps) I + 2 mu eps per triangle (s11, s22, s12)."""
    x = lv.points[lv.tris]  # (M, 3, 2)
    u = disp[lv.tris]
    d1, d2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    # grad of the barycentric functions 1 and 2 (rows), 0 is minus their sum
    g1 = np.column_stack([d2[:, 1], -d2[:, 0]]) / det[:, None]
    g2 = np.column_stack([-d1[:, 1], d1[:, 0]]) / det[:, None]
    G = np.einsum("mc,md->mcd", u[:, 1] - u[:, 0], g1) + np.einsum("mc,md->mcd", u[:, 2] - u[:, 0], g2)
    lam = np.array([lv.bodies[b]["lambda_star"] for b in lv.body_of_tri])
    mu = np.array([lv.bodies[b]["mu"] for b in lv.body_of_tri])
    exx, eyy, exy = G[:, 0, 0], G[:, 1, 1], 0.5 * (G[:, 0, 1] + G[:, 1, 0])
    tr = exx + eyy
    return np.column_stack([lam * tr + 2 * mu * exx, lam * tr + 2 * mu * eyy, 2 * mu * exy])


def ascii(a, fmt="%.17g"):
    return " ".join(fmt % v for v in np.asarray(a).ravel())


def write_vtu(path, points, tris, point_data, cell_data):
    """VTK XML unstructured grid, ASCII, P1 triangles (VTK type 5)."""
    n, m = len(points), len(tris)
    pts = np.column_stack([points, np.zeros(n)])

    def arrays(data):
        out = []
        for name, a in data.items():
            a = np.asarray(a)
            comps = 1 if a.ndim == 1 else a.shape[1]
            kind, fmt = ("Int32", "%d") if a.dtype.kind in "iu" else ("Float64", "%.17g")
            out.append(f'<DataArray type="{kind}" Name="{name}" NumberOfComponents="{comps}" '
                       f'format="ascii">{ascii(a, fmt)}</DataArray>')
        return "\n".join(out)

    path.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
        f'<UnstructuredGrid>\n<Piece NumberOfPoints="{n}" NumberOfCells="{m}">\n'
        f'<Points>\n<DataArray type="Float64" NumberOfComponents="3" format="ascii">{ascii(pts)}</DataArray>\n</Points>\n'
        '<Cells>\n'
        f'<DataArray type="Int64" Name="connectivity" format="ascii">{ascii(tris, "%d")}</DataArray>\n'
        f'<DataArray type="Int64" Name="offsets" format="ascii">{ascii(3 * np.arange(1, m + 1), "%d")}</DataArray>\n'
        f'<DataArray type="UInt8" Name="types" format="ascii">{ascii(np.full(m, 5), "%d")}</DataArray>\n'
        '</Cells>\n'
        f'<PointData>\n{arrays(point_data)}\n</PointData>\n'
        f'<CellData>\n{arrays(cell_data)}\n</CellData>\n'
        '</Piece>\n</UnstructuredGrid>\n</VTKFile>\n'
    )


def solve_level(export, out, level, problem, brick, load_source, load_rule):
    t0 = time.perf_counter()
    lv = Level(export, level, problem)
    if set(lv.bodies) != {1, 2}:
        fail("problem.toml: bodies: this script handles two bodies numbered 1 and 2")
    lv.slave_region = lv.names[problem["contact"]["slave_curve"]][1]
    nodes, w, nu, h_slave = slave_data(lv, problem)
    # r: Alart-Curnier's augmentation parameter, which turns a gap (a length) into a traction.
    # The nodal brick's solution does not depend on it (its conditions are node by node): E,
    # as GetFEM's documentation advises. The integral brick's does (see R_FACTOR): E first,
    # then R_FACTOR E / h (h the longest slave edge) from that solution.
    young = float(lv.bodies[1]["young"])
    r = young if brick == "nodal" else R_FACTOR * young / h_slave
    md, rhs_brick, fixed = build_model(lv, problem, brick, r, load_source, load_rule)

    loads_path = export / f"loads_{level}.csv"
    if not loads_path.is_file():
        fail(f"{loads_path}: not found; re-export with this level")
    loads = np.loadtxt(loads_path, delimiter=",", skiprows=1, ndmin=2)

    # Body 1 may be held in y by contact alone (a traction on top, rollers in x): with the
    # contact inactive, the tangent matrix is singular. Newton starts from u = 0 and a small
    # compressive multiplier everywhere (lambda = -1e-3 E for the traction, -1e-3 E times the
    # slave edge length for the nodal force), which makes every slave node active in the
    # first tangent (a bilateral tie: non-singular); later steps start from the previous
    # step's solution, which is in contact somewhere.
    nlam = md.variable("lambda").size
    md.set_variable("lambda", np.full(nlam, -1e-3 * young * (1.0 if brick == "integral" else w.mean())))

    setup_s = time.perf_counter() - t0
    solve_s, datasets, report = 0.0, [], []
    for step, t in enumerate(problem["time"]["times"], start=1):
        rows = loads[loads[:, 0] == step]
        if len(rows) == 0 or abs(rows[0, 1] - t) > 1e-9 * problem["time"]["final_time"]:
            fail(f"{loads_path}: no rows for step {step} at t = {t}; re-export")
        node = rows[:, 2].astype(int) - 1  # tags 1..N in file order (checked)
        f = {}
        for number in lv.bodies:
            at = lv.body_of_node[node] == number
            F = np.zeros(lv.mf[number].nbdof())
            for c, col in ((0, 3), (1, 4)):
                np.add.at(F, lv.dof[number][node[at]] + c, rows[at, col])
            F[fixed[number]] = 0.0  # a row at a supported component is ignored
            f[number] = F  # with --loads getfem only the size of the loads (Newton's scale)
            if load_source == "exported":
                md.set_private_rhs(rhs_brick[number], F)
        md.set_variable("t", [t])
        load = sum(np.abs(F).sum() for F in f.values())
        t1 = time.perf_counter()
        newton = ("max_iter", MAX_ITER, "max_res", NEWTON_TOL * load, "lsolver", LSOLVER)
        if brick == "integral":
            # Newton at r = E, then at r = R_FACTOR E / h from its solution: started from the
            # tie at the large r, the semismooth Newton needed 11 + 17 iterations on
            # rates-exact level 2 and did not settle in 20 on level 3. GetFEM's own stop does
            # not see the change of r (the contact rows are tiny in |R|_1): the iterations
            # at the large r are mostly the check's, below.
            md.set_variable("r", [young])
            n0, c0 = md.solve(*newton)
            md.set_variable("r", [r])
            n1, converged = md.solve(*newton)
            nbit, converged = f"{n0}+{n1}", c0 and converged
        else:
            nbit, converged = md.solve(*newton)
        res_stop = residual(md) / load
        # The check: further Newton iterations, one at a time (max_res 0 lets GetFEM stop only
        # at max_iter), until one moves u by less than CHECK_TOL of max |u|. A semismooth
        # Newton whose active set is final moves u by round-off only; GetFEM's stop alone does
        # not prove that (the contact rows are lengths, tiny in |R|_1).
        for extra in range(1, MAX_CHECK + 1):
            before = np.concatenate([md.variable(f"u{b}") for b in lv.bodies])
            md.solve("max_iter", 1, "max_res", 0.0, "lsolver", LSOLVER)
            after = np.concatenate([md.variable(f"u{b}") for b in lv.bodies])
            du = np.abs(after - before).max() / max(np.abs(after).max(), 1e-300)
            if du < CHECK_TOL:
                break
        eta, res_end = backward_error(md, load)
        solve_s += time.perf_counter() - t1
        report.append(f"t={t:g}: {nbit}+{extra} it, |R|_1/|f|_1 {res_stop:.1e} at GetFEM's stop, "
                      f"{res_end:.1e} (backward error {eta:.1e}) after the last, |du|/|u| {du:.1e}")
        if not (converged and du < CHECK_TOL and eta < ETA_TOL):
            print(f"level {level}: " + "; ".join(report))
            fail(f"level {level}, step {step}: Newton did not converge (GetFEM's converged = "
                 f"{converged} after {nbit} iterations; {extra} more moved u by {du:.1e} of "
                 f"max |u|; backward error {eta:.1e})")

        disp = np.zeros((len(lv.points), 2))
        for number in lv.bodies:
            u = md.variable(f"u{number}")
            own = np.flatnonzero(lv.body_of_node == number)
            d = lv.dof[number][own]
            disp[own] = np.column_stack([u[d], u[d + 1]])
        pressure = pressure_of(lv, md, brick, nodes, w, nu)
        name = f"level_{level}_step_{step}.vtu"
        write_vtu(
            out / name, lv.points, lv.tris,
            {"displacement": np.column_stack([disp, np.zeros(len(disp))]), "pressure": pressure},
            {"body": lv.body_of_tri.astype(np.int32), "stress": stress_p0(lv, disp)},
        )
        datasets.append(f'<DataSet timestep="{t!r}" file="{name}"/>')
    (out / f"level_{level}.pvd").write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
        + "\n".join(datasets) + "\n</Collection>\n</VTKFile>\n"
    )
    print(f"level {level}: {len(lv.points)} nodes, {md.nbdof()} unknowns, {len(nodes)} slave nodes; "
          + "; ".join(report)
          + f"; setup {setup_s:.2f} s, Newton {solve_s:.2f} s", flush=True)


def residual(md):
    """|R|_1 of the whole system at the current state, as GetFEM's Newton measures it."""
    md.assembly("build_rhs")
    return np.abs(md.rhs()).sum()


def backward_error(md, load):
    """|R|_1 / (| |K| |x| |_1 + |f|_1), K the tangent matrix and x the state (u, support and
    contact multipliers): the residual against the size of the terms it sums, which
    round-off alone leaves near 1e-16 whatever the load and the mesh. Also |R|_1 / |f|_1."""
    md.assembly("build_all")
    K = md.tangent_matrix()
    jc, ir = K.csc_ind()
    n = md.nbdof()
    Kabs = sp.csc_matrix((np.abs(K.csc_val()), ir, jc), shape=(n, n))
    R = np.abs(md.rhs()).sum()
    return R / (np.abs(Kabs @ np.abs(md.from_variables())).sum() + load), R / load


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("export", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--brick", choices=["integral", "nodal"], required=True)
    ap.add_argument("--levels", help="A-B (default: every level in problem.toml)")
    ap.add_argument("--loads", choices=["exported", "getfem"], default="exported",
                    help="exported: loads_L.csv's nodal loads; getfem: problem.toml's expressions "
                         "integrated by GetFEM with --load-rule")
    ap.add_argument("--load-rule", default=LOAD_RULE,
                    help=f"GetFEM's integration method for --loads getfem (default {LOAD_RULE})")
    a = ap.parse_args()
    if not (a.export / "problem.toml").is_file():
        fail(f"{a.export}/problem.toml: not found; run `contact-rates export --study ... --out {a.export}` first")
    problem = tomllib.loads((a.export / "problem.toml").read_text())
    levels = problem["levels"]
    if a.levels:
        lo, _, hi = a.levels.partition("-")
        want = range(int(lo), int(hi or lo) + 1)
        if not set(want) <= set(levels):
            fail(f"--levels {a.levels}: the export has levels {levels}")
        levels = list(want)
    if any("viscoplastic" in b for b in problem["bodies"]):
        print("note: a body is viscoplastic in problem.toml; it is solved elastically here, which "
              "is its solution only where the stress is statically determinate (as in `patch`)")
    gf.util_trace_level(0)
    a.out.mkdir(parents=True, exist_ok=True)
    for level in levels:
        solve_level(a.export, a.out, level, problem, a.brick, a.loads, a.load_rule)


if __name__ == "__main__":
    main()
