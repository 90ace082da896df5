//! The physics of an exported problem as numbers and expressions (problem.toml), and the same
//! expressions as sympy callables (problem.py), so that another code can solve exactly the
//! problem this project solves and no user translates syntax by hand.

use crate::contact::Interface;
use crate::expr::Expr;
use crate::fe::Model;
use crate::mesh::msh::ExportMesh;
use crate::scene::Scene;
use serde::Serialize;

/// The syntax of every expression in problem.toml.
pub const SYNTAX: &str = "expressions in x, y (length) and t (time): numbers, + - * / ^ (power), parentheses, pi, sin cos tan exp log (natural) sqrt abs, and signum(z) (-1 for z < 0, +1 for z >= 0); the kink of a piecewise field is an abs, its derivative a signum. problem.py gives every expression as a sympy expression and a callable";

/// problem.toml.
#[derive(Serialize)]
pub struct ProblemFile {
    /// What this file is.
    pub format: String,
    /// The scene exported, and the study whose meshes and steps were used, if any.
    pub scene: String,
    pub study: Option<String>,
    pub description: String,
    pub model: String,
    pub levels: Vec<usize>,
    pub syntax: String,
    pub time: Time,
    pub bodies: Vec<Body>,
    pub supports: Vec<Support>,
    pub tractions: Vec<TractionLoad>,
    pub contact: Contact,
    pub exact: ExactFields,
}

/// The time grid.
#[derive(Serialize)]
pub struct Time {
    pub final_time: f64,
    pub steps: usize,
    /// t_1 .. t_N (t_0 = 0 is the unloaded initial state, u = 0, sigma = 0).
    pub times: Vec<f64>,
    pub scheme: String,
}

/// One body's material and load.
#[derive(Serialize)]
pub struct Body {
    /// 1 or 2: the cell array `body` and the physical surface tag of the meshes.
    pub number: usize,
    /// Its physical surface's name.
    pub surface: String,
    pub role: String,
    /// Young's modulus E (stress units).
    pub young: f64,
    /// Poisson's ratio nu.
    pub poisson: f64,
    /// "plane stress" or "plane strain" (the same for both bodies).
    pub plane: String,
    /// The first Lame-type constant of the 2D law: lambda* = E nu / (1 - nu^2) in plane
    /// stress, lambda = E nu / ((1 + nu) (1 - 2 nu)) in plane strain (stress units).
    pub lambda_star: f64,
    /// mu = E / (2 (1 + nu)) (stress units).
    pub mu: f64,
    pub elasticity: String,
    /// The body force per area (x, y), or none.
    pub body_force: Option<[String; 2]>,
    pub viscoplastic: Option<Viscoplastic>,
}

/// Perzyna's law, written out.
#[derive(Serialize)]
pub struct Viscoplastic {
    /// The viscosity lambda of the paper (stress x time).
    pub viscosity: f64,
    /// The uniaxial yield stress sigma_Y (stress units).
    pub yield_stress: f64,
    pub law: String,
    pub projection: String,
    pub time_discretization: String,
    /// The constitutive source s (stress per time), per component [s11, s22, s12], when the
    /// exact fields need one.
    pub source: Option<String>,
}

/// A Dirichlet boundary.
#[derive(Serialize)]
pub struct Support {
    pub curve: String,
    pub body: usize,
    pub kind: String,
    pub condition: String,
}

/// A Neumann boundary.
#[derive(Serialize)]
pub struct TractionLoad {
    pub curve: String,
    pub body: usize,
    /// The outward normal where it is the same along the curve.
    pub normal: Option<[f64; 2]>,
    /// The traction (force per length), x and y.
    pub traction: [String; 2],
}

/// Gamma_C.
#[derive(Serialize)]
pub struct Contact {
    pub slave_curve: String,
    pub master_curve: String,
    pub roles: String,
    pub condition: String,
    /// The initial gap g0(x, y) >= 0 along nu^1 (length), an expression evaluated on body
    /// 1's side of Gamma_C; none: the bodies touch where their curves do.
    pub gap: Option<String>,
    /// How the gap enters the condition, where there is one.
    pub gap_rule: Option<String>,
    pub pieces: Vec<ContactPiece>,
}

