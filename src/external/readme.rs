//! The README.md of an exported problem: what to solve, what to write back, how to convert.

use super::family::Family;
use std::fmt::Write as _;

/// The README of an export of `family` at `levels` (level, h, nodes, triangles).
pub fn export_readme(family: &Family, levels: &[(usize, f64, usize, usize)]) -> String {
    let scene = &family.scene;
    let what = match &family.study {
        Some(s) => format!("study `{s}` (scene `{}`)", scene.name),
        None => format!("scene `{}`", scene.name),
    };
    let (first, last) = (levels[0].0, levels[levels.len() - 1].0);
    let viscoplastic = scene
        .bodies
        .iter()
        .any(|b| b.material.viscoplastic.is_some());
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# The contact problem of {what}, levels {first}-{last}\n"
    );
    let _ = writeln!(
        out,
        "{}\n\nSolve it with your own contact code on these meshes (or any P1 triangle meshes of the same bodies), write the solutions as below, and grade them:\n\n```sh\ncontact-rates grade {} {} --solutions SOLUTIONS --levels {first}-{last} --name mycode\n```\n\nThe report gives your code's errors against the exact solution, fitted rates and verdicts, beside this project's mortar (K_h^pi) and node-on-segment (K_h^I) on the same meshes.\n",
        scene.description,
        family.option,
        family.study.as_deref().unwrap_or(&scene.name),
    );
    out.push_str("## Files\n\n| file | what |\n|---|---|\n");
    out.push_str("| `mesh_L.msh` | level L's mesh of both bodies, gmsh MSH 4.1 ASCII |\n");
    out.push_str("| `mesh_L.msh22.msh` | the same mesh in MSH 2.2 ASCII, for readers of the older format (GetFEM 5.4) |\n");
    out.push_str("| `problem.toml` | the physics: materials as numbers (plane stress lambda* and mu beside E and nu), supports, tractions, Gamma_C with its normals, time steps, and the loads and exact fields as expressions (syntax in its `syntax` key) |\n");
    out.push_str("| `problem.py` | the same expressions as sympy expressions and callables (`pip install sympy`); `python3 problem.py` checks every derived field against sympy's own derivatives |\n");
    out.push_str("| `loads_L.csv` | the P1-consistent nodal loads of level L at every step (step, t, node, fx, fy): body forces and tractions integrated exactly across the kinks of the exact fields, as this project's solver does |\n");
    if viscoplastic {
        out.push_str("| `source_L.csv` | the constitutive source's mean over each triangle of level L at t_n (step, t, element, s11, s22, s12; stress per time) |\n");
    }
    out.push_str(
        "\n| level | h (largest triangle diameter) | nodes | triangles |\n|---|---|---|---|\n",
    );
    for (level, h, nodes, triangles) in levels {
        let _ = writeln!(out, "| {level} | {h:.6} | {nodes} | {triangles} |");
    }
    out.push_str(MESH_TEXT);
    out.push_str(SOLVE_TEXT);
    if viscoplastic {
        out.push_str(VISCOPLASTIC_TEXT);
    }
    out.push_str(WRITE_BACK_TEXT);
    let _ = writeln!(
        out,
        "\n## This project's own solve of a level\n\n`{}` writes `out/solution.pvd` with its `.vtu` steps, which `grade` reads as it reads yours (`--solutions` holding `level_L.pvd` and the steps).",
        family.solve_command(first)
    );
    out
}

const MESH_TEXT: &str = "
## The meshes

Node tags are 1..N, body 1's nodes first; triangle tags 1..M (body 1's first), then the
boundary lines. The physical surfaces name the bodies (tag 1: body 1, tag 2: body 2), the
physical curves every support, traction and contact curve, as `problem.toml` refers to them.

**The two bodies share no node**, also at the ends of Gamma_C where their corners coincide.
Do not let your importer merge coincident points (meshio does not; in gmsh keep
`Geometry.AutoCoherence = 0` and do not call `Coherence Mesh`): merged nodes glue the bodies
there.
";

const SOLVE_TEXT: &str = "
## What to solve

Two bodies, plane stress, small strain, frictionless, quasistatic. At each t_n
(`time.times`), find u_n in K, the displacements that satisfy the supports and
non-penetration on Gamma_C, such that for every v in K

    int_Omega sigma_n : eps(v - u_n) dx >= int_Omega f(t_n) . (v - u_n) dx + int_Gamma_N g(t_n) . (v - u_n) ds

