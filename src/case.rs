//! A case: one scene on one mesh level with one cone, built from files through gmsh.

use crate::analytical::Exact;
use crate::contact::{Interface, Method};
use crate::error::{Error, Result};
use crate::fe::Model;
use crate::mesh::{gmsh, msh};
use crate::scene::{Refinement, Scene};
use crate::solve::{Problem, Solution, SolverKind, Timings};
use std::time::Instant;

/// A built case with its provenance and set-up costs.
#[derive(Debug, Clone)]
pub struct Case {
    /// The discrete problem.
    pub problem: Problem,
    /// Refinement level (0 = gmsh's own mesh).
    pub level: usize,
    /// The judge's h ([`Model::judge_h`]): the largest element diameter over both bodies on
    /// split levels, the effective size on remeshed ones (length).
    pub h: f64,
    /// gmsh and .geo provenance.
    pub mesh: gmsh::GeneratedMesh,
    /// Seconds to generate (or fetch) and read the mesh.
    pub mesh_s: f64,
    /// Seconds to build the model, interface and constraint rows.
    pub setup_s: f64,
    /// Warnings about the scene (e.g. a body free to move), for the user.
    pub warnings: Vec<String>,
}

/// Warnings for bodies that neither a support nor the contact holds: for each displacement
/// component a body's clamps and rollers leave free, the net load at T must press the body
/// against Gamma_C (contact pushes body b along -nu^b) or the body can move freely.
pub fn support_warnings(
    model: &Model,
    interface: &Interface,
    raw: &crate::mesh::RawMesh,
) -> Result<Vec<String>> {
    let sc = &model.scene;
    // The load only where a component is free (a clamped pair of bodies pays nothing).
    let mut f: Option<Vec<f64>> = None;
    let mut out = Vec::new();
    for b in 0..2 {
        let mesh = &model.meshes[b];
        let mut held = [false; 2];
        for c in &sc.clamps {
            if !mesh.curve_edges(raw, c).is_empty() {
                held = [true, true];
            }
        }
        for r in &sc.rollers {
            if !mesh.curve_edges(raw, &r.curve).is_empty() {
                held[r.component] = true;
            }
        }
        if held == [true, true] {
            continue;
        }
        if f.is_none() {
            f = Some(model.load(sc.final_time)?);
        }
        let f = f.as_deref().expect("computed above");
        let range = model.node_offset[b]..model.node_offset[b] + mesh.nodes.len();
        let load = [0, 1].map(|c| range.clone().map(|n| f[2 * n + c]).sum::<f64>());
        let scale = load[0].abs().max(load[1].abs()).max(f64::MIN_POSITIVE);
        for c in 0..2 {
            if held[c] {
                continue;
            }
            let pressed = interface.pieces.iter().any(|p| {
                let nu = if b == 0 { p.normal[c] } else { -p.normal[c] };
                nu * load[c] > 1e-9 * scale
            });
            if !pressed {
                out.push(format!(
                    "{}: body '{}' has no clamp or roller holding u_{} and its net load at T ({:.3e}) does not press it against Gamma_C in that direction: it is free to move; add a roller or a clamp",
                    sc.file.display(),
                    sc.bodies[b].surface,
                    ["x", "y"][c],
                    load[c]
                ));
            }
        }
    }
    Ok(out)
}

/// The scene's gmsh parameters overridden by `params`, checked against the .geo.
fn checked_parameters(scene: &Scene, params: &[(String, f64)]) -> Result<Vec<(String, f64)>> {
    let mut all: Vec<(String, f64)> = scene
        .parameters
        .iter()
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    for (k, v) in params {
        match all.iter_mut().find(|(kk, _)| kk == k) {
            Some(e) => e.1 = *v,
            None => all.push((k.clone(), *v)),
        }
    }
    check_parameters(scene, &all)?;
    Ok(all)
}

impl Case {
    /// Mesh `scene` at `level` (gmsh parameters from the scene, overridden by `params`),
    /// and build the problem for `method`.
    pub fn build(
        scene: &Scene,
        level: usize,
        method: Method,
        params: &[(String, f64)],
    ) -> Result<Self> {
        let t0 = Instant::now();
        let all = checked_parameters(scene, params)?;
        if level > 0 {
            check_memory(scene, &all, level)?;
        }
        let (generated, raw) = mesh_healed(scene, &all, level, &gmsh::cache_dir())?;
        Self::from_mesh(scene, level, method, generated, raw, t0)
    }

