//! The README.md of an exported problem: what to solve, what to write back, how to convert.

use super::export::Loading;
use super::family::Family;
use std::fmt::Write as _;

/// The README of an export of `family` at `levels` (level, h, nodes, triangles), with what
/// `loading` says of the loads.
pub fn export_readme(
    family: &Family,
    levels: &[(usize, f64, usize, usize)],
    loading: &Loading,
) -> String {
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
        "{}\n\nSolve it with your own contact code on these meshes (or any P1 triangle meshes of the same bodies), write the solutions as below, and grade them:\n\n```sh\ncontact-rates grade {} {} --solutions SOLUTIONS --levels {first}-{last} --name mycode\n```\n\n(`contact-rates` is this project's binary: `cargo install --path .` in its checkout puts it on PATH; or write `cargo run --release --` in its place, from the checkout.)\n\nThe report gives your code's errors against the exact solution, fitted rates and verdicts, beside this project's mortar (K_h^pi) and node-on-segment (K_h^I) on the same meshes.\n",
        scene.description,
        family.option,
        family.study.as_deref().unwrap_or(&scene.name),
    );
    out.push_str("## Files\n\n| file | what |\n|---|---|\n");
    out.push_str("| `mesh_L.msh` | level L's mesh of both bodies, gmsh MSH 4.1 ASCII |\n");
    out.push_str("| `mesh_L.msh22.msh` | the same mesh in MSH 2.2 ASCII, for readers of the older format (GetFEM 5.4) |\n");
    out.push_str("| `problem.toml` | the physics: materials as numbers (the 2D law's lambda* and mu beside E and nu, `bodies.plane`), supports, tractions, Gamma_C with its normals, time steps, and the loads and exact fields as expressions (syntax in its `syntax` key) |\n");
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
    let plane = scene.bodies[0].material.elastic.plane.label();
    out.push_str(&SOLVE_TEXT.replace(
        "Two bodies, plane stress,",
        &format!("Two bodies, {plane},"),
    ));
    if let Some(g) = &scene.initial_gap {
        let _ = write!(out, "{}", GAP_TEXT.replace("G0", &g.text));
    }
    out.push_str(&loading_text(family, loading, viscoplastic));
    out.push_str(SUPPORTS_TEXT);
    if viscoplastic {
        out.push_str(VISCOPLASTIC_TEXT);
    }
    out.push_str(WRITE_BACK_TEXT);
    let _ = writeln!(
        out,
        "\n## This project's own solves\n\n`solve --out DIR` writes `DIR/solution.pvd` with its `.vtu` steps; `grade` reads a folder `level_L` per level as it reads `level_L.pvd` (one `.pvd`, or one `.vtu` or `.msh`, in it). Mortar's solves of every level, graded as yours would be (`--method nts` for the other cone):\n\n```sh"
    );
    for (level, ..) in levels {
        let _ = writeln!(
            out,
            "{} --out cones/level_{level}",
            family.solve_command(*level)
        );
    }
    let _ = writeln!(
        out,
        "contact-rates grade {} {} --solutions cones --levels {first}-{last} --name own-mortar\n```",
        family.option,
        family.study.as_deref().unwrap_or(&scene.name),
    );
    out
}

/// What the loads do in time, and which body only the contact holds.
fn loading_text(family: &Family, loading: &Loading, viscoplastic: bool) -> String {
    let mut out = String::from("\n### The loading\n\n");
    if loading.proportional {
        out.push_str("The loads are proportional to t: every step's nodal loads are t_n / T times those at T (checked on every exported level to 1e-12 of the largest). ");
        out.push_str(match viscoplastic {
            false => "Both bodies are elastic, so the state at t_n is one solve with the loads at t_n: a code that solves t = T alone gives the state at T (`level_L.vtu`), graded at T only.\n",
            true => "A viscoplastic body's state depends on its history: solve every step in turn.\n",
        });
    } else {
        out.push_str("The loads are not proportional to t: solve every step with its own loads.\n");
    }
    if let Some(body) = loading.held_by_contact {
        let _ = write!(
            out,
            "\nBody {} ('{}') is held along Gamma_C's normal by the contact alone: no support holds it there. A code that starts from u = 0 with the contact inactive sees a singular tangent (a rigid motion): start with every slave node in contact (the bodies touch at t = 0), or, in a penalty or augmented-Lagrangian code, from a start that presses body {} onto the other (a small displacement along Gamma_C's normal), so that the contact acts at the first iteration.\n",
            body + 1,
            family.scene.bodies[body].surface,
            body + 1
        );
    }
    out
}

