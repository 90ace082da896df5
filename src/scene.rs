//! Scenes are data: a TOML file names the .geo and its gmsh parameters, the two bodies and
//! their materials, the boundary parts by physical-curve name, loads as expressions in
//! x, y, t, the contact lines, the time interval, and optionally an exact solution.

use crate::analytical::{Exact, Field};
use crate::error::{Error, Result};
pub use crate::expr::{Expr, VectorExpr};
use crate::material::{Elasticity, Material, Plane, Viscoplasticity};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One body of a scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Physical-surface name in the mesh.
    pub surface: String,
    /// Young's modulus E (> 0).
    pub young: f64,
    /// Poisson's ratio in (-1, 0.5).
    pub poisson: f64,
    /// Perzyna viscosity lambda (> 0); with `yield_stress`, makes the body viscoplastic.
    pub lambda: Option<f64>,
    /// Uniaxial yield stress sigma_Y (> 0); absent: the body is elastic.
    pub yield_stress: Option<f64>,
    /// Body force f = [f_x, f_y] as expressions in x, y, t (force per area).
    pub body_force: Option<[String; 2]>,
}

/// A clamped curve (u = 0).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampSpec {
    /// Physical-curve name.
    pub curve: String,
}

/// A roller (symmetry) curve: one displacement component held at zero.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollerSpec {
    /// Physical-curve name (axis-aligned).
    pub curve: String,
    /// The held component, "x" or "y".
    pub component: String,
}

/// A traction on a curve, g = [g_x, g_y] (force per length) as expressions in x, y, t.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TractionSpec {
    /// Physical-curve name.
    pub curve: String,
    /// The traction components; omitted in a manufactured scene, where g = sigma(u) n is
    /// derived from the manufactured displacement.
    pub g: Option<[String; 2]>,
}

/// The contact lines.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Surface name of the body that carries the constraint (body 1, the "slave").
    pub slave_body: String,
    /// Physical-curve name of Gamma_C on the slave body.
    pub slave_curve: String,
    /// Physical-curve name of Gamma_C on the other body (the "master").
    pub master_curve: String,
    /// The initial gap g0(x, y) >= 0 between the bodies along body 1's outward normal, as
    /// an expression in x and y on body 1's trace (length), added to the gap between the
    /// two meshed traces; absent: the bodies touch where their traces do.
    pub gap: Option<String>,
}

/// Exact stress: components [s11, s22, s12] or the full tensor [[s11, s12], [s21, s22]]
/// (whose symmetry is checked), for both bodies or one per body.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum StressSpec {
    /// The same stress in both bodies, as [s11, s22, s12].
    Both([String; 3]),
    /// One stress per body, in [[bodies]] order, as [s11, s22, s12].
    PerBody([[String; 3]; 2]),
    /// The same stress tensor in both bodies, [[s11, s12], [s21, s22]].
    BothTensor([[String; 2]; 2]),
    /// One stress tensor per body, in [[bodies]] order.
    PerBodyTensor([[[String; 2]; 2]; 2]),
}

impl StressSpec {
    /// The stress of body `i` (file order) as (field name, [s11, s22, s12], s21 when the
    /// tensor form gives it with a text other than s12's).
    fn of(&self, i: usize) -> (String, [&String; 3], Option<&String>) {
        fn tensor(t: &[[String; 2]; 2], field: String) -> (String, [&String; 3], Option<&String>) {
            let same = t[0][1].split_whitespace().collect::<String>()
                == t[1][0].split_whitespace().collect::<String>();
            (
                field,
                [&t[0][0], &t[1][1], &t[0][1]],
                (!same).then_some(&t[1][0]),
            )
        }
        match self {
            StressSpec::Both(s) => ("exact.stress".into(), [&s[0], &s[1], &s[2]], None),
            StressSpec::PerBody(s) => {
                let s = &s[i];
                (format!("exact.stress[{i}]"), [&s[0], &s[1], &s[2]], None)
            }
            StressSpec::BothTensor(t) => tensor(t, "exact.stress".into()),
            StressSpec::PerBodyTensor(t) => tensor(&t[i], format!("exact.stress[{i}]")),
        }
    }
}