    /// [`Case::build`] with the two bodies refined independently: body 1 (the slave) at
    /// `levels[0]`, body 2 at `levels[1]`, both from the same gmsh family (level 0 meshed
    /// with the scene's parameters overridden by `params`, then split). Where the levels are
    /// equal the mesh is [`Case::build`]'s at that level. `level` of the case is the larger.
    pub fn build_sizes(
        scene: &Scene,
        levels: [usize; 2],
        method: Method,
        params: &[(String, f64)],
    ) -> Result<Self> {
        if levels[0] == levels[1] {
            return Self::build(scene, levels[0], method, params);
        }
        let t0 = Instant::now();
        let all = checked_parameters(scene, params)?;
        let top = levels[0].max(levels[1]);
        if top > 0 {
            check_memory(scene, &all, top)?;
        }
        let (g0, r0) = mesh_healed(scene, &all, levels[0], &gmsh::cache_dir())?;
        let (g1, r1) = mesh_healed(scene, &all, levels[1], &gmsh::cache_dir())?;
        let raw = msh::RawMesh::combine_bodies(
            &r0,
            &r1,
            [&scene.bodies[0].surface, &scene.bodies[1].surface],
        );
        let generated = if levels[0] >= levels[1] { g0 } else { g1 };
        Self::from_mesh(scene, top, method, generated, raw, t0)
    }

    /// The level-`level` mesh of `scene` (gmsh parameters from the scene, overridden by
    /// `params`), generated or fetched from the cache, and read: what [`Case::build`] meshes,
    /// without its memory check. Errors name the scene file.
    pub fn mesh(
        scene: &Scene,
        level: usize,
        params: &[(String, f64)],
    ) -> Result<(gmsh::GeneratedMesh, msh::RawMesh)> {
        mesh_healed(
            scene,
            &checked_parameters(scene, params)?,
            level,
            &gmsh::cache_dir(),
        )
    }

    /// The case of `scene` on a mesh [`Case::mesh`] gave, at `level`, for `method`: every
    /// check of the scene against its mesh, its exact solution and the problem's set-up.
    pub fn on_mesh(
        scene: &Scene,
        level: usize,
        method: Method,
        generated: gmsh::GeneratedMesh,
        raw: msh::RawMesh,
    ) -> Result<Self> {
        Self::from_mesh(scene, level, method, generated, raw, Instant::now())
    }

    /// The case of `scene` on the read mesh `raw` (generated as `generated`, from `t0`).
    fn from_mesh(
        scene: &Scene,
        level: usize,
        method: Method,
        generated: gmsh::GeneratedMesh,
        raw: msh::RawMesh,
        t0: Instant,
    ) -> Result<Self> {
        let mesh_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let model = Model::new(scene, &raw, &generated.path)?;
        let interface = Interface::new(&model, &raw)?;
        let h = model.judge_h();
        let warnings = support_warnings(&model, &interface, &raw)?;
        verify_exact(&model, &interface, &raw)?;
        let problem = Problem::new(model, interface, method);
        Ok(Case {
            problem,
            level,
            h,
            mesh: generated,
            mesh_s,
            setup_s: t1.elapsed().as_secs_f64(),
            warnings,
        })
    }
}

/// Refuse gmsh parameters that cannot make a mesh, before meshing: every value must be
/// finite, and a size (a parameter named h...) positive.
fn check_parameters(scene: &Scene, params: &[(String, f64)]) -> Result<()> {
    for (name, value) in params {
        let field = format!("parameters.{name}");
        if !value.is_finite() {
            return Err(Error::input(
                &scene.file,
                field,
                format!(
                    "{name} = {value} is not a finite number; give a finite value (--set {name}=VALUE or the scene's [parameters])"
                ),
            ));
        }
        if name.starts_with('h') && *value <= 0.0 {
            return Err(Error::input(
                &scene.file,
                field,
                format!(
                    "{name} = {value} is a mesh size and must be positive; give a size > 0 (the scene's default is in its [parameters])"
                ),
            ));
        }
    }
    Ok(())
}