/// A straight piece of Gamma_C.
#[derive(Serialize)]
pub struct ContactPiece {
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// nu^1, body 1's outward normal (body 2's is -nu^1).
    pub slave_normal: [f64; 2],
}

/// The exact solution.
#[derive(Serialize)]
pub struct ExactFields {
    /// (u_x, u_y) of body 1 and of body 2.
    pub displacement: Option<[[String; 2]; 2]>,
    /// (s11, s22, s12) of body 1 and of body 2.
    pub stress: Option<[[String; 3]; 2]>,
    /// The contact pressure on Gamma_C, positive in compression.
    pub pressure: Option<String>,
}

/// Where an exported problem's meshes come from.
pub struct Origin<'a> {
    pub scene: &'a Scene,
    pub study: Option<&'a str>,
    pub levels: &'a [usize],
    pub steps: usize,
}

fn role(b: usize) -> String {
    match b {
        0 => "slave (body 1): carries the rows of the discrete contact condition K_h (the side whose nodes are constrained; GetFEM: the slave region of a mortar or nodal contact brick; MOOSE: the secondary boundary)".into(),
        _ => "master (body 2): the side its normal displacement is interpolated or projected from (GetFEM: master; MOOSE: primary)".into(),
    }
}

/// An expression as the scene wrote it, or a derived one (a derivative: its text for
/// messages reads `d/dx (...)`, which no scene expression can contain) in the same syntax.
fn text(e: &Expr) -> String {
    if e.text.contains("d/d") {
        e.plain_text()
    } else {
        e.text.clone()
    }
}

/// problem.toml's contents for `model` (any level of the export: the physics is the same)
/// on `interface`, meshed as `mesh`.
pub fn problem_file(
    origin: &Origin,
    model: &Model,
    interface: &Interface,
    mesh: &ExportMesh,
) -> ProblemFile {
    let scene = origin.scene;
    let exact = scene.exact.as_deref();
    let final_time = scene.final_time;
    let times = (1..=origin.steps)
        .map(|n| final_time * n as f64 / origin.steps as f64)
        .collect();
    let bodies = (0..2).map(|b| body(scene, b)).collect();
    let body_of_curve = |curve: &str| mesh.body_of_curve(curve).map_or(0, |b| b + 1);
    let mut supports: Vec<Support> = scene
        .clamps
        .iter()
        .map(|c| Support {
            curve: c.clone(),
            body: body_of_curve(c),
            kind: "clamp".into(),
            condition: "u = 0".into(),
        })
        .collect();
    for r in &scene.rollers {
        let (held, free) = if r.component == 0 {
            ("x", "y")
        } else {
            ("y", "x")
        };
        supports.push(Support {
            curve: r.curve.clone(),
            body: body_of_curve(&r.curve),
            kind: format!("roller {held}"),
            condition: format!("u_{held} = 0; u_{free} free, with zero traction in {free}"),
        });
    }
    let tractions = scene
        .tractions
        .iter()
        .enumerate()
        .map(|(i, tr)| traction(model, i, tr, body_of_curve(&tr.curve)))
        .collect();
    let exact_fields = ExactFields {
        displacement: exact
            .and_then(|e| e.displacement.as_ref())
            .map(|u| u.each_ref().map(|ub| ub.each_ref().map(|c| c.text.clone()))),
        stress: exact
            .and_then(|e| e.stress.as_ref())
            .map(|s| s.each_ref().map(|sb| sb.each_ref().map(text))),
        pressure: exact
            .and_then(|e| e.pressure.as_ref())
            .map(|p| p.text.clone()),
    };
    ProblemFile {
        format: "contact-rates problem, version 1".into(),
        scene: scene.name.clone(),
        study: origin.study.map(str::to_string),
        description: scene.description.clone(),
        model: format!("2D, small strain, {}, frictionless unilateral contact between two bodies, quasistatic; units are the scene's (consistent: length, force, time)", scene.bodies[0].material.elastic.plane.label()),
        levels: origin.levels.to_vec(),
        syntax: SYNTAX.into(),
        time: Time {
            final_time,
            steps: origin.steps,
            times,
            scheme: "t_n = n T / N, n = 1..N, from u = 0, sigma = 0 at t_0 = 0; every load is taken at t_n; an elastic body's problem at t_n depends on t_n only, a viscoplastic body's on the previous step by backward Euler (bodies.viscoplastic)".into(),
        },
        bodies,
        supports,
        tractions,
        contact: Contact {
            slave_curve: scene.slave_curve.clone(),
            master_curve: scene.master_curve.clone(),
            roles: "the slave curve is body 1's side of Gamma_C, the master curve body 2's; they coincide geometrically but are meshed independently (the nodes do not match)".into(),
            condition: "frictionless unilateral contact: with nu = nu^1 and [u.nu] = u^1.nu^1 + u^2.nu^2 (positive where the bodies would interpenetrate), [u.nu] <= g0, p >= 0, p ([u.nu] - g0) = 0 on Gamma_C, where g0 is the initial gap (contact.gap; 0 where none is given) and p = -sigma_nn >= 0 is the contact pressure (a traction -p nu^1 on body 1 and -p nu^2 on body 2), and zero tangential traction on both sides".into(),
            gap: scene.initial_gap.as_ref().map(|g| g.text.clone()),
            gap_rule: scene.initial_gap.as_ref().map(|_| "the bodies are meshed touching (the slave and master curves coincide) and g0 is the distance between them along nu^1 before any load: a point x of body 1's curve meets body 2 where [u.nu](x) = g0(x). A code that takes a gap per constraint uses its own discretization of g0: at the slave nodes for node-on-segment rows (this project's nts), the integral of g0 against each row's test function for mortar rows (mortar: the weighted gap; lac: the mean of g0 over a macro-element). A code that takes geometry only poses it by moving body 2 down by g0 along nu^1 (its contact curve y = g0(x) below body 1's for a flat Gamma_C), with the supports and loads of body 2 unchanged: that is a different mesh, and its measured gap is then its own trace's".into()),
            pieces: interface
                .pieces
                .iter()
                .map(|p| ContactPiece {
                    from: p.a,
                    to: p.point(p.length),
                    // + 0.0 writes -0 as 0.
                    slave_normal: p.normal.map(|v| v + 0.0),
                })
                .collect(),
        },
        exact: exact_fields,
    }
}