/// Optional exact solution: what a study with `[reference] exact = true` measures against.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExactSpec {
    /// Displacement [u_x, u_y] of each body, in [[bodies]] order (length).
    pub displacement: Option<[[String; 2]; 2]>,
    /// Stress [s11, s22, s12] or [[s11, s12], [s21, s22]] (derived from the displacement
    /// of elastic bodies when omitted; required with the displacement of a manufactured
    /// viscoplastic body, whose constitutive source needs both).
    pub stress: Option<StressSpec>,
    /// Contact pressure on Gamma_C (force/length; -sigma_nn of the slave when omitted).
    pub pressure: Option<String>,
    /// The fields are manufactured: the body forces f = -div sigma and the tractions
    /// sigma n on the Neumann curves are derived from them, and where the stress is given
    /// the constitutive source s = d sigma/dt - E eps(du/dt) - G(sigma).
    #[serde(default)]
    pub manufactured: bool,
    /// A part of the displacement singular at a point, added to `displacement`.
    pub singular: Option<SingularSpec>,
    /// Gamma_C's exact geometry where it is curved or the bodies are meshed apart.
    pub contact: Option<ExactContactSpec>,
}

/// `[exact.contact]`: the exact contact geometry of a curved Gamma_C or of bodies meshed
/// apart (the press fit), as expressions in x and y on body 1's contact curve. Without it
/// the exact fields are read at the discrete trace's own points and normal, the two bodies
/// at one point (flat and touching).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExactContactSpec {
    /// Body 1's outward unit normal nu(x, y) [n_x, n_y] (normalised where it is read).
    pub normal: [String; 2],
    /// The point m(x, y) [x, y] of body 2's contact curve that the point (x, y) of body 1's
    /// faces along nu (length): the gap before any load is (m - x).nu, and action and
    /// reaction balance per unit length along the map (p1 = p2 |dm/ds|).
    pub master: [String; 2],
}

/// `[exact.singular]`: the part of a manufactured elastic displacement singular at a point
/// c, O(r^exponent) with r = |x - c| and a factor smooth along the rays from c (the
/// `regularity` scenes). The displacement is `exact.displacement` plus this part; every
/// integral on the triangles at c splits its integrand by power of r
/// (`analytical::Singular`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SingularSpec {
    /// The point c (length): a node of both meshes.
    pub point: [f64; 2],
    /// beta > 1/2 (the pressure ~ r^(beta-1) must lie in L2(Gamma_C)).
    pub exponent: f64,
    /// The singular part [u_x, u_y] of each body, in [[bodies]] order.
    pub displacement: [[String; 2]; 2],
}

/// The TOML layout of a scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// One line saying what the scene is.
    pub description: String,
    /// The .geo file, relative to the scene file.
    pub geo: PathBuf,
    /// gmsh parameters (`-setnumber NAME VALUE`).
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
    /// How level L is made: by splitting level L - 1 (default), or by meshing the .geo
    /// again with `level = L` (a .geo whose sizes are graded: splitting keeps level 0's
    /// size ratios).
    #[serde(default)]
    pub refinement: Refinement,
    /// Final time T (> 0).
    pub final_time: f64,
    /// Default number of uniform time steps (> 0).
    pub steps: usize,
    /// The two bodies.
    pub bodies: Vec<BodySpec>,
    /// Clamped curves.
    #[serde(default)]
    pub clamp: Vec<ClampSpec>,
    /// Roller curves.
    #[serde(default)]
    pub roller: Vec<RollerSpec>,
    /// Traction curves.
    #[serde(default)]
    pub traction: Vec<TractionSpec>,
    /// Contact lines.
    pub contact: ContactSpec,
    /// Exact solution, if known.
    pub exact: Option<ExactSpec>,
    /// The elastic law's 2D reduction, "stress" (default) or "strain", for both bodies.
    #[serde(default)]
    pub plane: Plane,
}

/// How a scene's mesh levels are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Refinement {
    /// Level L splits every triangle of level L - 1 in four (nested levels).
    #[default]
    Split,
    /// Level L is gmsh's own mesh of the .geo with the parameter `level = L` (the .geo
    /// scales its sizes by 2^-level itself); levels are not nested.
    Remesh,
    /// Level L splits level 0 L times with every new boundary node on its .geo curve
    /// ([`crate::mesh::gmsh::Split::OnCurves`]): curved traces converge to their curves;
    /// nested but for those nodes, judged in the effective h as a remeshed family.
    Curved,
}