/// Peak resident memory of a solve per free dof (bytes): measured with newton (4 steps)
/// at 1.4e5-2.2e6 dofs, 2.6-3.4 KB (whole `solve` process at 5.5e5 dofs: 3.0 KB; `study
/// speed`'s solve peak at 2.2e6: 3.4 KB), rounded up for the mesh and the model.
pub const BYTES_PER_DOF: f64 = 4.0e3;

/// The machine's memory (bytes), from /proc/meminfo.
fn machine_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Refuse a level whose estimated memory exceeds the machine's, before refining to it
/// ([`memory_refusal`]), naming the scene file.
fn check_memory(scene: &Scene, params: &[(String, f64)], level: usize) -> Result<()> {
    match memory_refusal(scene, params, level)? {
        Some(message) => Err(Error::input(&scene.file, "level", message)),
        None => Ok(()),
    }
}

/// Why `level` of `scene` (with the checked gmsh parameters `params`) does not fit in this
/// machine's memory, or `None` where it fits (or the memory is unknown): the dofs of level 0
/// (meshed, or fetched from the cache) times 4 per level, times [`BYTES_PER_DOF`]. The text
/// gives the estimate and the largest level that fits. Nothing finer than level 0 is meshed.
pub fn memory_refusal(
    scene: &Scene,
    params: &[(String, f64)],
    level: usize,
) -> Result<Option<String>> {
    let Some(available) = machine_memory() else {
        return Ok(None);
    };
    if level == 0 {
        return Ok(None);
    }
    // A refusal leaves the mesh cache as it found it. Level 0, where it is not cached, is
    // meshed in a folder of its own and moved into the cache only where the level fits:
    // files that appear in the shared cache meanwhile are other runs' (a concurrent solve
    // refining the same family), never ours to remove.
    let cache = gmsh::cache_dir();
    let (geo_params, geo_level, split) = gmsh_call(scene, params, 0);
    let cached = gmsh::cache_path(&cache, &scene.geo, &geo_params, geo_level, split)?;
    let probe = if cached.exists() {
        None
    } else {
        std::fs::create_dir_all(&cache).map_err(|e| Error::io(&cache, e))?;
        let dir = tempfile::Builder::new()
            .prefix(".level-0-")
            .tempdir_in(&cache)
            .map_err(|e| Error::io(&cache, e))?;
        Some(dir)
    };
    let meshed_in = probe.as_ref().map_or(cache.as_path(), |d| d.path());
    let (generated, raw) = mesh_healed(scene, params, 0, meshed_in)?;
    let dofs = |l: usize| 2.0 * raw.nodes.len() as f64 * 4f64.powi(l as i32);
    let bytes = |l: usize| dofs(l) * BYTES_PER_DOF;
    if bytes(level) <= available {
        if probe.is_some() {
            // Another run may have put it there meanwhile: the same bytes, either is kept.
            let _ = std::fs::rename(&generated.path, &cached);
        }
        return Ok(None);
    }
    let gib = |b: f64| b / (1024.0 * 1024.0 * 1024.0);
    let fits = (0..level)
        .rev()
        .find(|&l| bytes(l) <= available)
        .unwrap_or(0);
    Ok(Some(format!(
        "level {level} needs about {:.1e} dofs and {:.0} GiB ({:.0} KB per dof, measured), more than this machine's {:.1} GiB; the largest level that fits is {fits} ({:.1e} dofs, {:.1} GiB)",
        dofs(level),
        gib(bytes(level)),
        BYTES_PER_DOF / 1e3,
        gib(available),
        dofs(fits),
        gib(bytes(fits)),
    )))
}

/// [`memory_refusal`] for `scene` with `params` overriding its gmsh parameters (checked).
pub fn memory_refusal_of(
    scene: &Scene,
    params: &[(String, f64)],
    level: usize,
) -> Result<Option<String>> {
    memory_refusal(scene, &checked_parameters(scene, params)?, level)
}

/// The mesh of `scene` at `level` and its contents. A cached file that does not parse (a
/// run killed while writing it, a disk that filled up) is deleted and regenerated, with a
/// one-line warning. Errors about the .geo or the mesh name the scene file and its field
/// `geo` (the .geo meshed with the scene's parameters).
fn mesh_healed(
    scene: &Scene,
    params: &[(String, f64)],
    level: usize,
    cache: &std::path::Path,
) -> Result<(gmsh::GeneratedMesh, msh::RawMesh)> {
    mesh_or_regenerated(scene, params, level, cache).map_err(|e| match e {
        Error::Input {
            file,
            field,
            message,
        } if file != scene.file => Error::input(
            &scene.file,
            "geo",
            format!(
                "{}: {field}: {message} (the .geo meshed with {})",
                file.display(),
                parameter_list(params)
            ),
        ),
        Error::Io { path, source } if path == scene.geo => Error::input(
            &scene.file,
            "geo",
            format!("{}: {source}; fix the path or the file", path.display()),
        ),
        other => other,
    })
}

