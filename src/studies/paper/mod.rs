//! Reproduction of the paper's three numerical tests (section 5): every figure regenerated
//! and every claim the paper makes there checked by a number.

pub mod report;
pub mod results;

use crate::verify::kind::{Found, Kind};

/// The kind: one built-in study, `study paper`.
pub const KIND: Kind = Kind {
    name: "paper",
    description: DESCRIPTION,
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run()?))),
    rejudge: None,
    results: Some(results::section),
};


use crate::case::Case;
use crate::contact::Method;
use crate::error::Result;
use crate::material::von_mises;
use crate::metrics;
use crate::scene::Scene;
use crate::solve::{Solution, SolverKind};
use crate::verify::{solve_case, theorem_distance};
use nalgebra::Vector3;

/// One line for `study list`.
pub const DESCRIPTION: &str =
    "The paper's three numerical tests (section 5): figures and the numbers behind its words";

/// Geometry and fields of one solved case, for figures.
#[derive(Debug, Clone)]
pub struct MeshData {
    /// Node coordinates (undeformed).
    pub nodes: Vec<[f64; 2]>,
    /// Nodal displacements at T.
    pub u: Vec<[f64; 2]>,
    /// Triangles (global node indices).
    pub triangles: Vec<[usize; 3]>,
    /// Body (1 or 2) per triangle.
    pub body: Vec<u8>,
    /// Von Mises stress per triangle at T.
    pub von_mises: Vec<f64>,
    /// sigma_22 per triangle at T.
    pub s22: Vec<f64>,
    /// Interface nodes of body 1 and body 2 (global indices).
    pub interface_nodes: [Vec<usize>; 2],
    /// Contact-line segments (node pairs of body 1).
    pub contact: Vec<[usize; 2]>,
}

/// One solved case of a test.
#[derive(Debug, Clone)]
pub struct Run {
    /// Label ("mortar", "nts", "mortar, matching").
    pub label: String,
    /// Level.
    pub level: usize,
    /// Free dofs.
    pub dofs: usize,
    /// Triangles per body.
    pub triangles: [usize; 2],
    /// Nodes per body.
    pub nodes: [usize; 2],
    /// Time steps.
    pub steps: usize,
    /// Iterations in total and max per step.
    pub iterations: (usize, usize),
    /// Wall time of the solve (s).
    pub wall_s: f64,
    /// Largest interpenetration over the history (length).
    pub max_penetration: f64,
    /// Contact fraction at T.
    pub contact_fraction: f64,
    /// Plastic fraction at T.
    pub plastic_fraction: f64,
    /// Contact pressure at T along Gamma_C: (arclength, pressure).
    pub pressure: Vec<(f64, f64)>,
    /// Mesh and fields.
    pub mesh: MeshData,
}

/// Numbers behind the paper's words in Test 2.
#[derive(Debug, Clone, Copy)]
pub struct Test2Numbers {
    /// Mortar: max over triangles and steps of |sigma - diag(0, -10 t)| / (10 t).
    pub mortar_stress_error: f64,
    /// Mortar: max |sigma_11|, |sigma_12| at T.
    pub mortar_s11_s12: (f64, f64),
    /// Mortar: sigma_22 range at T (min, max).
    pub mortar_s22: (f64, f64),
    /// Mortar: largest interpenetration relative to max |u|.
    pub mortar_penetration: f64,
    /// Nts: largest interpenetration (absolute and relative to max |u|).
    pub nts_penetration: (f64, f64),
    /// Nts: largest spurious stress |sigma - exact| / 10 at T, and where (x, y).
    pub nts_stress_error: (f64, [f64; 2]),
}

/// Everything `study paper` measured.
#[derive(Debug, Clone)]
pub struct PaperResult {
    /// Test 1 runs (mortar, nts).
    pub test1: Vec<Run>,
    /// Test 2 runs (mortar, nts).
    pub test2: Vec<Run>,
    /// Test 2 numbers.
    pub test2_numbers: Test2Numbers,
    /// Test 3 runs (mortar non-matching, nts non-matching, mortar matching).
    pub test3: Vec<Run>,
    /// Test 3 agreement: (level, h, relative theorem-norm difference non-matching vs matching).
    pub test3_agreement: Vec<(usize, f64, f64)>,
    /// Total wall time (s).
    pub wall_s: f64,
}

fn describe(label: &str, case: &Case, sol: &Solution, wall: f64) -> Run {
    let p = &case.problem;
    let m = &p.model;
    let last = sol.last();
    let mut pressure = Vec::new();
    let mut offset = 0.0;
    for (pi, piece) in p.interface.pieces.iter().enumerate() {
        for (row, l) in p
            .rows
            .iter()
            .zip(&last.lambda)
            .filter(|(r, _)| r.piece == pi)
        {
            for at in row.pressure_at(piece) {
                pressure.push((offset + at, row.pressure(*l)));
            }
        }
        offset += piece.length;
    }
    let mut contact = Vec::new();
    let mut inodes = [Vec::new(), Vec::new()];
    for piece in &p.interface.pieces {
        inodes[0].extend_from_slice(&piece.slave_nodes);
        inodes[1].extend_from_slice(&piece.master_nodes);
        for w in piece.slave_nodes.windows(2) {
            contact.push([w[0], w[1]]);
        }
    }
    Run {
        label: label.into(),
        level: case.level,
        dofs: m.n_free,
        triangles: [m.meshes[0].triangles.len(), m.meshes[1].triangles.len()],
        nodes: [m.meshes[0].nodes.len(), m.meshes[1].nodes.len()],
        steps: sol.reports.len(),
        iterations: (sol.iterations(), sol.max_step_iterations()),
        wall_s: wall,
        max_penetration: sol
            .states
            .iter()
            .map(|s| metrics::max_penetration(p, s))
            .fold(0.0, f64::max),
        contact_fraction: metrics::contact_fraction(p, last),
        plastic_fraction: metrics::plastic_fraction(p, last),
        pressure,
        mesh: MeshData {
            nodes: (0..m.n_nodes).map(|g| m.position(g)).collect(),
            u: (0..m.n_nodes)
                .map(|g| [last.u[2 * g], last.u[2 * g + 1]])
                .collect(),
            triangles: m.elements.iter().map(|e| e.nodes).collect(),
            body: m.elements.iter().map(|e| e.body as u8 + 1).collect(),
            von_mises: last.sigma.iter().map(von_mises).collect(),
            s22: last.sigma.iter().map(|s| s[1]).collect(),
            interface_nodes: inodes,
            contact,
        },
    }
}