impl Refinement {
    /// Whether the judge reads a level's largest element diameter (nested splits) rather
    /// than its effective size (levels meshed anew, or split on curves;
    /// [`crate::fe::Model::judge_h`]).
    pub fn judged_by_max_diameter(self) -> bool {
        self == Refinement::Split
    }

    /// The name of the h the judge reads, for a plot's axis.
    pub fn h_axis(self) -> &'static str {
        match self.judged_by_max_diameter() {
            true => "h (max element diameter)",
            false => "h_eff = (|Omega_h| / triangles)^(1/2)",
        }
    }
}

/// A body of a validated scene.
#[derive(Debug, Clone)]
pub struct SceneBody {
    /// Physical-surface name.
    pub surface: String,
    /// Its material.
    pub material: Material,
    /// Body force, if any.
    pub body_force: Option<VectorExpr>,
    /// Its place in the scene file's `[[bodies]]`: errors name the field
    /// `bodies[file_index]`.
    pub file_index: usize,
}

/// A roller condition: curve and held component (0 = x, 1 = y).
#[derive(Debug, Clone)]
pub struct Roller {
    /// Physical-curve name.
    pub curve: String,
    /// Held component.
    pub component: usize,
}

/// A traction on a curve.
#[derive(Debug, Clone)]
pub struct Traction {
    /// Physical-curve name.
    pub curve: String,
    /// g(x, y, t); None: sigma(u) n of the manufactured solution, on the curve's body.
    pub g: Option<VectorExpr>,
}

/// A validated scene, ready to be meshed and solved.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Scene name (file stem).
    pub name: String,
    /// The scene file.
    pub file: PathBuf,
    /// One-line description.
    pub description: String,
    /// Absolute path of the .geo.
    pub geo: PathBuf,
    /// gmsh parameters.
    pub parameters: BTreeMap<String, f64>,
    /// How the levels are made.
    pub refinement: Refinement,
    /// Final time T.
    pub final_time: f64,
    /// Default number of time steps.
    pub steps: usize,
    /// Bodies; index 0 is the slave (body 1), index 1 the master (body 2).
    pub bodies: [SceneBody; 2],
    /// Clamped curves.
    pub clamps: Vec<String>,
    /// Roller curves.
    pub rollers: Vec<Roller>,
    /// Tractions.
    pub tractions: Vec<Traction>,
    /// Gamma_C on body 1.
    pub slave_curve: String,
    /// Gamma_C on body 2.
    pub master_curve: String,
    /// The exact solution, if known (Box: it holds many expressions).
    pub exact: Option<Box<Exact>>,
    /// The initial gap g0(x, y) along body 1's normal on Gamma_C (`[contact] gap`; length).
    pub initial_gap: Option<Expr>,
}