/// `name = value, ...`, or "no parameters".
fn parameter_list(params: &[(String, f64)]) -> String {
    if params.is_empty() {
        return "no parameters".into();
    }
    params
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The gmsh parameters and the number of splits that give `scene`'s mesh at `level`: a
/// remeshed family meshes the .geo again at each level, `level` one of its parameters.
fn gmsh_call(
    scene: &Scene,
    params: &[(String, f64)],
    level: usize,
) -> (Vec<(String, f64)>, usize, gmsh::Split) {
    match scene.refinement {
        Refinement::Split => (params.to_vec(), level, gmsh::Split::Chords),
        Refinement::Curved => (params.to_vec(), level, gmsh::Split::OnCurves),
        Refinement::Remesh => (
            params
                .iter()
                .cloned()
                .chain([("level".to_string(), level as f64)])
                .collect(),
            0,
            gmsh::Split::Chords,
        ),
    }
}

/// [`mesh_healed`] before its errors are put on the scene file.
fn mesh_or_regenerated(
    scene: &Scene,
    params: &[(String, f64)],
    level: usize,
    cache: &std::path::Path,
) -> Result<(gmsh::GeneratedMesh, msh::RawMesh)> {
    let (params, level, split) = gmsh_call(scene, params, level);
    let params = &params[..];
    let generated = gmsh::generate_in(cache, &scene.geo, params, level, split)?;
    match msh::read_msh(&generated.path) {
        Ok(raw) => Ok((generated, raw)),
        Err(_) => {
            eprintln!(
                "warning: the cached mesh {} did not parse; regenerating it",
                generated.path.display()
            );
            std::fs::remove_file(&generated.path).map_err(|e| Error::io(&generated.path, e))?;
            let generated = gmsh::generate_in(cache, &scene.geo, params, level, split)?;
            let raw = msh::read_msh(&generated.path)?;
            Ok((generated, raw))
        }
    }
}

/// What one solve of a case gave and cost: the run summary that `solve` writes as
/// summary.csv and `study speed` extends with its own columns.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// Scene name.
    pub scene: String,
    /// Cone.
    pub method: Method,
    /// Solver.
    pub solver: SolverKind,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter over both bodies (length).
    pub h: f64,
    /// Free dofs.
    pub dofs: usize,
    /// Time steps.
    pub steps: usize,
    /// Iterations in total (Newton iterations; inner solves for the fixed-point solvers).
    pub iterations: usize,
    /// Largest iteration count of one step.
    pub max_step_iterations: usize,
    /// Active-set changes summed over the steps.
    pub active_set_changes: usize,
    /// Largest interpenetration at T (length).
    pub max_penetration: f64,
    /// Contact fraction at T.
    pub contact_fraction: f64,
    /// Plastic fraction at T.
    pub plastic_fraction: f64,
    /// Seconds generating (or fetching) and reading the mesh.
    pub mesh_s: f64,
    /// Seconds building the model, interface and constraint rows.
    pub model_s: f64,
    /// Wall time of the time loop (s), without the solver's one-off set-up.
    pub time_loop_s: f64,
    /// Where the solver's time went.
    pub timings: Timings,
    /// The floor measured on the same problem (s), when measured.
    pub floor_s: Option<f64>,
    /// Peak resident memory of the process during the solve (GiB; the peak is reset just
    /// before it, see [`PeakMemory`]), where known.
    pub peak_rss_gib: Option<f64>,
}