fn solve(
    scene: &Scene,
    method: Method,
    level: usize,
    params: &[(String, f64)],
) -> Result<(Case, Solution, f64)> {
    let case = Case::build(scene, level, method, params)?;
    let (sol, wall) = solve_case(&case, SolverKind::Newton, scene.steps)?;
    Ok((case, sol, wall))
}

/// Test 2's numbers from its two solved cases.
pub fn test2_numbers(mortar: (&Case, &Solution), nts: (&Case, &Solution)) -> Test2Numbers {
    let exact = |t: f64| Vector3::new(0.0, -10.0 * t, 0.0);
    let umax = |s: &Solution| {
        s.states
            .iter()
            .map(|st| crate::solve::inf_norm(&st.u))
            .fold(0.0, f64::max)
    };
    let (mc, ms) = mortar;
    let mortar_stress_error = ms
        .states
        .iter()
        .skip(1)
        .map(|st| {
            st.sigma
                .iter()
                .map(|s| (s - exact(st.time)).amax() / (10.0 * st.time))
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let last = ms.last();
    let s11 = last.sigma.iter().map(|s| s[0].abs()).fold(0.0, f64::max);
    let s12 = last.sigma.iter().map(|s| s[2].abs()).fold(0.0, f64::max);
    let s22 = (
        last.sigma
            .iter()
            .map(|s| s[1])
            .fold(f64::INFINITY, f64::min),
        last.sigma
            .iter()
            .map(|s| s[1])
            .fold(f64::NEG_INFINITY, f64::max),
    );
    let mpen = ms
        .states
        .iter()
        .map(|s| metrics::max_penetration(&mc.problem, s))
        .fold(0.0, f64::max)
        / umax(ms);
    let (nc, ns) = nts;
    let npen = ns
        .states
        .iter()
        .map(|s| metrics::max_penetration(&nc.problem, s))
        .fold(0.0, f64::max);
    let nl = ns.last();
    let (mut worst, mut at) = (0.0, [0.0; 2]);
    for (e, s) in nc.problem.model.elements.iter().zip(&nl.sigma) {
        let d = (s - exact(nl.time)).amax() / 10.0;
        if d > worst {
            worst = d;
            let p = e.nodes.map(|n| nc.problem.model.position(n));
            at = [
                (p[0][0] + p[1][0] + p[2][0]) / 3.0,
                (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            ];
        }
    }
    Test2Numbers {
        mortar_stress_error,
        mortar_s11_s12: (s11, s12),
        mortar_s22: s22,
        mortar_penetration: mpen,
        nts_penetration: (npen, npen / umax(ns)),
        nts_stress_error: (worst, at),
    }
}

/// Run the three tests.
pub fn run() -> Result<PaperResult> {
    let t0 = std::time::Instant::now();
    // Test 1: straight contact line.
    let s1 = Scene::load("paper-1")?;
    let mut test1 = Vec::new();
    for m in [Method::Mortar, Method::Nts] {
        let (c, s, w) = solve(&s1, m, 0, &[])?;
        test1.push(describe(m.name(), &c, &s, w));
    }
    // Test 2: the patch test, E = 3e5.
    let s2 = Scene::load("patch")?;
    let (mc, ms, mw) = solve(&s2, Method::Mortar, 0, &[])?;
    let (nc, ns, nw) = solve(&s2, Method::Nts, 0, &[])?;
    let test2_numbers = test2_numbers((&mc, &ms), (&nc, &ns));
    let test2 = vec![
        describe("mortar", &mc, &ms, mw),
        describe("nts", &nc, &ns, nw),
    ];
    // Test 3: piecewise-straight contact line, non-matching against matching meshes.
    let s3 = Scene::load("paper-3")?;
    let matching = vec![("matching".to_string(), 1.0)];
    let mut test3 = Vec::new();
    let mut test3_agreement = Vec::new();
    for level in 0..3 {
        let (c, s, w) = solve(&s3, Method::Mortar, level, &[])?;
        let (cm, sm, wm) = solve(&s3, Method::Mortar, level, &matching)?;
        test3_agreement.push((level, c.h, theorem_distance(&c, &s, &cm, &sm)));
        if level == 0 {
            let (cn, sn, wn) = solve(&s3, Method::Nts, level, &[])?;
            test3.push(describe("mortar, non-matching", &c, &s, w));
            test3.push(describe("nts, non-matching", &cn, &sn, wn));
            test3.push(describe("mortar, matching", &cm, &sm, wm));
        }
    }
    Ok(PaperResult {
        test1,
        test2,
        test2_numbers,
        test3,
        test3_agreement,
        wall_s: t0.elapsed().as_secs_f64(),
    })
}