fn body(scene: &Scene, b: usize) -> Body {
    let body = &scene.bodies[b];
    let m = &body.material;
    let (young, poisson) = (m.elastic.young, m.elastic.poisson);
    Body {
        number: b + 1,
        surface: body.surface.clone(),
        role: role(b),
        young,
        poisson,
        lambda_star: m.elastic.a(),
        mu: 0.5 * m.elastic.b(),
        plane: m.elastic.plane.label().into(),
        elasticity: format!("sigma = E eps(u) = lambda_star tr(eps) I + 2 mu eps ({}{}), eps(u) = (grad u + grad u^T) / 2", m.elastic.plane.label(), match m.elastic.plane {
            crate::material::Plane::Stress => ": sigma_33 = 0",
            crate::material::Plane::Strain => ": eps_33 = 0, sigma_33 = nu (sigma_11 + sigma_22), lambda_star = Lame's lambda",
        }),
        body_force: body
            .body_force
            .as_ref()
            .map(|f| f.0.each_ref().map(text)),
        viscoplastic: m.viscoplastic.map(|vp| Viscoplastic {
            viscosity: vp.lambda,
            yield_stress: vp.yield_stress,
            law: "Perzyna: d sigma/dt = E eps(du/dt) + G(sigma) + s, G(sigma) = -(1 / (2 viscosity)) E (sigma - P sigma), s the constitutive source below (zero where none is given)".into(),
            projection: "P sigma is the projection of sigma onto B = {tau : |tau|_VM <= yield_stress}, |tau|_VM = sqrt(t11^2 + t22^2 - t11 t22 + 3 t12^2), in the inner product (E^-1 sigma, tau) (the energy norm of the compliance): the closest point of B to sigma in that norm".into(),
            time_discretization: "backward Euler on each triangle: sigma_n = sigma_(n-1) + E (eps(u_n) - eps(u_(n-1))) + k G(sigma_n) + k s_n, with k = t_n - t_(n-1) and s_n the mean of the source s(t_n) over the triangle (source_L.csv); the stress is constant per triangle (P0)".into(),
            source: scene
                .exact
                .as_deref()
                .and_then(|e| e.source_rate.as_ref())
                .map(|_| "s = d sigma/dt - E eps(du/dt) - G(sigma) of the exact fields (exact.stress and exact.displacement), per triangle as its mean at t_n: source_L.csv".into()),
        }),
    }
}