impl RunSummary {
    /// Summarize `sol`, the solution of `case` by `solver`.
    pub fn new(
        case: &Case,
        solver: SolverKind,
        sol: &Solution,
        floor_s: Option<f64>,
        peak_rss_gib: Option<f64>,
    ) -> Self {
        let p = &case.problem;
        let last = sol.last();
        RunSummary {
            scene: p.model.scene.name.clone(),
            method: p.method,
            solver,
            level: case.level,
            h: case.h,
            dofs: p.model.n_free,
            steps: sol.reports.len(),
            iterations: sol.iterations(),
            max_step_iterations: sol.max_step_iterations(),
            active_set_changes: sol.active_set_changes(),
            max_penetration: crate::metrics::max_penetration(p, last),
            contact_fraction: crate::metrics::contact_fraction(p, last),
            plastic_fraction: crate::metrics::plastic_fraction(p, last),
            mesh_s: case.mesh_s,
            model_s: case.setup_s,
            time_loop_s: sol.wall_s,
            timings: sol.timings,
            floor_s,
            peak_rss_gib,
        }
    }

    /// The solver's cost, its one-off set-up (pattern, symbolic analysis) plus the time
    /// loop, over the floor (which has its own pattern and symbolic analysis).
    pub fn ratio_to_floor(&self) -> Option<f64> {
        self.floor_s
            .map(|f| (self.timings.setup_s + self.time_loop_s) / f)
    }
}

/// The peak resident memory of one run: Linux keeps the process's peak (VmHWM in
/// /proc/self/status) and resets it to the current size when "5" is written to
/// /proc/self/clear_refs, so a run's peak is read after a reset just before it.
pub struct PeakMemory {
    reset: bool,
}

impl PeakMemory {
    /// Reset the process's peak to its current resident size, after handing the heap's free
    /// memory back to the system (glibc keeps freed memory resident: without the trim, a
    /// small run after a large one would report the large one's leftover heap).
    pub fn start() -> Self {
        release_free_heap();
        PeakMemory {
            reset: std::fs::write("/proc/self/clear_refs", "5").is_ok(),
        }
    }

    /// The peak since [`PeakMemory::start`] (GiB); None where it cannot be read or reset.
    pub fn peak_gib(&self) -> Option<f64> {
        if !self.reset {
            return None;
        }
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb / (1024.0 * 1024.0))
    }
}

pub use crate::solve::floor::release_free_heap;

/// Round-off bound of the checks of an exact solution, relative to the field's scale.
const EXACT_TOL: f64 = 1e-9;

/// A point of Gamma_C with the slave's outward normal and the tangent.
type ContactSample = ([f64; 2], [f64; 2], [f64; 2]);

/// A point of a clamp or roller: position, body, held components, curve name.
type SupportSample<'a> = ([f64; 2], usize, Vec<usize>, &'a str);

/// Refuse an exact solution that is not a solution of the contact problem, before anything
/// is solved: at 401 points of every piece of Gamma_C and at t = T/4, T/2, 3T/4, T, no
/// tangential traction on either side, equal normal tractions, pressure >= 0, gap >= 0,
/// pressure x gap = 0 (each to round-off, 1e-9 of the field's scale), a given pressure equal
/// to -sigma_nn; and u = 0 on the clamps, u_c = 0 with no tangential traction on the rollers
/// (at the ends and middle of their edges).
pub fn verify_exact(
    model: &Model,
    interface: &Interface,
    raw: &crate::mesh::RawMesh,
) -> Result<()> {
    let sc = &model.scene;
    let Some(ex) = sc.exact.as_deref() else {
        return Ok(());
    };
    let times: Vec<f64> = (1..=4).map(|k| sc.final_time * k as f64 / 4.0).collect();
    let contact = contact_samples(interface, ex);
    let supports = support_samples(model, raw);
    let scales = exact_scales(ex, &contact, &supports, &times);
    check_singular_point(model, interface, ex)?;
    check_symmetry(model, ex, &times, scales.0)?;
    for &t in &times {
        let failure = contact
            .iter()
            .find_map(|c| {
                check_contact_point(ex, c, t, scales)
                    .err()
                    .map(|w| (w, c.0))
            })
            .or_else(|| {
                supports.iter().find_map(|s| {
                    check_support_point(ex, s, t, scales)
                        .err()
                        .map(|w| (w, s.0))
                })
            });
        if let Some((what, x)) = failure {
            return Err(Error::input(
                &sc.file,
                "exact",
                format!(
                    "the exact solution is not a solution of the contact problem: {what} at (x, y) = ({:.6}, {:.6}), t = {t}; fix the [exact] fields",
                    x[0], x[1]
                ),
            ));
        }
    }
    Ok(())
}