with sigma_n = E eps(u_n) in an elastic body (`bodies.elasticity`). Written as equilibrium,
the contact pressure p is a traction on both sides of Gamma_C, positive in compression:
-p nu^1 on body 1 and -p nu^2 = p nu^1 on body 2 (`contact.pieces.slave_normal` is nu^1), with

    [u.nu] = u^1.nu^1 + u^2.nu^2 <= 0,   p >= 0,   p [u.nu] = 0,   zero tangential traction.

The body forces f and tractions g are in `problem.toml` as expressions, and as nodal loads in
`loads_L.csv` for codes that cannot integrate expressions (a row at a node where a support
prescribes a component is ignored there). How you discretize the contact condition is your
choice: mortar, node-to-segment, penalty, Nitsche, augmented Lagrangian.

Body 1 is the slave (its nodes carry the rows of the discrete condition in this project):
GetFEM's slave region, MOOSE's secondary boundary. Body 2 is the master (primary).
";

const VISCOPLASTIC_TEXT: &str = "
### The viscoplastic body

Perzyna's law (`bodies.viscoplastic`): d sigma/dt = E eps(du/dt) + G(sigma) + s with
G(sigma) = -(1/(2 viscosity)) E (sigma - P sigma), P the projection onto the von Mises set
{|tau|_VM <= yield_stress} in the inner product (E^-1 sigma, tau). Time discretization:
backward Euler per triangle, sigma_n = sigma_(n-1) + E (eps(u_n) - eps(u_(n-1))) + k G(sigma_n)
+ k s_n, with the stress constant per triangle (P0) and s_n the source's mean over the triangle
at t_n (`source_L.csv`). The source makes the manufactured fields satisfy the law; a code
that implements the law as written here reproduces the exact solution's rates.
";

const WRITE_BACK_TEXT: &str = "
## What to write back

One file per level L in the solutions folder, any of:

- `level_L.vtu`: the state at t = T (VTK XML unstructured grid; the theorem norm is then taken
  at T only, and the report says so);
- `level_L.pvd`: a ParaView collection of `.vtu` files, one per step, whose `timestep`s are the
  t_n of `problem.toml` (to 1e-9 T);
- `level_L.msh`: gmsh MSH (ASCII 4.1 or 2.2) with the bodies as physical surfaces named as in
  `mesh_L.msh` (or, without `$PhysicalNames`, with physical tags 1 and 2), and `$NodeData`/`$ElementData` views named as the fields below, one per step
  (the view's time is its real tag).

Fields (other names with `--displacement`, `--stress`, `--pressure`), in the scene's units:

| field | where | components | required |
|---|---|---|---|
| `displacement` | points | 2, or 3 with a zero z | yes |
| `stress` | cells (P0) | 3 (s11, s22, s12), 4 (2x2 row-major) or 9 (3x3, zero z parts) | for a viscoplastic body; otherwise computed from u_h as E eps(u_h) |
| `pressure` | points | 1, force per length, positive in compression, read at the slave curve's nodes | no: without it the pressure quantities are not measured |
| `body` | cells (VTU only) | 1: 1 for body 1, 2 for body 2 | yes |

Only P1 triangles are graded: split quadrilaterals into triangles, and write a P2 solution's
vertex values as P1. Any mesh of the two bodies is accepted, not only these.

**A pressure from contact forces or multipliers.** A nodal contact force F_i at slave node i
(node-on-segment codes, GetFEM's nodal contact brick) is p_i = |F_i . nu^1| / w_i, with w_i
half the length of the slave edges at node i. A multiplier that is already a traction
(GetFEM's integral contact brick with a P1 multiplier, MOOSE's `contact_pressure`) is p as it
is, sign flipped if it is negative in compression.

**Converting with meshio** (`pip install meshio`), the element blocks numbered as the bodies:

    python3 -c \"import meshio, numpy as np; m = meshio.read('out.e'); m.cell_data['body'] = [np.full(len(c.data), i + 1) for i, c in enumerate(m.cells)]; meshio.write('level_3.vtu', m)\"
    python3 -c \"import meshio, numpy as np; r = meshio.xdmf.TimeSeriesReader('u.xdmf'); p, c = r.read_points_cells(); t, pd, cd = r.read_data(r.num_steps - 1); meshio.write('level_3.vtu', meshio.Mesh(p, c, point_data=pd, cell_data={'body': [np.full(len(b.data), i + 1) for i, b in enumerate(c)]}))\"

The first converts an Exodus file (MOOSE) at its last step, the second an XDMF time series
(FEniCSx, dolfinx.io.XDMFFile) at its last step; where your bodies are not separate blocks,
set `body` from your cell markers instead.
";