/// The scene's `traction[i]` on `body` (1 or 2): its expressions, or those of sigma n of
/// the exact stress.
fn traction(model: &Model, i: usize, tr: &crate::scene::Traction, body: usize) -> TractionLoad {
    let edges: Vec<usize> = model
        .traction_edges
        .iter()
        .enumerate()
        .filter(|(_, (j, _))| *j == i)
        .map(|(e, _)| e)
        .collect();
    let normals: Vec<(usize, [f64; 2])> = edges
        .iter()
        .filter_map(|&e| model.traction_normals.get(e).copied())
        .collect();
    let normal = normals.first().map(|n| n.1.map(|v| v + 0.0)).filter(|n0| {
        normals
            .iter()
            .all(|(_, n)| (n[0] - n0[0]).abs() + (n[1] - n0[1]).abs() < 1e-12)
    });
    let traction = match (
        &tr.g,
        model.scene.exact.as_deref().and_then(|e| e.stress.as_ref()),
    ) {
        (Some(g), _) => g.0.each_ref().map(|c| c.text.clone()),
        (None, Some(stress)) => {
            let s = &stress[body.max(1) - 1];
            match normal {
                // sigma n on a straight curve: a combination of the stress's expressions.
                Some(n) => [
                    Expr::combine(&[(n[0], &s[0]), (n[1], &s[2])]).plain_text(),
                    Expr::combine(&[(n[0], &s[2]), (n[1], &s[1])]).plain_text(),
                ],
                None => [
                    "sigma n of exact.stress, n the outward normal of each edge".into(),
                    "(see x)".into(),
                ],
            }
        }
        (None, None) => ["0".into(), "0".into()],
    };
    TractionLoad {
        curve: tr.curve.clone(),
        body,
        normal,
        traction,
    }
}