/// The points of Gamma_C the contact conditions are checked at: 401 per piece with its
/// normal; where the scene gives Gamma_C's exact geometry, body 1's trace nodes (which lie
/// on its curve; the points between lie on chords, off it) with the exact normal.
fn contact_samples(interface: &Interface, ex: &Exact) -> Vec<ContactSample> {
    let mut out = Vec::new();
    for p in &interface.pieces {
        let points: Vec<[f64; 2]> = match ex.contact {
            Some(_) => p.slave_s.iter().map(|&s| p.point(s)).collect(),
            None => (0..=400)
                .map(|k| p.point(p.length * k as f64 / 400.0))
                .collect(),
        };
        for x in points {
            let n = ex.normal_at(p.normal, x[0], x[1]);
            out.push((x, n, [-n[1], n[0]]));
        }
    }
    out
}

/// Refuse a singular point off Gamma_C: the singular part is the transition between
/// contact and separation, and its place among the trace nodes is reported
/// ([`Interface::node_offset`]). The point need not be a node: the rules split the
/// triangles and segments that hold it.
fn check_singular_point(model: &Model, interface: &Interface, ex: &Exact) -> Result<()> {
    let Some(s) = &ex.singular else {
        return Ok(());
    };
    if interface.node_offset(s.point).is_none() {
        return Err(Error::input(
            &model.scene.file,
            "exact.singular.point",
            format!(
                "the singular point ({}, {}) is not on Gamma_C (curves '{}' and '{}'); the singular part belongs to the transition between contact and separation: put the point on Gamma_C, where the displacement's singular part is centred",
                s.point[0], s.point[1], model.scene.slave_curve, model.scene.master_curve
            ),
        ));
    }
    Ok(())
}

