"""Solve an exported contact problem with Kratos Multiphysics 10.4 (mortar contact, augmented
Lagrangian method, frictionless) and write the solutions `grade` reads.

    pip install KratosMultiphysics KratosStructuralMechanicsApplication \
        KratosContactStructuralMechanicsApplication KratosLinearSolversApplication
    contact-rates export --study rates-exact --levels 0-4 --out EXPORT_DIR
    OMP_NUM_THREADS=1 python3 examples/grade_kratos.py EXPORT_DIR OUT_DIR [--levels A-B]
    contact-rates grade --study rates-exact --solutions OUT_DIR --levels 0-4 --name kratos-alm

(`contact-rates` is the project's binary: `cargo install --path .` puts it on PATH, or
use `cargo run --release --` in its place from the checkout.)

Per level L of EXPORT_DIR, the model part is built here in Python from mesh_L.msh22.msh:
- elements: P1 triangles, SmallDisplacementElement2D3N, LinearElasticPlaneStress2DLaw with E and
  nu of problem.toml and thickness 1;
- supports: the curves of problem.toml's [[supports]], as fixed degrees of freedom;
- loads: the nodal loads of loads_L.csv, as PointLoadCondition2D1N with POINT_LOAD;
- contact: the ContactStructuralMechanicsApplication's ALMContactProcess, frictionless mortar
  contact with dual Lagrange multipliers between the slave curve (body 1) and the master curve
  (body 2) of problem.toml's [contact].
Small strain: the mesh never moves, so the mortar operators stay those of the exported mesh. At
each t_n, Kratos's Newton solves with the active set frozen, and this script updates the active
set by the ALM rule from the weighted gaps of u (Kratos's own update would read gaps of the
unmoved mesh: see solve_level), until it repeats; the residual is then checked independently.
Writes OUT_DIR/level_L.pvd and one .vtu per step with point data `displacement` and `pressure`
(force per length, positive in compression, at the slave nodes), cell data `body` and `stress`
(Kratos's P0 Cauchy stress s11, s22, s12).
"""

import argparse
import json
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

import KratosMultiphysics as KM
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA
import KratosMultiphysics.LinearSolversApplication  # noqa: F401 (registers sparse_lu)
import KratosMultiphysics.StructuralMechanicsApplication as SMA
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (
    StructuralMechanicsAnalysis,
)

FIXED = {"clamp": "xy", "roller x": "x", "roller y": "y"}  # support kind -> fixed components
LM = CSMA.LAGRANGE_MULTIPLIER_CONTACT_PRESSURE
UX, UY, RX, RY = KM.DISPLACEMENT_X, KM.DISPLACEMENT_Y, KM.REACTION_X, KM.REACTION_Y
NEWTON_TOL = 1e-10  # residual relative to the step's first one, or correction relative to u
CHECK_TOL = 1e-8  # largest residual entry relative to the largest load, checked independently


def read_msh22(path):
    """gmsh MSH 2.2 ASCII: the points (N, 2), row = node tag - 1, and per physical name the
    triangles (node-tag triples) or lines (node-tag pairs) that carry it."""
    lines = Path(path).read_text().splitlines()
    sec = {s: i for i, s in enumerate(lines) if s.startswith("$")}
    names = {}
    for s in lines[sec["$PhysicalNames"] + 2 : sec["$EndPhysicalNames"]]:
        _, tag, name = s.split(maxsplit=2)
        names[int(tag)] = name.strip('"')
    nodes = [s.split() for s in lines[sec["$Nodes"] + 2 : sec["$EndNodes"]]]
    if [int(n[0]) for n in nodes] != list(range(1, len(nodes) + 1)):
        sys.exit(f"{path}: $Nodes: node tags are not 1..N in order; re-export the mesh")
    points = np.array([[float(n[1]), float(n[2])] for n in nodes])
    groups = {}
    for s in lines[sec["$Elements"] + 2 : sec["$EndElements"]]:
        f = [int(v) for v in s.split()]
        if f[1] not in (1, 2):  # gmsh type 1: 2-node line, 2: 3-node triangle
            sys.exit(f"{path}: element {f[0]} has gmsh type {f[1]}: only P1 lines and triangles")
        groups.setdefault(names[f[3]], []).append(f[3 + f[2] :])  # f[3]: the physical tag
    return points, {k: np.array(v) for k, v in groups.items()}