/// A Python string literal (TOML's basic strings and Python's agree on `"` and `\` escapes
/// for the characters expressions use).
fn py(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

fn py_pair(v: &[String; 2]) -> String {
    format!("(parse({}), parse({}))", py(&v[0]), py(&v[1]))
}

fn py_float(v: f64) -> String {
    format!("{v:e}")
}

/// problem.py: the expressions of `problem` as sympy expressions and callables, and a check
/// of every derived field against sympy's own derivatives of the given ones, at `samples`
/// (points inside each body) and on Gamma_C. `derived_stress[b]`: whether body b's stress
/// is E eps(u) (derived) rather than given.
pub fn problem_py(
    problem: &ProblemFile,
    samples: &[Vec<[f64; 2]>; 2],
    derived_stress: [bool; 2],
) -> String {
    let mut out = String::new();
    py_preamble(&mut out, problem);
    py_fields(&mut out, problem);
    py_boundary_and_check(&mut out, problem, samples, derived_stress);
    out
}

/// problem.py's docstring, imports and parsing helpers; the times and each body's
/// constants.
fn py_preamble(out: &mut String, problem: &ProblemFile) {
    let mut line = |s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    line("#!/usr/bin/env python3".into());
    line(format!(
        "\"\"\"The exact fields and loads of problem.toml (scene {}) as sympy expressions and callables.\n",
        problem.scene
    ));
    line("    pip install sympy".into());
    line("    import problem".into());
    line(
        "    u_x = problem.displacement[1][0]     # body 1's u_x: a sympy expression in x, y, t"
            .into(),
    );
    line("    problem.f(u_x)(0.5, 1.5, 1.0)        # its value at x = 0.5, y = 1.5, t = 1".into());
    line("    python3 problem.py                   # checks every derived field against sympy's derivatives".into());
    line("".into());
    line("Generated by `contact-rates export`; do not edit (regenerate instead).\n\"\"\"".into());
    line("import sympy as sp\n".into());
    line("x, y, t = sp.symbols(\"x y t\", real=True)\n".into());
    line("\ndef _signum(z):\n    \"\"\"-1 for z < 0, +1 for z >= 0 (the branch of an abs).\"\"\"\n    return sp.Piecewise((-1, z < 0), (1, True))\n".into());
    line("\n_NAMES = {\"x\": x, \"y\": y, \"t\": t, \"pi\": sp.pi, \"abs\": sp.Abs, \"signum\": _signum, \"log\": sp.log}\n".into());
    line("\ndef parse(text):\n    \"\"\"An expression in problem.toml's syntax as a sympy expression (^ is power).\"\"\"\n    return sp.sympify(text.replace(\"^\", \"**\"), locals=_NAMES)\n".into());
    line("\ndef f(expr):\n    \"\"\"A callable (x, y, t) -> float of a sympy expression.\"\"\"\n    return sp.lambdify((x, y, t), expr, modules=\"math\")\n".into());
    line(format!(
        "\ntimes = [{}]",
        problem
            .time
            .times
            .iter()
            .map(|v| py_float(*v))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    line("# Per body (1, 2): the 2D law's constants (problem.toml bodies.plane), whether the body is elastic.".into());
    line("bodies = {".into());
    for b in &problem.bodies {
        line(format!(
            "    {}: {{\"surface\": {}, \"lambda_star\": {}, \"mu\": {}, \"elastic\": {}}},",
            b.number,
            py(&b.surface),
            py_float(b.lambda_star),
            py_float(b.mu),
            if b.viscoplastic.is_none() {
                "True"
            } else {
                "False"
            }
        ));
    }
    line("}".into());
}

/// problem.py's exact fields (displacement, stress, pressure) and body forces.
fn py_fields(out: &mut String, problem: &ProblemFile) {
    let mut line = |s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    match &problem.exact.displacement {
        Some(u) => line(format!(
            "displacement = {{1: {}, 2: {}}}",
            py_pair(&u[0]),
            py_pair(&u[1])
        )),
        None => line("displacement = None".into()),
    }
    match &problem.exact.stress {
        Some(s) => line(format!(
            "stress = {{1: (parse({}), parse({}), parse({})), 2: (parse({}), parse({}), parse({}))}}",
            py(&s[0][0]),
            py(&s[0][1]),
            py(&s[0][2]),
            py(&s[1][0]),
            py(&s[1][1]),
            py(&s[1][2])
        )),
        None => line("stress = None".into()),
    }
    match &problem.contact.gap {
        Some(g) => line(format!(
            "# The initial gap g0(x, y) along nu^1 on Gamma_C (problem.toml contact.gap_rule).\ngap = parse({})",
            py(g)
        )),
        None => line("gap = None".into()),
    }
    match &problem.exact.pressure {
        Some(p) => line(format!("pressure = parse({})", py(p))),
        None => line("pressure = None".into()),
    }
    line("body_force = {".into());
    for b in &problem.bodies {
        match &b.body_force {
            Some(f) => line(format!("    {}: {},", b.number, py_pair(f))),
            None => line(format!("    {}: None,", b.number)),
        }
    }
    line("}".into());
}

/// problem.py's tractions, the pieces of Gamma_C, which stresses are derived, the sample
/// points and the check itself.
fn py_boundary_and_check(
    out: &mut String,
    problem: &ProblemFile,
    samples: &[Vec<[f64; 2]>; 2],
    derived_stress: [bool; 2],
) {
    let mut line = |s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    line(
        "# Per traction curve: its body, its outward normal (None where it varies), (g_x, g_y)."
            .into(),
    );
    line("traction = {".into());
    for tr in &problem.tractions {
        let normal = tr.normal.map_or("None".into(), |n| {
            format!("({}, {})", py_float(n[0]), py_float(n[1]))
        });
        line(format!(
            "    {}: {{\"body\": {}, \"normal\": {normal}, \"g\": {}}},",
            py(&tr.curve),
            tr.body,
            py_pair(&tr.traction)
        ));
    }
    line("}".into());
    line("# The straight pieces of Gamma_C: (from, to, nu^1 the outward normal of body 1).".into());
    line("contact_pieces = [".into());
    for p in &problem.contact.pieces {
        line(format!(
            "    (({}, {}), ({}, {}), ({}, {})),",
            py_float(p.from[0]),
            py_float(p.from[1]),
            py_float(p.to[0]),
            py_float(p.to[1]),
            py_float(p.slave_normal[0]),
            py_float(p.slave_normal[1])
        ));
    }
    line("]".into());
    line(format!(
        "# Whether each body's stress is E eps(u) (derived from the displacement) rather than given.\n_derived_stress = {{1: {}, 2: {}}}",
        if derived_stress[0] { "True" } else { "False" },
        if derived_stress[1] { "True" } else { "False" }
    ));
    line("# Points inside each body where check() compares.".into());
    line("_samples = {".into());
    for (b, pts) in samples.iter().enumerate() {
        let list: Vec<String> = pts
            .iter()
            .map(|p| format!("({}, {})", py_float(p[0]), py_float(p[1])))
            .collect();
        line(format!("    {}: [{}],", b + 1, list.join(", ")));
    }
    line("}".into());
    line(CHECK_PY.into());
}

/// problem.py's check: sympy derives from the given fields what the file gives as derived.
const CHECK_PY: &str = r#"

def _compare(what, got, want, points, tolerance):
    """Count the points where got and want (expressions) agree to tolerance relative to
    max(1, |want|); raise on the first that does not."""
    g, w = f(got), f(want)
    for (px, py_) in points:
        for tn in times:
            a, b = g(px, py_, tn), w(px, py_, tn)
            if abs(a - b) > tolerance * max(1.0, abs(b)):
                raise AssertionError(f"{what} at x = {px}, y = {py_}, t = {tn}: {a} given, {b} derived by sympy")
    return len(points) * len(times)


def check(tolerance=1e-9):
    """Compare every derived field with sympy's derivatives of the given ones: the elastic
    stress E eps(u), the body force -div sigma, each traction sigma n, and on Gamma_C the
    pressure with -sigma_nn of both bodies. Returns the number of comparisons."""
    done = 0
    gamma = [(a[0] + s / 10 * (b[0] - a[0]), a[1] + s / 10 * (b[1] - a[1]), n)
             for a, b, n in contact_pieces for s in range(11)]
    for body in (1, 2):
        pts = _samples[body]
        s = stress[body] if stress else None
        if displacement and s is not None and _derived_stress[body]:
            u = displacement[body]
            lam, mu = bodies[body]["lambda_star"], bodies[body]["mu"]
            e11, e22 = sp.diff(u[0], x), sp.diff(u[1], y)
            e12 = (sp.diff(u[0], y) + sp.diff(u[1], x)) / 2
            want = (lam * (e11 + e22) + 2 * mu * e11, lam * (e11 + e22) + 2 * mu * e22, 2 * mu * e12)
            for c in range(3):
                done += _compare(f"stress[{body}][{c}]", s[c], want[c], pts, tolerance)
        if s is not None and body_force[body] is not None:
            want = (-(sp.diff(s[0], x) + sp.diff(s[2], y)), -(sp.diff(s[2], x) + sp.diff(s[1], y)))
            for c in range(2):
                done += _compare(f"body_force[{body}][{c}]", body_force[body][c], want[c], pts, tolerance)
        if s is not None and pressure is not None:
            for (px, py_, n) in gamma:
                # nu^1 for body 1, nu^2 = -nu^1 for body 2: sigma_nn is the same.
                snn = s[0] * n[0] ** 2 + 2 * s[2] * n[0] * n[1] + s[1] * n[1] ** 2
                done += _compare(f"pressure (body {body}: -sigma_nn)", pressure, -snn, [(px, py_)], tolerance)
    for name, tr in traction.items():
        if stress and tr["normal"] is not None:
            s, (nx, ny) = stress[tr["body"]], tr["normal"]
            want = (s[0] * nx + s[2] * ny, s[2] * nx + s[1] * ny)
            for c in range(2):
                done += _compare(f"traction[{name}][{c}]", tr["g"][c], want[c], _samples[tr["body"]], tolerance)
    return done


if __name__ == "__main__":
    print(f"problem.py: {check()} comparisons of derived fields with sympy's derivatives agree to 1e-9")
"#;