const SUPPORTS_TEXT: &str = "
### Supports

`problem.toml`'s `[[supports]]` name a curve, its body and a `kind`, one of:

| kind | condition on the curve |
|---|---|
| `clamp` | u = 0 |
| `roller x` | u_x = 0; u_y free, with zero traction in y |
| `roller y` | u_y = 0; u_x free, with zero traction in x |
";

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

const GAP_TEXT: &str = "
### The initial gap

This problem has an initial gap g0 = G0 (`contact.gap`, length) between the bodies along nu^1:
the condition reads [u.nu] <= g0, p >= 0, p ([u.nu] - g0) = 0. The meshes are touching (the
two contact curves coincide); pose the gap as data, per constraint, the way your code takes
one: at the slave nodes for node-to-segment constraints, weighted by each multiplier's test
function for mortar constraints (the weighted gap, integral of g0 psi_i), averaged over a
patch for averaged constraints (`contact.gap_rule` in `problem.toml`). A code that takes
geometry only must move body 2's contact curve by g0 along nu^1, away from body 1: that is a
different mesh, graded on its own. Penetration is graded against g0 on your mesh's
Gamma_C: the largest ([u.nu] - g0)^+ and its L2 norm.
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

**A pressure from contact forces or multipliers.** Write p at the slave curve's nodes,
positive in compression, signed (a pulling force gives a negative p: do not take its
absolute value, `grade` reads it as what the code did):
- a nodal contact force F_i on slave node i (node-on-segment codes, GetFEM's nodal contact
  brick, and a penalty code's forces summed at the slave nodes from its Gauss points) is
  p_i = -(F_i . nu^1) / w_i, F_i the force the contact exerts on body 1 and w_i half the
  length of the slave edges at node i (sum the slave side's forces only: the master side's
  are their reaction);
- a multiplier that is already a traction (GetFEM's integral contact brick with a P1
  multiplier, MOOSE's `contact_pressure`) is p as it is, sign flipped if it is negative in
  compression;
- a scaled multiplier is p = the scale times the multiplier, sign as above: Kratos's mortar
  ALM stores `LAGRANGE_MULTIPLIER_CONTACT_PRESSURE` divided by its `SCALE_FACTOR`
  (p = -SCALE_FACTOR x that multiplier; examples/grade_kratos.py).

`grade` checks the result: the resultant of p over Gamma_C at T against the exact one's; a
negative ratio (the sign), or a ratio off 1 by more than 5% and the same to 1% at every
level (a scale), or off by more than a factor 2 at every level (the units), is refused with
the fix.

**Converting with meshio** (`pip install meshio`), the element blocks numbered as the bodies:

    python3 -c \"import meshio, numpy as np; m = meshio.read('out.e'); m.cell_data['body'] = [np.full(len(c.data), i + 1) for i, c in enumerate(m.cells)]; meshio.write('level_3.vtu', m)\"
    python3 -c \"import meshio, numpy as np; r = meshio.xdmf.TimeSeriesReader('u.xdmf'); p, c = r.read_points_cells(); t, pd, cd = r.read_data(r.num_steps - 1); meshio.write('level_3.vtu', meshio.Mesh(p, c, point_data=pd, cell_data={'body': [np.full(len(b.data), i + 1) for i, b in enumerate(c)]}))\"

The first converts an Exodus file (MOOSE) at its last step, the second an XDMF time series
(FEniCSx, dolfinx.io.XDMFFile) at its last step; where your bodies are not separate blocks,
set `body` from your cell markers instead.
";