def project_parameters(problem):
    """The analysis stage's settings: the solver and the contact process (the model part is
    built in Python: `use_input_model_part`)."""
    return {
        "problem_data": {
            "problem_name": "contact-rates",
            "parallel_type": "OpenMP",
            "start_time": 0.0,
            "end_time": problem["time"]["final_time"],
            "echo_level": 0,
        },
        "solver_settings": {
            "model_part_name": "Structure",
            "domain_size": 2,
            "solver_type": "Static",
            "echo_level": 0,
            "analysis_type": "non_linear",
            "model_import_settings": {"input_type": "use_input_model_part"},
            "material_import_settings": {"materials_filename": ""},
            "time_stepping": {"time_step": 1.0},  # set per step below
            "move_mesh_flag": False,  # small strain: the mesh, so the mortar operators, stay
            "compute_reactions": True,
            "contact_settings": {"mortar_type": "ALMContactFrictionless"},
            "max_iteration": 50,
            "linear_solver_settings": {"solver_type": "LinearSolversApplication.sparse_lu"},
        },
        "processes": {
            "contact_process_list": [
                {
                    "python_module": "alm_contact_process",
                    "kratos_module": "KratosMultiphysics.ContactStructuralMechanicsApplication",
                    "process_name": "ALMContactProcess",
                    "Parameters": {
                        "model_part_name": "Structure",
                        # the nodes of both contact curves: the process builds the line
                        # conditions from the elements' edges and pairs them by its search
                        "contact_model_part": {"0": ["ContactCurves"]},
                        "assume_master_slave": {"0": [problem["contact"]["slave_curve"]]},
                        "contact_type": "Frictionless",
                    },
                }
            ]
        },
        "output_processes": {},
    }


def build_model_part(mp, points, groups, problem, loaded_nodes):
    """Nodes (id = MSH tag), elements (id 1..M, body 1's first), one sub model part per body
    and per named curve, and a point-load condition at each loaded node. Returns the body of
    each element, the elements, and the point-load conditions by node."""
    for i, (x, y) in enumerate(points, start=1):
        mp.CreateNewNode(i, x, y, 0.0)
    body_of, elements, prop_of_node = [], [], {}
    for b in problem["bodies"]:
        prop = mp.GetProperties()[b["number"]]
        prop.SetValue(KM.YOUNG_MODULUS, b["young"])
        prop.SetValue(KM.POISSON_RATIO, b["poisson"])
        prop.SetValue(KM.THICKNESS, 1.0)
        prop.SetValue(KM.DENSITY, 1.0)
        prop.SetValue(KM.CONSTITUTIVE_LAW, SMA.LinearElasticPlaneStress2DLaw())
        tris = groups[b["surface"]].copy()
        a, c, d = (points[tris[:, k] - 1] for k in range(3))
        cw = (c[:, 0] - a[:, 0]) * (d[:, 1] - a[:, 1]) - (c[:, 1] - a[:, 1]) * (
            d[:, 0] - a[:, 0]
        ) < 0
        tris[cw] = tris[cw][:, [0, 2, 1]]  # Kratos wants counter-clockwise triangles
        body = mp.CreateSubModelPart(b["surface"])
        for t in tris:
            nodes = [int(n) for n in t]
            elements.append(
                mp.CreateNewElement("SmallDisplacementElement2D3N", len(elements) + 1, nodes, prop)
            )
        body.AddNodes(sorted({int(n) for n in tris.ravel()}))
        body.AddElements([e.Id for e in elements[len(body_of) :]])
        body_of += [b["number"]] * len(tris)
        prop_of_node.update({int(n): prop for n in tris.ravel()})
    contact = problem["contact"]
    curves = {s["curve"] for s in problem["supports"]} | {
        contact["slave_curve"],
        contact["master_curve"],
    }
    for name in curves:
        if name not in groups:
            sys.exit(f"problem.toml names the curve {name!r}, which the mesh lacks; re-export")
        mp.CreateSubModelPart(name).AddNodes(sorted({int(n) for n in groups[name].ravel()}))
    # "Contact" is the name the contact process gives its own sub model part: not this one
    both = {int(n) for c in ("slave_curve", "master_curve") for n in groups[contact[c]].ravel()}
    mp.CreateSubModelPart("ContactCurves").AddNodes(sorted(both))
    # the contact process renumbers all conditions: keep the objects, not their ids
    point_loads = {
        n: mp.CreateNewCondition("PointLoadCondition2D1N", k, [n], prop_of_node[n])
        for k, n in enumerate(loaded_nodes, start=1)
    }
    return np.array(body_of), elements, point_loads