/// Refuse a stress given as a full tensor whose off-diagonal entries differ (s12 != s21 at
/// an element centroid, beyond round-off of the stress scale `s_scale`): a Cauchy stress is
/// symmetric, and the solver stores one shear component.
fn check_symmetry(model: &Model, ex: &Exact, times: &[f64], s_scale: f64) -> Result<()> {
    for (b, asymmetry) in ex.asymmetry.iter().enumerate() {
        let Some(d) = asymmetry else { continue };
        for e in model.elements.iter().filter(|e| e.body == b) {
            let p = e.nodes.map(|n| model.position(n));
            let (x, y) = (
                (p[0][0] + p[1][0] + p[2][0]) / 3.0,
                (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            );
            for &t in times {
                let v = d.eval(x, y, t);
                if !(v.abs() <= EXACT_TOL * s_scale) {
                    return Err(Error::input(
                        &model.scene.file,
                        "exact.stress",
                        format!(
                            "the stress of body '{}' is not symmetric: s12 - s21 = {v:.3e} at (x, y) = ({x:.6}, {y:.6}), t = {t}; a Cauchy stress is symmetric: give s21 the same expression as s12",
                            model.scene.bodies[b].surface
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Points of the clamps and rollers (the ends and middle of every edge).
fn support_samples<'a>(model: &'a Model, raw: &crate::mesh::RawMesh) -> Vec<SupportSample<'a>> {
    let sc = &model.scene;
    let held = sc.clamps.iter().map(|c| (c.as_str(), vec![0, 1])).chain(
        sc.rollers
            .iter()
            .map(|r| (r.curve.as_str(), vec![r.component])),
    );
    let mut out = Vec::new();
    for (curve, components) in held {
        for b in 0..2 {
            for e in model.meshes[b].curve_edges(raw, curve) {
                let (pa, pb) = (model.meshes[b].nodes[e[0]], model.meshes[b].nodes[e[1]]);
                for w in [0.0, 0.5, 1.0] {
                    let x = [pa[0] + w * (pb[0] - pa[0]), pa[1] + w * (pb[1] - pa[1])];
                    out.push((x, b, components.clone(), curve));
                }
            }
        }
    }
    out
}

/// The largest stress component (or pressure) and displacement over the samples and times,
/// each point in its own body (both bodies on Gamma_C): the scales of the round-off bounds.
fn exact_scales(
    ex: &Exact,
    contact: &[ContactSample],
    supports: &[SupportSample],
    times: &[f64],
) -> (f64, f64) {
    let (mut s_scale, mut u_scale) = (f64::MIN_POSITIVE, f64::MIN_POSITIVE);
    let points = contact
        .iter()
        .flat_map(|c| [(c.0, 0), (c.0, 1)])
        .chain(supports.iter().map(|s| (s.0, s.1)));
    for (x, b) in points {
        for &t in times {
            if let Some(s) = ex.stress_at(b, x[0], x[1], t) {
                s_scale = s.iter().fold(s_scale, |m, v| m.max(v.abs()));
            }
            if let Some(u) = ex.displacement_at(b, x[0], x[1], t) {
                u_scale = u.iter().fold(u_scale, |m, v| m.max(v.abs()));
            }
            if let Some(p) = ex.pressure.as_ref() {
                s_scale = s_scale.max(p.eval(x[0], x[1], t).abs());
            }
        }
    }
    (s_scale, u_scale)
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The contact conditions at one point of Gamma_C; Err says which fails and by how much.
fn check_contact_point(
    ex: &Exact,
    &(x, n, tau): &ContactSample,
    t: f64,
    (s_scale, u_scale): (f64, f64),
) -> std::result::Result<(), String> {
    use crate::analytical::traction;
    let mut pressure = ex.pressure.as_ref().map(|p| p.eval(x[0], x[1], t));
    // Body 2's side at the point x faces, its traction per unit length of body 1's curve.
    let m = ex.facing(x[0], x[1]);
    let stretch = ex
        .contact
        .as_ref()
        .map_or(1.0, |c| c.stretch_at(x[0], x[1]));
    if let (Some(s1), Some(s2)) = (
        ex.stress_at(0, x[0], x[1], t),
        ex.stress_at(1, m[0], m[1], t),
    ) {
        let t2 = traction(s2, [-n[0], -n[1]]).map(|v| v * stretch);
        let t1 = traction(s1, n);
        for (side, tr) in [("slave", t1), ("master", t2)] {
            if dot(tr, tau).abs() > EXACT_TOL * s_scale {
                return Err(format!(
                    "tangential traction on the {side} side {:.3e} (should be 0)",
                    dot(tr, tau)
                ));
            }
        }
        let (nn1, nn2) = (dot(t1, n), -dot(t2, n));
        if (nn1 - nn2).abs() > EXACT_TOL * s_scale {
            return Err(format!(
                "normal tractions differ: sigma_nn {nn1:.6e} on the slave side, {nn2:.6e} on the master side"
            ));
        }
        if let Some(p) = pressure {
            if (p + nn1).abs() > EXACT_TOL * s_scale {
                return Err(format!(
                    "exact.pressure {p:.6e} is not -sigma_nn = {:.6e}",
                    -nn1
                ));
            }
        }
        pressure = Some(-nn1);
    }
    if let Some(p) = pressure {
        if p < -EXACT_TOL * s_scale {
            return Err(format!(
                "pressure {p:.3e} < 0 (the bodies pull on each other)"
            ));
        }
    }
    if let Some(gap) = ex.gap_at(n, x[0], x[1], t) {
        if gap < -EXACT_TOL * u_scale {
            return Err(format!("gap {gap:.3e} < 0 (the bodies interpenetrate)"));
        }
        if let Some(p) = pressure {
            if (p * gap).abs() > EXACT_TOL * s_scale * u_scale {
                return Err(format!(
                    "pressure x gap = {:.3e} != 0 (pressure {p:.6e}, gap {gap:.6e})",
                    p * gap
                ));
            }
        }
    }
    Ok(())
}

/// The support conditions at one point of a clamp or roller.
fn check_support_point(
    ex: &Exact,
    (x, b, components, curve): &SupportSample,
    t: f64,
    (s_scale, u_scale): (f64, f64),
) -> std::result::Result<(), String> {
    if let Some(u) = ex.displacement_at(*b, x[0], x[1], t) {
        for &c in components {
            if u[c].abs() > EXACT_TOL * u_scale {
                return Err(format!(
                    "u_{} = {:.6e} on '{curve}', which holds it at 0",
                    ["x", "y"][c],
                    u[c]
                ));
            }
        }
    }
    if components.len() == 1 {
        if let Some(s) = ex.stress_at(*b, x[0], x[1], t) {
            if s[2].abs() > EXACT_TOL * s_scale {
                return Err(format!(
                    "tangential traction sigma_12 = {:.3e} on the roller '{curve}' (should be 0)",
                    s[2]
                ));
            }
        }
    }
    Ok(())
}