/// The folder of the built-in scenes.
pub fn builtin_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Names of the built-in scenes.
pub fn builtin_names() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(builtin_dir())
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter_map(|e| {
                    let p = e.path();
                    (p.extension().is_some_and(|x| x == "toml"))
                        .then(|| p.file_stem().unwrap().to_string_lossy().to_string())
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Every built-in scene, name and one-line description, sorted by name.
pub fn builtin_list() -> Result<Vec<(String, String)>> {
    builtin_names()
        .into_iter()
        .map(|n| Ok((n.clone(), Scene::load(&n)?.description)))
        .collect()
}

fn check_positive(file: &Path, field: &str, v: f64, what: &str) -> Result<()> {
    if !(v > 0.0 && v.is_finite()) {
        return Err(Error::input(
            file,
            field,
            format!("{what} must be a positive finite number, got {v}; fix the value"),
        ));
    }
    Ok(())
}

impl Scene {
    /// Load a built-in scene by name, or a scene file by path.
    pub fn load(name_or_path: &str) -> Result<Self> {
        let p = Path::new(name_or_path);
        if p.is_dir() && p.extension().is_some_and(|e| e == "toml") {
            return Err(Error::input(
                name_or_path,
                "scene",
                "is a folder, not a scene file; give the path of a scene's .toml file or a built-in scene's name (`contact-rates scene list`)",
            ));
        }
        let file = if p.extension().is_some_and(|e| e == "toml") || p.is_file() {
            p.to_path_buf()
        } else {
            let f = builtin_dir().join(format!("{name_or_path}.toml"));
            if !f.exists() {
                return Err(Error::input(
                    name_or_path,
                    "scene",
                    format!(
                        "no built-in scene named '{name_or_path}' and no such file; built-in scenes (`contact-rates scene list` describes them): {}",
                        builtin_names().join(", ")
                    ),
                ));
            }
            f
        };
        let text = std::fs::read_to_string(&file).map_err(|e| Error::io(&file, e))?;
        Self::from_toml(&text, &file)
    }

    /// The same scene with body `surface` carrying the contact constraint (the slave):
    /// the file read again with its `[contact]` slave and master exchanged where needed,
    /// and validated as a file would be.
    pub fn with_slave(&self, surface: &str) -> Result<Self> {
        let text = std::fs::read_to_string(&self.file).map_err(|e| Error::io(&self.file, e))?;
        let mut sf: SceneFile = crate::error::parse_toml(&text, &self.file, "scene file")?;
        if sf.contact.slave_body != surface {
            if !sf.bodies.iter().any(|b| b.surface == surface) {
                return Err(Error::input(
                    &self.file,
                    "contact.slave_body",
                    format!(
                        "'{surface}' is not the surface of either body ({}); name one of them as the slave",
                        sf.bodies
                            .iter()
                            .map(|b| b.surface.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
            sf.contact.slave_body = surface.to_string();
            std::mem::swap(&mut sf.contact.slave_curve, &mut sf.contact.master_curve);
        }
        Self::validate(sf, &self.file)
    }

    /// Parse and validate scene TOML text; `file` locates the .geo and names errors.
    pub fn from_toml(text: &str, file: &Path) -> Result<Self> {
        let sf: SceneFile = crate::error::parse_toml(text, file, "scene file")?;
        Self::validate(sf, file)
    }

    /// Validate a parsed scene file; `file` locates the .geo and names errors. One check per
    /// table, in a fixed order (the first error found is the one reported).
    fn validate(sf: SceneFile, file: &Path) -> Result<Self> {
        let name = file
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let geo = geo_path(&sf.geo, file)?;
        check_time(sf.final_time, sf.steps, file)?;
        let mut bodies = bodies(&sf.bodies, sf.plane, file)?;
        let swapped = slave_first(&mut bodies, &sf.contact, file)?;
        let mut claims = Claims::new(file);
        for (i, c) in sf.clamp.iter().enumerate() {
            claims.claim(&c.curve, "clamp", format!("clamp[{i}].curve"))?;
        }
        let rollers = rollers(&sf.roller, &mut claims, file)?;
        let manufactured = sf.exact.as_ref().is_some_and(|e| e.manufactured);
        let tractions = tractions(&sf.traction, manufactured, &mut claims, file)?;
        claims.claim(
            &sf.contact.slave_curve,
            "contact",
            "contact.slave_curve".into(),
        )?;
        claims.claim(
            &sf.contact.master_curve,
            "contact",
            "contact.master_curve".into(),
        )?;
        let initial_gap = initial_gap(&sf.contact, file)?;
        let exact = match &sf.exact {
            Some(spec) => {
                let mut exact = exact_solution(spec, &mut bodies, swapped, file)?;
                exact.initial_gap = initial_gap.clone();
                Some(Box::new(exact))
            }
            None => None,
        };
        let [b0, b1]: [SceneBody; 2] = bodies.try_into().expect("two bodies");
        Ok(Scene {
            name,
            file: file.to_path_buf(),
            description: sf.description,
            geo,
            parameters: sf.parameters,
            refinement: sf.refinement,
            final_time: sf.final_time,
            steps: sf.steps,
            bodies: [b0, b1],
            clamps: sf.clamp.into_iter().map(|c| c.curve).collect(),
            rollers,
            tractions,
            slave_curve: sf.contact.slave_curve,
            master_curve: sf.contact.master_curve,
            exact,
            initial_gap,
        })
    }
}

/// The `[contact] gap` key: an expression in x and y (a gap that changed with t would not
/// be an initial one). Its sign is checked on the mesh, where body 1's trace is known.
fn initial_gap(contact: &ContactSpec, file: &Path) -> Result<Option<Expr>> {
    let Some(text) = &contact.gap else {
        return Ok(None);
    };
    let g = Expr::parse(text, file, "contact.gap")?;
    if g.reads_time() {
        return Err(Error::input(
            file,
            "contact.gap",
            format!(
                "the initial gap '{text}' reads t; write it in x and y only (the gap before any load)"
            ),
        ));
    }
    Ok(Some(g))
}

/// The `geo` key: the .geo file relative to the scene file, which must exist.
fn geo_path(geo: &Path, file: &Path) -> Result<PathBuf> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let geo = dir.join(geo);
    if !geo.is_file() {
        return Err(Error::input(
            file,
            "geo",
            format!(
                "the .geo file {} does not exist or is not a file; give its path relative to the scene file",
                geo.display()
            ),
        ));
    }
    Ok(geo)
}

/// The `final_time` and `steps` keys: a positive interval and at least one step.
fn check_time(final_time: f64, steps: usize, file: &Path) -> Result<()> {
    check_positive(file, "final_time", final_time, "final_time")?;
    if steps == 0 {
        return Err(Error::input(
            file,
            "steps",
            "steps must be at least 1; fix the value",
        ));
    }
    Ok(())
}

/// The `[[bodies]]` tables: exactly two, each with its material and body force, in file
/// order.
fn bodies(specs: &[BodySpec], plane: Plane, file: &Path) -> Result<Vec<SceneBody>> {
    if specs.len() != 2 {
        return Err(Error::input(
            file,
            "bodies",
            format!("a scene has exactly two [[bodies]], found {}", specs.len()),
        ));
    }
    specs
        .iter()
        .enumerate()
        .map(|(i, b)| body(i, b, plane, file))
        .collect()
}

/// Body `i` of the `[[bodies]]` tables: elastic constants, the viscoplastic pair (both or
/// neither), and the body force.
fn body(i: usize, b: &BodySpec, plane: Plane, file: &Path) -> Result<SceneBody> {
    let f = |k: &str| format!("bodies[{i}].{k}");
    check_positive(file, &f("young"), b.young, "Young's modulus")?;
    if !(b.poisson > -1.0 && b.poisson < 0.5) {
        return Err(Error::input(
            file,
            f("poisson"),
            format!(
                "Poisson's ratio must lie in (-1, 0.5), got {}; fix the value",
                b.poisson
            ),
        ));
    }
    let viscoplastic = match (b.lambda, b.yield_stress) {
        (None, None) => None,
        (Some(_), Some(_)) if plane == Plane::Strain => {
            // The von Mises set and its projection are written for sigma_33 = 0.
            return Err(Error::input(
                file,
                "plane",
                format!(
                    "body {} is viscoplastic, and the viscoplastic law is plane stress (the von Mises set of sigma_33 = 0); set plane = \"stress\" or make the body elastic (no lambda, no yield_stress)",
                    b.surface
                ),
            ));
        }
        (Some(l), Some(y)) => {
            check_positive(file, &f("lambda"), l, "the viscosity lambda")?;
            check_positive(file, &f("yield_stress"), y, "the yield stress")?;
            Some(Viscoplasticity {
                lambda: l,
                yield_stress: y,
            })
        }
        (Some(_), None) => {
            return Err(Error::input(
                file,
                f("yield_stress"),
                "lambda is given without yield_stress; give both for a viscoplastic body or neither for an elastic one",
            ));
        }
        (None, Some(_)) => {
            return Err(Error::input(
                file,
                f("lambda"),
                "yield_stress is given without lambda; give both for a viscoplastic body or neither for an elastic one",
            ));
        }
    };
    let body_force = b
        .body_force
        .as_ref()
        .map(|e| VectorExpr::parse(e, file, &f("body_force")))
        .transpose()?;
    Ok(SceneBody {
        surface: b.surface.clone(),
        material: Material {
            elastic: Elasticity {
                young: b.young,
                poisson: b.poisson,
                plane,
            },
            viscoplastic,
        },
        body_force,
        file_index: i,
    })
}

/// `[contact] slave_body`: puts the slave first in `bodies`; true when the file lists it
/// second (the order swapped).
fn slave_first(bodies: &mut [SceneBody], contact: &ContactSpec, file: &Path) -> Result<bool> {
    let slave = bodies
        .iter()
        .position(|b| b.surface == contact.slave_body)
        .ok_or_else(|| {
            Error::input(
                file,
                "contact.slave_body",
                format!(
                    "'{}' is not the surface of either body ({}, {})",
                    contact.slave_body, bodies[0].surface, bodies[1].surface
                ),
            )
        })?;
    if slave == 1 {
        bodies.swap(0, 1);
    }
    Ok(slave == 1)
}

/// The boundary curves claimed so far, and by which condition: a curve takes one.
struct Claims<'f> {
    file: &'f Path,
    claimed: BTreeMap<String, &'static str>,
}

impl<'f> Claims<'f> {
    fn new(file: &'f Path) -> Self {
        Claims {
            file,
            claimed: BTreeMap::new(),
        }
    }

    /// Claim `curve` for the condition `what` (named `field` in the file); errs on a curve
    /// claimed before.
    fn claim(&mut self, curve: &str, what: &'static str, field: String) -> Result<()> {
        if let Some(prev) = self.claimed.insert(curve.to_string(), what) {
            return Err(Error::input(
                self.file,
                field,
                format!(
                    "curve '{curve}' is claimed twice ({prev} and {what}); a boundary part takes one condition: split it into two physical curves or drop one"
                ),
            ));
        }
        Ok(())
    }
}

/// The `[[roller]]` tables: each curve claimed, its component "x" or "y".
fn rollers(specs: &[RollerSpec], claims: &mut Claims, file: &Path) -> Result<Vec<Roller>> {
    let mut rollers = Vec::new();
    for (i, r) in specs.iter().enumerate() {
        claims.claim(&r.curve, "roller", format!("roller[{i}].curve"))?;
        let component = match r.component.as_str() {
            "x" => 0,
            "y" => 1,
            other => {
                return Err(Error::input(
                    file,
                    format!("roller[{i}].component"),
                    format!("'{other}' is not a component; use \"x\" or \"y\""),
                ));
            }
        };
        rollers.push(Roller {
            curve: r.curve.clone(),
            component,
        });
    }
    Ok(rollers)
}

/// The `[[traction]]` tables: each curve claimed, with its g, or none in a manufactured
/// scene (which derives it).
fn tractions(
    specs: &[TractionSpec],
    manufactured: bool,
    claims: &mut Claims,
    file: &Path,
) -> Result<Vec<Traction>> {
    let mut tractions = Vec::new();
    for (i, t) in specs.iter().enumerate() {
        claims.claim(&t.curve, "traction", format!("traction[{i}].curve"))?;
        let g = match (&t.g, manufactured) {
            (Some(g), false) => Some(VectorExpr::parse(g, file, &format!("traction[{i}].g"))?),
            (None, true) => None,
            (None, false) => {
                return Err(Error::input(
                    file,
                    format!("traction[{i}].g"),
                    "missing; give g = [\"gx\", \"gy\"] (only a manufactured scene derives it)",
                ));
            }
            (Some(_), true) => {
                return Err(Error::input(
                    file,
                    format!("traction[{i}].g"),
                    "a manufactured scene derives g = sigma n from the exact fields; remove g",
                ));
            }
        };
        tractions.push(Traction {
            curve: t.curve.clone(),
            g,
        });
    }
    Ok(tractions)
}

/// The scene's exact solution from its `[exact]` table; `bodies` are in slave-first order
/// (`swapped`: the file lists the master first). A manufactured solution's body forces are
/// set on `bodies`.
fn exact_solution(
    spec: &ExactSpec,
    bodies: &mut [SceneBody],
    swapped: bool,
    file: &Path,
) -> Result<Exact> {
    let order = |b: usize| if swapped { 1 - b } else { b };
    let mut displacement = exact_displacement(spec, order, file)?;
    let singular = match &spec.singular {
        Some(sp) => {
            let part = singular_part(sp, spec, bodies, order, file)?;
            let smooth = displacement.take().expect("checked by singular_part");
            displacement = Some(crate::analytical::add_displacements(&smooth, &part));
            Some((sp, part, smooth))
        }
        None => None,
    };
    let (stress, asymmetry) = exact_stress(spec, order, file)?;
    let pressure = spec
        .pressure
        .as_ref()
        .map(|p| Expr::parse(p, file, "exact.pressure"))
        .transpose()?;
    if spec.manufactured {
        check_manufactured(displacement.is_some(), stress.is_some(), bodies, file)?;
    }
    // The exact fields and the singular part's, derived side by side. With a singular part
    // and no given stress, the whole fields are the smooth part's plus the singular part's:
    // exmex differentiates the two small displacements, not their sum (its cost grows
    // faster than the expression).
    let materials = [&bodies[0].material, &bodies[1].material];
    let mut exact = match singular {
        Some((sp, part, smooth)) if stress.is_none() => {
            let smooth_copy = smooth.clone();
            let (smooth_fields, singular) = rayon::join(
                || Exact::new(Some(smooth_copy), None, None, spec.manufactured, materials),
                || crate::analytical::Singular::new(sp.point, sp.exponent, part, smooth, materials),
            );
            Exact::with_singular(displacement, pressure, smooth_fields, singular)
        }
        singular => {
            let (mut exact, singular) = rayon::join(
                || Exact::new(displacement, stress, pressure, spec.manufactured, materials),
                || {
                    singular.map(|(sp, part, smooth)| {
                        crate::analytical::Singular::new(
                            sp.point,
                            sp.exponent,
                            part,
                            smooth,
                            materials,
                        )
                    })
                },
            );
            exact.singular = singular;
            exact
        }
    };
    exact.asymmetry = asymmetry;
    exact.contact = spec
        .contact
        .as_ref()
        .map(|c| exact_contact(c, file))
        .transpose()?;
    if let Some(f) = &exact.body_force {
        for (b, body) in bodies.iter_mut().enumerate() {
            body.body_force = Some(VectorExpr(f[b].clone()));
        }
    }
    if !exact.gives(Field::Displacement)
        && !exact.gives(Field::Stress)
        && !exact.gives(Field::Pressure)
    {
        return Err(Error::input(
            file,
            "exact",
            "the [exact] table gives nothing; give displacement, stress or pressure, or remove it",
        ));
    }
    Ok(exact)
}

/// `[exact.contact]` parsed: the normal and the map to body 2's curve, with the map's
/// derivatives.
fn exact_contact(spec: &ExactContactSpec, file: &Path) -> Result<crate::analytical::ContactMap> {
    let parse = |v: &[String; 2], field: &str| -> Result<[Expr; 2]> {
        let [a, b] =
            [0, 1].map(|c| Expr::parse(&v[c], file, &format!("exact.contact.{field}[{c}]")));
        Ok([a?, b?])
    };
    Ok(crate::analytical::ContactMap::new(
        parse(&spec.normal, "normal")?,
        parse(&spec.master, "master")?,
    ))
}

/// `[exact.singular]`'s displacement per body in slave-first order, after its checks: an
/// elastic manufactured scene with a displacement, and beta > 1/2.
fn singular_part(
    sp: &SingularSpec,
    spec: &ExactSpec,
    bodies: &[SceneBody],
    order: impl Fn(usize) -> usize,
    file: &Path,
) -> Result<[[Expr; 2]; 2]> {
    let bad = |field: &str, msg: &str| Err(Error::input(file, field, msg.to_string()));
    if !spec.manufactured || spec.displacement.is_none() || spec.stress.is_some() {
        return bad(
            "exact.singular",
            "a singular part belongs to a manufactured displacement: set exact.manufactured = true and give exact.displacement (its smooth part), without exact.stress",
        );
    }
    if bodies.iter().any(|b| b.material.viscoplastic.is_some()) {
        return bad(
            "exact.singular",
            "a singular part is supported for elastic bodies only: remove lambda and yield_stress",
        );
    }
    if !(sp.exponent > 0.5 && sp.exponent.is_finite()) {
        return bad(
            "exact.singular.exponent",
            "the exponent beta must exceed 1/2 (the pressure ~ r^(beta-1) must lie in L2(Gamma_C)); give a number > 0.5",
        );
    }
    if sp.point.iter().any(|v| !v.is_finite()) {
        return bad(
            "exact.singular.point",
            "give the point as [x, y], two finite numbers",
        );
    }
    parse_displacement(&sp.displacement, order, file, "exact.singular.displacement")
}

/// `exact.displacement` per body in slave-first order (`order` maps it to file order).
fn exact_displacement(
    spec: &ExactSpec,
    order: impl Fn(usize) -> usize,
    file: &Path,
) -> Result<Option<[[Expr; 2]; 2]>> {
    spec.displacement
        .as_ref()
        .map(|d| parse_displacement(d, order, file, "exact.displacement"))
        .transpose()
}

/// A displacement [[u_x, u_y], [u_x, u_y]] in file order parsed into slave-first order
/// (`order` maps it to file order); `field` names it in errors (`field[i][c]`).
fn parse_displacement(
    d: &[[String; 2]; 2],
    order: impl Fn(usize) -> usize,
    file: &Path,
    field: &str,
) -> Result<[[Expr; 2]; 2]> {
    let [[a, b], [c, e]] = [0, 1].map(|b| {
        let i = order(b);
        [0, 1].map(|c| Expr::parse(&d[i][c], file, &format!("{field}[{i}][{c}]")))
    });
    Ok([[a?, b?], [c?, e?]])
}

/// An exact stress [s11, s22, s12] per body, slave first.
type BodyStresses = [[Expr; 3]; 2];

/// `exact.stress` per body in slave-first order (`order` maps it to file order) as [s11,
/// s22, s12], and per body s12 - s21 where the tensor form gives an s21 of another text.
fn exact_stress(
    spec: &ExactSpec,
    order: impl Fn(usize) -> usize,
    file: &Path,
) -> Result<(Option<BodyStresses>, [Option<Expr>; 2])> {
    let mut stress = Vec::new();
    let mut asymmetry = [None, None];
    for b in 0..2 {
        if let Some(spec) = &spec.stress {
            let (field, s, s21) = spec.of(order(b));
            stress.push([
                Expr::parse(s[0], file, &format!("{field}[0]"))?,
                Expr::parse(s[1], file, &format!("{field}[1]"))?,
                Expr::parse(s[2], file, &format!("{field}[2]"))?,
            ]);
            if let Some(s21) = s21 {
                let s21 = Expr::parse(s21, file, &format!("{field}[1][0]"))?;
                asymmetry[b] = Some(Expr::combine(&[(1.0, &stress[b][2]), (-1.0, &s21)]));
            }
        }
    }
    Ok((stress.try_into().ok(), asymmetry))
}

/// `exact.manufactured = true` derives the loads from the fields: it needs the
/// displacement, the stress of a viscoplastic body, and no body force given.
fn check_manufactured(
    has_displacement: bool,
    has_stress: bool,
    bodies: &[SceneBody],
    file: &Path,
) -> Result<()> {
    if !has_displacement {
        return Err(Error::input(
            file,
            "exact.manufactured",
            "a manufactured solution needs exact.displacement = [[\"ux\", \"uy\"], [\"ux\", \"uy\"]], one pair per body",
        ));
    }
    for b in bodies.iter() {
        if b.material.viscoplastic.is_some() && !has_stress {
            return Err(Error::input(
                file,
                "exact.stress",
                format!(
                    "body '{}' is viscoplastic: the constitutive source s = d sigma/dt - E eps(du/dt) - G(sigma) of a manufactured solution needs its stress; give exact.stress = [[\"s11\", \"s22\", \"s12\"], [\"s11\", \"s22\", \"s12\"]], one per body (or remove lambda and yield_stress for an elastic body)",
                    b.surface
                ),
            ));
        }
        if b.body_force.is_some() {
            return Err(Error::input(
                file,
                "exact.manufactured",
                format!(
                    "body '{}' gives a body_force; a manufactured scene derives it from the exact fields: remove it",
                    b.surface
                ),
            ));
        }
    }
    Ok(())
}