def residual(solver, mp):
    """The residual (external minus internal and contact forces; the weighted gaps at the LM
    rows), built anew by Kratos's builder at the converged state: largest free displacement
    and LM entries."""
    bs, scheme = solver._GetBuilderAndSolver(), solver._GetScheme()
    b = KM.Vector(bs.GetEquationSystemSize(), 0.0)
    bs.BuildRHS(scheme, mp, b)
    worst = {"disp": 0.0, "lm": 0.0}
    for dof in bs.GetDofSet():
        if not dof.IsFixed():
            key = "lm" if dof.GetVariable().Name() == LM.Name() else "disp"
            worst[key] = max(worst[key], abs(b[dof.EquationId]))
    return worst


def weighted_gaps(solver, mp, slave_nodes, active):
    """The weighted gaps g_j = -nu_j . (D x1 - M x2)_j of u (x = X + u), positive open: the
    LM rows of the residual of an active node are SCALE_FACTOR * g_j, so they are read with
    every slave node flagged active, then the flags are restored."""
    for j in slave_nodes:
        mp.GetNode(int(j)).Set(KM.ACTIVE, True)
    bs, scheme = solver._GetBuilderAndSolver(), solver._GetScheme()
    b = KM.Vector(bs.GetEquationSystemSize(), 0.0)
    bs.BuildRHS(scheme, mp, b)
    for j in slave_nodes:
        mp.GetNode(int(j)).Set(KM.ACTIVE, active[j])
    rows = [mp.GetNode(int(j)).GetDof(LM).EquationId for j in slave_nodes]
    return np.array([b[i] for i in rows]) / mp.ProcessInfo[KM.SCALE_FACTOR]


def write_vtu(path, points, tris, point_data, cell_data):
    """VTK XML unstructured grid, ASCII, P1 triangles (VTK type 5)."""

    def arr(name, a, kind):
        a = np.asarray(a)
        comps = 1 if a.ndim == 1 else a.shape[1]
        fmt = "%d" if kind == "Int32" else "%.17g"
        body = "\n".join(" ".join(fmt % v for v in np.atleast_1d(row)) for row in a)
        head = (
            f'<DataArray type="{kind}" Name="{name}" NumberOfComponents="{comps}" format="ascii">'
        )
        return f"{head}\n{body}\n</DataArray>\n"

    xyz = np.column_stack([points, np.zeros(len(points))])
    path.write_text(
        '<?xml version="1.0"?>\n'
        '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
        f'<UnstructuredGrid>\n<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(tris)}">\n'
        "<Points>\n"
        + arr("Points", xyz, "Float64")
        + "</Points>\n<Cells>\n"
        + arr("connectivity", tris.ravel(), "Int32")
        + arr("offsets", 3 * np.arange(1, len(tris) + 1), "Int32")
        + arr("types", np.full(len(tris), 5), "Int32")
        + "</Cells>\n<PointData>\n"
        + "".join(arr(k, v, "Float64") for k, v in point_data.items())
        + "</PointData>\n<CellData>\n"
        + "".join(arr(k, v, "Int32" if k == "body" else "Float64") for k, v in cell_data.items())
        + "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
    )


def solve_level(export, out, level, problem):
    t0 = time.perf_counter()
    points, groups = read_msh22(export / f"mesh_{level}.msh22.msh")
    if not (export / f"loads_{level}.csv").is_file():
        sys.exit(f"{export}/loads_{level}.csv: not found; re-export with this level")
    loads = np.loadtxt(export / f"loads_{level}.csv", delimiter=",", skiprows=1, ndmin=2)
    contact = problem["contact"]
    normals = {tuple(p["slave_normal"]) for p in contact["pieces"]}
    if len(normals) != 1:
        sys.exit(
            "problem.toml: contact.pieces: this script handles one slave_normal (straight Gamma_C)"
        )
    nu = np.array(normals.pop(), float)
    load_scale = np.abs(loads[:, 3:5]).max()

    model = KM.Model()
    params = KM.Parameters(json.dumps(project_parameters(problem)))
    analysis = StructuralMechanicsAnalysis(model, params)  # creates "Structure" with its variables
    mp = model["Structure"]
    loaded = sorted({int(n) for n in loads[:, 2]})
    body_of, elements, point_loads = build_model_part(mp, points, groups, problem, loaded)
    # Newton with frozen ACTIVE flags (see the active-set loop below): plain criteria replace
    # the application's, whose mortar part would update the flags. The residual one alone can
    # stall on round-off: the LM rows are SCALE_FACTOR times gaps computed from coordinates.
    solver = analysis._GetSolver()
    solver._convergence_criterion = KM.OrCriteria(
        KM.ResidualCriteria(NEWTON_TOL, 1e-14 * load_scale),
        KM.DisplacementCriteria(NEWTON_TOL, 1e-300),
    )
    analysis.Initialize()  # adds the dofs; the contact process makes its conditions, SCALE_FACTOR
    fixed = set()
    for s in problem["supports"]:
        if s["kind"] not in FIXED:
            sys.exit(f"problem.toml: supports: kind {s['kind']!r}: this script knows {list(FIXED)}")
        for c in FIXED[s["kind"]]:
            var = UX if c == "x" else UY
            for node in mp.GetSubModelPart(s["curve"]).Nodes:
                node.Fix(var)
                node.SetSolutionStepValue(var, 0.0)
                fixed.add((node.Id, c))

    # The pressure: p_j = -SCALE_FACTOR * LAGRANGE_MULTIPLIER_CONTACT_PRESSURE_j. The multiplier
    # is a scaled unknown, negative in compression: each mortar pair adds (SCALE_FACTOR * lambda_j
    # + k * g_j^pair) nu_j . (D dv1 - M dv2)_j to the virtual work, with g_j^pair the pair's share
    # of the weighted gap. With dual multipliers D is diagonal, D_jj = w_j = int N_j ds (half the
    # slave edges at j), so the nodal force at slave node j is p_j w_j up to the k * g_j^pair
    # shares, which cancel only in sum over the pairs (checked below against the loads).
    slave_lines = groups[contact["slave_curve"]]
    slave_nodes = np.unique(slave_lines)
    w = np.zeros(len(points) + 1)
    half = 0.5 * np.linalg.norm(
        points[slave_lines[:, 0] - 1] - points[slave_lines[:, 1] - 1], axis=1
    )
    np.add.at(w, slave_lines.ravel(), np.repeat(half, 2))
    body1 = [n.Id for n in mp.GetSubModelPart(problem["bodies"][0]["surface"]).Nodes]
    slave_objects = [mp.GetNode(int(j)) for j in slave_nodes]
    scale_factor = mp.ProcessInfo[KM.SCALE_FACTOR]
    penalty = mp.ProcessInfo[KM.INITIAL_PENALTY]  # k, the ALM penalty

    tris = np.array([[n.Id - 1 for n in e.GetGeometry()] for e in elements])
    active = {j: True for j in slave_nodes}
    setup_s, solve_s, datasets, report = time.perf_counter() - t0, 0.0, [], []
    for step, t in enumerate(problem["time"]["times"], start=1):
        solver.settings["time_stepping"]["time_step"].SetDouble(t - analysis.time)
        analysis.time = solver.AdvanceInTime(analysis.time)
        rows = loads[loads[:, 0] == step]
        if len(rows) == 0 or abs(rows[0, 1] - t) > 1e-9 * problem["time"]["final_time"]:
            sys.exit(f"{export}/loads_{level}.csv: no rows for step {step} at t = {t}; re-export")
        f = {n: np.zeros(2) for n in point_loads}
        for r in rows:
            f[int(r[2])] += r[3:5]
        for n, cond in point_loads.items():
            # a load on a supported component is ignored
            fx, fy = (0.0 if (n, c) in fixed else v for c, v in zip("xy", f[n]))
            cond.SetValue(SMA.POINT_LOAD, [fx, fy, 0.0])
            f[n] = np.array([fx, fy])
        # The active set is driven here, by the primal-dual active set rule of the ALM process,
        # because Kratos's own rule reads the nodal WEIGHTED_GAP, which it integrates on the
        # current nodal coordinates: with the mesh fixed they never move, that gap never sees u,
        # and the active set cycles on round-off (rates-exact level 2). Each pass solves with the
        # ACTIVE flags frozen (Newton on a linear problem), then updates them from
        # SCALE_FACTOR * lambda + k * (weighted gap of u) < 0.
        # The singular start: body 1 may be held along nu by contact alone, so the first step
        # starts with all slave nodes active (body 1 tied to body 2 along nu: regular); each
        # later step starts from the previous step's active set.
        analysis.InitializeSolutionStep()
        iterations, passes = [], 0
        t1 = time.perf_counter()
        while True:
            passes += 1
            for j, node in zip(slave_nodes, slave_objects):
                node.Set(KM.ACTIVE, active[j])
            converged = solver.SolveSolutionStep()
            iterations.append(mp.ProcessInfo[KM.NL_ITERATION_NUMBER])
            if not converged:
                sys.exit(
                    f"level {level}, step {step} (t = {t}): Newton did not converge in "
                    f"{iterations[-1]} iterations (active-set pass {passes})"
                )
            lam = np.array([lm_node.GetSolutionStepValue(LM) for lm_node in slave_objects])
            gap = weighted_gaps(solver, mp, slave_nodes, active)
            aug = scale_factor * lam + penalty * gap
            tol = 1e-12 * max(np.abs(scale_factor * lam).max(), np.abs(penalty * gap).max(), 1e-300)
            new = {j: a < (tol if active[j] else -tol) for j, a in zip(slave_nodes, aug)}
            if new == active:
                break
            if passes == 30:
                sys.exit(f"level {level}, step {step} (t = {t}): the active set did not settle")
            active = new
        solve_s += time.perf_counter() - t1
        r = residual(solver, mp)
        analysis.FinalizeSolutionStep()  # computes REACTION
        if max(r.values()) > CHECK_TOL * load_scale:
            sys.exit(
                f"level {level}, step {step} (t = {t}): largest residual {max(r.values()):.2e}, "
                f"loads up to {load_scale:.2e}"
            )
        disp = np.array([[n.GetSolutionStepValue(v) for v in (UX, UY)] for n in mp.Nodes])
        pressure = np.zeros(len(points))
        pressure[slave_nodes - 1] = -scale_factor * lam
        n_active = sum(active.values())
        # complementarity, scaled: weighted gaps by max w * max |u|, pressures by max p
        gap_scale, p_scale = w.max() * np.abs(disp).max(), max(pressure.max(), 1e-300)
        kkt = max(
            (-gap).max() / gap_scale,
            (-pressure).max() / p_scale,
            np.abs(gap * pressure[slave_nodes - 1]).max() / (gap_scale * p_scale),
        )
        # Check the rule against equilibrium of body 1 along nu: its loads and support reactions
        # are balanced by the contact force -sum_j p_j w_j nu
        reaction = {
            n: np.array([mp.GetNode(n).GetSolutionStepValue(v) for v in (RX, RY)]) for n in body1
        }
        held = sum(np.dot(f.get(n, 0.0) + reaction[n], nu) for n in body1)
        transmitted = float(np.dot(pressure[slave_nodes - 1], w[slave_nodes]))
        stress = [
            e.CalculateOnIntegrationPoints(KM.CAUCHY_STRESS_VECTOR, mp.ProcessInfo)[0]
            for e in elements
        ]
        name = f"level_{level}_step_{step}.vtu"
        write_vtu(
            out / name,
            points,
            tris,
            {"displacement": disp, "pressure": pressure},
            {"body": body_of, "stress": np.array(stress)[:, :3]},
        )
        datasets.append(f'<DataSet timestep="{t!r}" file="{name}"/>')
        report.append(
            f"  step {step} t={t:g}: {passes} active-set passes, Newton iterations {iterations}, "
            f"residual / max load {r['disp'] / load_scale:.1e} (forces) {r['lm'] / load_scale:.1e} "
            f"(weighted gaps), {n_active}/{len(slave_nodes)} slave nodes active, complementarity "
            f"{kkt:.1e}, max p {pressure.max():.4g}, sum p w = {transmitted:.10g} against loads "
            f"{held:.10g} (rel. diff {abs(transmitted - held) / max(abs(held), 1e-300):.1e})"
        )
    analysis.Finalize()
    (out / f"level_{level}.pvd").write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
        + "\n".join(datasets)
        + "\n</Collection>\n</VTKFile>\n"
    )
    print(
        f"level {level}: {len(points)} nodes, {len(tris)} triangles, "
        f"{len(slave_nodes)} slave nodes, "
        f"SCALE_FACTOR {scale_factor:.6g}; set-up {setup_s:.2f} s, Newton {solve_s:.2f} s, "
        f"total {time.perf_counter() - t0:.2f} s"
    )
    print("\n".join(report), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("export", type=Path, help="a folder written by `contact-rates export`")
    ap.add_argument("out", type=Path, help="where to write level_L.pvd and the .vtu steps")
    ap.add_argument("--levels", help="A-B or A (default: every level of problem.toml)")
    args = ap.parse_args()
    if not (args.export / "problem.toml").is_file():
        sys.exit(
            f"{args.export}/problem.toml: not found; "
            f"run `contact-rates export --study ... --out {args.export}` first"
        )
    problem = tomllib.loads((args.export / "problem.toml").read_text())
    levels = problem["levels"]
    if args.levels:
        a, _, b = args.levels.partition("-")
        levels = [l for l in levels if int(a) <= l <= int(b or a)]
        if not levels:
            sys.exit(f"--levels {args.levels}: problem.toml has levels {problem['levels']}")
    args.out.mkdir(parents=True, exist_ok=True)
    for level in levels:
        solve_level(args.export, args.out, level, problem)


if __name__ == "__main__":
    main()
