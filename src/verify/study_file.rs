//! The TOML layout of a study file (studies/NAME.toml).

use super::quantity::Quantity;
use crate::analytical::Field;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::solve::{Settings, SolverKind};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The mesh family: gmsh size parameters of the two bodies at level 0 and the levels.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Name of the .geo parameter sizing body 1 (the slave).
    pub size_parameter_1: String,
    /// Name of the .geo parameter sizing body 2 (the master).
    pub size_parameter_2: String,
    /// Coarsest mesh size of body 1 (level 0), length units.
    pub coarsest: f64,
    /// Ratio h1/h2 of the two bodies' sizes (not a ratio of small integers).
    pub ratio: f64,
    /// Refinement levels of the study (each splits every triangle in four).
    pub levels: Vec<usize>,
    /// Coarsest sizes of body 1 of further families (same ratio and levels), solved and
    /// measured like the main one: they put the contact edge elsewhere relative to the
    /// nodes, so the spread of their rates measures the alignment effect.
    #[serde(default)]
    pub variants: Vec<f64>,
    /// Other gmsh parameters.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
}

/// The reference solution.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Reference level minus the finest study level (at least 2; not with `exact`).
    #[serde(default)]
    pub levels_above: usize,
    /// gmsh parameter overrides that make the meshes match on Gamma_C.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
    /// Measure against the scene's exact solution instead of a reference solve.
    #[serde(default)]
    pub exact: bool,
    /// Gauss points per direction of the rule that integrates errors against the exact
    /// solution (n x n per triangle, exact to degree 2n - 2).
    #[serde(default = "default_quadrature")]
    pub quadrature: usize,
}

/// One method's entry in `[thresholds]`: the rate in h the theorem that covers the method
/// on this study states, with where it comes from, or no rate and why no theorem covers it
/// here. Written `mortar = 0.75` (a rate, no source), `mortar = { rate = 0.75, source =
/// "..." }` or `lac = { none = "why" }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "ClaimFile")]
pub struct Claim {
    /// The theorem's rate in h of the threshold quantity (None: the method is reported
    /// without a threshold).
    pub rate: Option<f64>,
    /// The theorem and its hypotheses, or why none applies; empty for a bare rate.
    pub source: String,
}

/// How a [`Claim`] is written in a study file.
#[derive(Deserialize)]
#[serde(untagged)]
enum ClaimFile {
    Rate(f64),
    Table(BTreeMap<String, toml::Value>),
}

impl TryFrom<ClaimFile> for Claim {
    type Error = String;
    fn try_from(c: ClaimFile) -> std::result::Result<Self, String> {
        let table = match c {
            ClaimFile::Rate(rate) => {
                return Ok(Claim {
                    rate: Some(rate),
                    source: String::new(),
                });
            }
            ClaimFile::Table(t) => t,
        };
        let text = |key: &str| -> std::result::Result<Option<String>, String> {
            match table.get(key) {
                None => Ok(None),
                Some(toml::Value::String(s)) => Ok(Some(s.clone())),
                Some(v) => Err(format!(
                    "`{key}` must be a string (its source or reason), got {v}"
                )),
            }
        };
        if let Some(k) = table
            .keys()
            .find(|k| !["rate", "source", "none"].contains(&k.as_str()))
        {
            return Err(format!(
                "unknown key `{k}`: a method's threshold is a rate (0.75), {{ rate = 0.75, source = \"...\" }} or {{ none = \"why no theorem covers it here\" }}"
            ));
        }
        let rate = match table.get("rate") {
            None => None,
            Some(toml::Value::Float(v)) => Some(*v),
            Some(toml::Value::Integer(v)) => Some(*v as f64),
            Some(v) => return Err(format!("`rate` must be a number (a rate in h), got {v}")),
        };
        match (rate, text("source")?, text("none")?) {
            (Some(rate), source, None) => Ok(Claim {
                rate: Some(rate),
                source: source.unwrap_or_default(),
            }),
            (None, None, Some(why)) => Ok(Claim {
                rate: None,
                source: why,
            }),
            (Some(_), _, Some(_)) => Err(
                "give either `rate` (with its `source`) or `none` (why no theorem covers the method here), not both".into(),
            ),
            _ => Err(
                "give `rate` (with its `source`) or `none = \"why no theorem covers the method here\"`".into(),
            ),
        }
    }
}

/// The thresholds of the study's threshold quantity (`theorem` by default), each method's
/// from the theorem that states it within its hypotheses ([`Claim`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThresholdSpec {
    /// Mortar (K_h^pi): Theorem 3.1's 3/4 where it applies.
    #[serde(default)]
    pub mortar: Option<Claim>,
    /// Nts (K_h^I): Theorem 3.1's 1/2 where it applies.
    #[serde(default)]
    pub nts: Option<Claim>,
    /// LAC: not covered by Theorem 3.1; Drouet and Hild's estimate where its hypotheses
    /// hold, else `none`.
    #[serde(default)]
    pub lac: Option<Claim>,
    /// Allowed shortfall below each rate (at most 0.05).
    pub tolerance: f64,
    /// Methods that must reproduce the reference exactly (e.g. mortar on the patch scene):
    /// their `theorem` error must stay below `exact_tolerance` instead of meeting a rate.
    #[serde(default)]
    pub exact: Vec<Method>,
    /// Largest relative error allowed for the `exact` methods.
    #[serde(default = "default_exact_tolerance")]
    pub exact_tolerance: f64,
    /// The quantity the thresholds apply to (default `theorem`, Theorem 3.1's norm).
    #[serde(default = "default_threshold_quantity")]
    pub quantity: Quantity,
}

fn default_exact_tolerance() -> f64 {
    1e-9
}

fn default_quadrature() -> usize {
    super::exact_error::DEFAULT_POINTS
}

fn default_threshold_quantity() -> Quantity {
    Quantity::Theorem
}

pub use super::judge::Threshold;

impl ThresholdSpec {
    /// The entry of `method` (None where the file gives none).
    pub fn claim(&self, method: Method) -> Option<&Claim> {
        match method {
            Method::Mortar => self.mortar.as_ref(),
            Method::Nts => self.nts.as_ref(),
            Method::Lac => self.lac.as_ref(),
        }
    }

    /// The threshold of `method`'s error in the threshold quantity: exactness for the
    /// `exact` methods, else the claim's rate minus the tolerance; None where the method
    /// is reported without one (`none`, or no entry).
    pub fn of(&self, method: Method) -> Option<Threshold> {
        if self.exact.contains(&method) {
            return Some(Threshold::Exact(self.exact_tolerance));
        }
        let rate = self.claim(method)?.rate?;
        Some(Threshold::Rate(rate - self.tolerance))
    }

    /// What the study holds `method` to, for reports: "h^r (source), threshold t" or
    /// "exact to t", or "no threshold: why".
    pub fn describe(&self, method: Method) -> String {
        if self.exact.contains(&method) {
            return format!("exact to {:.0e}", self.exact_tolerance);
        }
        match self.claim(method) {
            Some(Claim {
                rate: Some(r),
                source,
            }) => {
                let from = if source.is_empty() {
                    String::new()
                } else {
                    format!(" ({source})")
                };
                format!("h^{r}{from}, threshold {:.2}", r - self.tolerance)
            }
            Some(Claim { rate: None, source }) => format!("no threshold: {source}"),
            None => "no threshold".into(),
        }
    }
}

/// A time-convergence study on a fixed mesh.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Mesh level.
    pub level: usize,
    /// Numbers of steps, increasing (each doubling halves k).
    pub steps: Vec<usize>,
    /// Steps of the reference in time (a solve on the same mesh); omitted when the study
    /// measures against the exact solution (`reference.exact`), which then is the truth in
    /// time too.
    pub reference_steps: Option<usize>,
    /// Scene of the time study (built-in name or path relative to the study file); default
    /// the study's. A scene whose fields are affine in t has no time error to measure: a
    /// variant with a t^2 part has.
    pub scene: Option<String>,
}

/// A two-size study: the two bodies refined independently (`studies::two_size`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoSizeSpec {
    /// The level a body is held at while the other is swept over `mesh.levels`: finer than
    /// every grid level (by 2 or more, so that its own error is small against the swept
    /// one's; the study measures it at (fixed, fixed) and leaves out sweep levels within 5x).
    pub fixed: usize,
    /// The bodies (surface names) that carry the constraint in turn; default the scene's
    /// slave only.
    #[serde(default)]
    pub slaves: Vec<String>,
    /// The diagonal study on the same family (its report under reports/), whose errors the
    /// grid's equal-level pairs (the same meshes) are compared with in the report.
    pub diagonal: Option<String>,
    /// Each method's exponents of its consistency error in the slave's and the master's
    /// mesh size, from the lemma that states them (none for a method no lemma covers).
    #[serde(default)]
    pub exponents: ExponentSpec,
}

/// A method's consistency exponents in (h1, h2), the slave's and the master's mesh size,
/// with their source.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Exponents {
    /// Exponent of the slave's size h1.
    pub slave: f64,
    /// Exponent of the master's size h2.
    pub master: f64,
    /// The lemma and its hypotheses.
    pub source: String,
}

/// The `[two_size.exponents]` table: one entry per method a lemma covers.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExponentSpec {
    /// Mortar (K_h^pi).
    pub mortar: Option<Exponents>,
    /// Nts (K_h^I).
    pub nts: Option<Exponents>,
    /// LAC.
    pub lac: Option<Exponents>,
}

impl ExponentSpec {
    /// The exponents of `method`, if the file gives them.
    pub fn of(&self, method: Method) -> Option<&Exponents> {
        match method {
            Method::Mortar => self.mortar.as_ref(),
            Method::Nts => self.nts.as_ref(),
            Method::Lac => self.lac.as_ref(),
        }
    }
}

/// A study file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// One line saying what the study measures.
    pub description: String,
    /// Built-in scene name or a scene file path relative to the study file.
    pub scene: String,
    /// Cones to compare: "mortar", "nts".
    pub methods: Vec<Method>,
    /// Solver: "newton" (default), "paper" or "qp".
    #[serde(default = "default_solver")]
    pub solver: SolverKind,
    /// Uniform time steps over [0, T].
    pub steps: usize,
    /// Quantities to report (subset of theorem, h1_u, l2_u, l2_stress, l2_pressure,
    /// max_penetration).
    pub quantities: Vec<Quantity>,
    /// The mesh family.
    pub mesh: MeshSpec,
    /// The reference.
    pub reference: ReferenceSpec,
    /// Rate thresholds.
    pub thresholds: ThresholdSpec,
    /// Optional time study.
    pub time: Option<TimeSpec>,
    /// A two-size study: `mesh.levels` are each body's grid levels.
    pub two_size: Option<TwoSizeSpec>,
    /// Another built-in study whose committed report's distance between the cones the
    /// report sets beside this one's, at the levels both measure (reports/COMPARE).
    #[serde(default)]
    pub compare: Option<String>,
    /// Another built-in study on the same meshes whose committed errors (reports/BESIDE)
    /// the report sets beside this one's, level by level and method by method: what this
    /// study's scene adds to that one's (the `gap` study beside regularity-unaligned's
    /// beta = 1.5).
    #[serde(default)]
    pub beside: Option<String>,
}

fn default_solver() -> SolverKind {
    SolverKind::Newton
}

/// The folder of the built-in studies.
pub fn builtin_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("studies")
}

/// Names and descriptions of the built-in studies.
pub fn list() -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(builtin_dir()) {
        for e in rd.flatten() {
            let p = e.path();
            if p.extension().is_some_and(|x| x == "toml") {
                let name = p.file_stem().unwrap().to_string_lossy().to_string();
                let desc = StudyFile::load(&p)
                    .map(|s| s.description)
                    .unwrap_or_else(|e| format!("(invalid: {e})"));
                out.push((name, desc));
            }
        }
    }
    out.sort();
    out
}

/// The study file of a built-in study name or a path, if there is one.
pub fn resolve(name_or_path: &str) -> Option<PathBuf> {
    let p = Path::new(name_or_path);
    if p.extension().is_some_and(|e| e == "toml") || p.exists() {
        return Some(p.to_path_buf());
    }
    let f = builtin_dir().join(format!("{name_or_path}.toml"));
    f.exists().then_some(f)
}

impl StudyFile {
    /// The file's quantities measured on one solution: all but the distances between the
    /// cones (which are measured between two).
    pub fn solution_quantities(&self) -> impl Iterator<Item = Quantity> + '_ {
        self.quantities.iter().copied().filter(|q| !q.is_distance())
    }

    /// Read and validate a study file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_toml(&text, path)
    }

    /// Parse and validate the text of a study file; `path` names it in errors. One check
    /// per table, in a fixed order (the first error found is the one reported).
    pub fn from_toml(text: &str, path: &Path) -> Result<Self> {
        let s: StudyFile = crate::error::parse_toml(text, path, "study file")?;
        s.check_top_level(path)?;
        s.mesh.check(path)?;
        s.reference.check(path)?;
        s.thresholds.check(path)?;
        if let Some(two) = &s.two_size {
            two.check(&s, path)?;
        }
        if let Some(ts) = &s.time {
            ts.check(s.reference.exact, path)?;
        }
        Ok(s)
    }

    /// The keys outside the tables: methods, quantities (which must hold the thresholds'
    /// quantity) and steps.
    fn check_top_level(&self, path: &Path) -> Result<()> {
        if self.methods.is_empty() {
            return bad(path, "methods", "list at least one method".into());
        }
        if !self.quantities.contains(&self.thresholds.quantity) {
            return bad(
                path,
                "quantities",
                format!(
                    "the thresholds apply to '{}': include it",
                    self.thresholds.quantity
                ),
            );
        }
        if self.steps == 0 {
            return bad(
                path,
                "steps",
                "steps must be at least 1 (the time step k must be positive)".into(),
            );
        }
        if let Some(m) = self
            .methods
            .iter()
            .find(|&&m| self.thresholds.claim(m).is_none() && !self.thresholds.exact.contains(&m))
        {
            return bad(
                path,
                &format!("thresholds.{m}"),
                format!(
                    "the study lists {m}: give the rate the theorem covering it here states, with its source ({m} = {{ rate = 0.75, source = \"...\" }}), say why none applies ({m} = {{ none = \"...\" }}), or list it in thresholds.exact"
                ),
            );
        }
        let both = self.methods.iter().any(|m| m.is_reference())
            && self.methods.iter().any(|m| !m.is_reference());
        if let Some(q) = self.quantities.iter().find(|q| q.is_distance() && !both) {
            return bad(
                path,
                "quantities",
                format!(
                    "'{q}' is the distance of a local method's solution to mortar's: list mortar and nts or lac (methods = [\"mortar\", \"nts\"]) or leave it out"
                ),
            );
        }
        if self.quantities.contains(&Quantity::BestL2Pressure) && !self.reference.exact {
            return bad(
                path,
                "quantities",
                "'best_l2_pressure' projects the exact pressure onto each level's pressure space: measure against the exact solution (reference.exact = true) or leave it out".into(),
            );
        }
        if self.quantities.contains(&Quantity::Consistency) && !self.reference.exact {
            return bad(
                path,
                "quantities",
                "'consistency' takes the exact sigma_nu: measure against the exact solution (reference.exact = true) or leave it out".into(),
            );
        }
        Ok(())
    }
}

/// The error of `field` in the study file `path`.
fn bad(path: &Path, field: &str, msg: String) -> Result<()> {
    Err(Error::input(path, field, msg))
}

impl MeshSpec {
    /// The `[mesh]` table: at least 3 increasing levels, positive sizes, and a ratio h1/h2
    /// that is no ratio of small integers.
    fn check(&self, path: &Path) -> Result<()> {
        if self.levels.len() < 3 {
            return bad(
                path,
                "mesh.levels",
                format!("a rate needs at least 3 levels, got {}", self.levels.len()),
            );
        }
        if self.levels.windows(2).any(|w| w[1] <= w[0]) {
            return bad(
                path,
                "mesh.levels",
                "levels must increase: a repeated level has the same h as its twin, and no rate between them; list each level once, in increasing order".into(),
            );
        }
        if !(self.coarsest > 0.0 && self.coarsest.is_finite()) {
            return bad(
                path,
                "mesh.coarsest",
                format!("the mesh size must be positive, got {}", self.coarsest),
            );
        }
        if let Some(v) = self
            .variants
            .iter()
            .find(|&&v| !(v > 0.0 && v.is_finite()) || v == self.coarsest)
        {
            return bad(
                path,
                "mesh.variants",
                format!("{v} is not a positive size other than mesh.coarsest; fix the value"),
            );
        }
        if !(self.ratio > 0.0 && self.ratio.is_finite()) {
            return bad(
                path,
                "mesh.ratio",
                format!("the ratio h1/h2 must be positive, got {}", self.ratio),
            );
        }
        for q in 1..=6u32 {
            for p in 1..=12u32 {
                if (self.ratio - p as f64 / q as f64).abs() < 1e-9 {
                    return bad(
                        path,
                        "mesh.ratio",
                        format!(
                            "h1/h2 = {} = {p}/{q} is a ratio of small integers: the meshes would match at many nodes; use e.g. 1.4142",
                            self.ratio
                        ),
                    );
                }
            }
        }
        Ok(())
    }
}

impl ReferenceSpec {
    /// The `[reference]` table: a solved reference at least 2 levels above the study's, an
    /// exact one with nothing to solve, and a quadrature of 1 to 32 points.
    fn check(&self, path: &Path) -> Result<()> {
        if !self.exact && self.levels_above < 2 {
            return bad(
                path,
                "reference.levels_above",
                "the reference must be at least 2 levels finer than the finest study level".into(),
            );
        }
        if self.exact && (self.levels_above != 0 || !self.parameters.is_empty()) {
            return bad(
                path,
                "reference",
                "an exact reference is not solved: remove levels_above and parameters".into(),
            );
        }
        if !(1..=32).contains(&self.quadrature) {
            return bad(
                path,
                "reference.quadrature",
                format!(
                    "give 1 to 32 Gauss points per direction, got {}",
                    self.quadrature
                ),
            );
        }
        Ok(())
    }
}

impl ThresholdSpec {
    /// The `[thresholds]` table: a tolerance in [0, 0.05].
    fn check(&self, path: &Path) -> Result<()> {
        if !(self.tolerance >= 0.0 && self.tolerance <= 0.05) {
            return bad(
                path,
                "thresholds.tolerance",
                format!(
                    "the tolerance must lie in [0, 0.05], got {}",
                    self.tolerance
                ),
            );
        }
        Ok(())
    }
}

impl TwoSizeSpec {
    /// The `[two_size]` table of `study`: a fixed level at least 2 above the grid's finest,
    /// below the reference, and no time study or mesh variants beside it.
    fn check(&self, study: &StudyFile, path: &Path) -> Result<()> {
        let (mesh, reference) = (&study.mesh, &study.reference);
        let finest = *mesh.levels.last().expect("at least 3 levels");
        if self.fixed < finest + 2 {
            return bad(
                path,
                "two_size.fixed",
                format!(
                    "the fixed level must be at least 2 above the finest grid level {finest} (its own error must be small against the swept body's), got {}",
                    self.fixed
                ),
            );
        }
        if !reference.exact && mesh.levels.last().unwrap() + reference.levels_above <= self.fixed {
            return bad(
                path,
                "reference.levels_above",
                format!(
                    "the reference must be finer than the fixed level {}: give levels_above >= {}",
                    self.fixed,
                    self.fixed + 1 - finest
                ),
            );
        }
        if study.time.is_some() || !mesh.variants.is_empty() {
            return bad(
                path,
                "two_size",
                "a two-size study has no [time] table and no mesh.variants; run those in a diagonal study".into(),
            );
        }
        Ok(())
    }
}

impl TimeSpec {
    /// The `[time]` table: at least [`super::rates::MIN_FIT_LEVELS`] increasing positive
    /// step counts, and a reference in time exactly when the study's reference is not the
    /// exact solution (`exact`).
    fn check(&self, exact: bool, path: &Path) -> Result<()> {
        if self.steps.len() < super::rates::MIN_FIT_LEVELS || self.steps.contains(&0) {
            return bad(
                path,
                "time.steps",
                format!(
                    "give at least {} positive step counts (a rate in k is fitted on 3 or more)",
                    super::rates::MIN_FIT_LEVELS
                ),
            );
        }
        if self.steps.windows(2).any(|w| w[1] <= w[0]) {
            return bad(
                path,
                "time.steps",
                "step counts must increase: a repeated count has the same k as its twin, and no rate between them".into(),
            );
        }
        match (self.reference_steps, exact) {
            (Some(_), true) => bad(
                path,
                "time.reference_steps",
                "the study measures against the exact solution, which is also the truth in time: remove reference_steps".into(),
            ),
            (None, false) => bad(
                path,
                "time.reference_steps",
                "missing: give the steps of the reference in time (a multiple of every step count), or measure against an exact solution (reference.exact = true)".into(),
            ),
            (Some(r), false) => {
                if r <= *self.steps.iter().max().unwrap() {
                    return bad(
                        path,
                        "time.reference_steps",
                        "reference_steps must be larger than every step count".into(),
                    );
                }
                if let Some(n) = self.steps.iter().find(|&&n| r % n != 0) {
                    return bad(
                        path,
                        "time.reference_steps",
                        format!(
                            "reference_steps must be a multiple of every step count ({r} is not a multiple of {n})"
                        ),
                    );
                }
                Ok(())
            }
            (None, true) => Ok(()),
        }
    }
}

impl StudyFile {
    /// gmsh parameters of the study family.
    pub fn family_parameters(&self) -> Vec<(String, f64)> {
        self.variant_parameters(self.mesh.coarsest)
    }

    /// gmsh parameters of the family whose body 1 has size `coarsest` at level 0.
    pub fn variant_parameters(&self, coarsest: f64) -> Vec<(String, f64)> {
        let mut v: Vec<(String, f64)> = self
            .mesh
            .parameters
            .iter()
            .map(|(k, v)| (k.clone(), *v))
            .collect();
        v.push((self.mesh.size_parameter_1.clone(), coarsest));
        v.push((
            self.mesh.size_parameter_2.clone(),
            coarsest / self.mesh.ratio,
        ));
        v
    }

    /// gmsh parameters of the reference family.
    pub fn reference_parameters(&self) -> Vec<(String, f64)> {
        let mut v = self.family_parameters();
        for (k, val) in &self.reference.parameters {
            match v.iter_mut().find(|(kk, _)| kk == k) {
                Some(e) => e.1 = *val,
                None => v.push((k.clone(), *val)),
            }
        }
        v
    }
}

/// A study file with its scene, read and checked.
pub struct LoadedStudy {
    /// The study's name (the file's stem): its report folder under reports/.
    pub name: String,
    /// The study file.
    pub path: PathBuf,
    /// Its text (part of every job's record key).
    pub text: String,
    /// Its contents, checked.
    pub file: StudyFile,
    /// The scene it names.
    pub scene: Scene,
    /// The time study's scene, where it is not the study's own.
    pub time_scene: Option<Scene>,
}

/// A scene named by a study file: a path relative to the study file, else a built-in name.
fn study_scene(path: &Path, name: &str) -> Result<Scene> {
    let scene_path = path.parent().unwrap_or(Path::new(".")).join(name);
    // A file only: a folder beside the study file named like its scene (an export folder)
    // is not a scene file.
    if scene_path.is_file() {
        Scene::load(&scene_path.display().to_string())
    } else {
        Scene::load(name)
    }
}

impl LoadedStudy {
    /// Read the study file `name` (a built-in name or a path) and its scenes, and check that
    /// an exact solution covers every quantity the study measures against it.
    pub fn load(name: &str) -> Result<Self> {
        let path = resolve(name).ok_or_else(|| {
            Error::input(
                name,
                "study",
                "no such study file; `study list` lists the built-in studies",
            )
        })?;
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let file = StudyFile::from_toml(&text, &path)?;
        let scene = study_scene(&path, &file.scene)?;
        let time_scene = match file.time.as_ref().and_then(|t| t.scene.as_ref()) {
            Some(name) => Some(study_scene(&path, name)?),
            None => None,
        };
        if file.quantities.contains(&Quantity::DiscreteGap) && scene.initial_gap.is_none() {
            return Err(Error::input(
                &path,
                "quantities",
                format!(
                    "discrete_gap measures the rows' initial gap, and scene '{}' gives none; add `gap = \"g0(x, y)\"` to its [contact] table or drop discrete_gap from the quantities",
                    scene.name
                ),
            ));
        }
        if file.reference.exact {
            check_covered(&file, &scene, &path)?;
            if let Some(ts) = &time_scene {
                check_time_covered(ts, &path)?;
            }
        }
        Ok(LoadedStudy {
            name: path.file_stem().unwrap().to_string_lossy().to_string(),
            path,
            text,
            file,
            scene,
            time_scene,
        })
    }

    /// Refuse, before anything is meshed past level 0, a study whose finest mesh (its finest
    /// level, or its reference level) does not fit in this machine's memory, naming this
    /// study file and the field that asks for it.
    pub fn check_memory(&self) -> Result<()> {
        let finest = *self.file.mesh.levels.last().unwrap_or(&0);
        let mut asks = vec![(finest, "mesh.levels")];
        if !self.file.reference.exact {
            asks.push((self.reference_level(), "reference.levels_above"));
        }
        let params = self.file.family_parameters();
        for (level, field) in asks {
            if let Some(message) = crate::case::memory_refusal_of(&self.scene, &params, level)? {
                return Err(Error::input(&self.path, field, message));
            }
        }
        Ok(())
    }

    /// The reference level: the finest study level plus `levels_above`.
    pub fn reference_level(&self) -> usize {
        self.file.mesh.levels.last().unwrap() + self.file.reference.levels_above
    }
}

/// What the exact solution must give for quantity `q`.
pub fn needs(q: Quantity) -> &'static [Field] {
    match q {
        Quantity::Theorem => &[Field::Displacement, Field::Stress],
        Quantity::H1U | Quantity::L2U => &[Field::Displacement],
        // The truth has no penetration; without an exact displacement the study's own
        // largest displacement makes it relative.
        Quantity::MaxPenetration | Quantity::L2Penetration => &[],
        Quantity::L2Stress => &[Field::Stress],
        Quantity::L2Pressure
        | Quantity::BestL2Pressure
        | Quantity::ContactEdge
        | Quantity::PressureResultant
        | Quantity::PressureWeighted
        | Quantity::PressureOscillation => &[Field::Pressure],
        Quantity::BandStress => &[Field::Stress],
        // Relative to the truth's theorem norm.
        Quantity::Consistency | Quantity::ConeDistance => &[Field::Displacement, Field::Stress],
        Quantity::ConeDistanceH1U => &[Field::Displacement],
        Quantity::ConeDistanceL2Stress | Quantity::ConeDistanceBandStress => &[Field::Stress],
        Quantity::ConeDistanceL2Pressure => &[Field::Pressure],
        Quantity::ConeDistanceNormalJump => &[],
        // The scene's gap against the rows': no field of the solution.
        Quantity::DiscreteGap => &[],
    }
}

/// Every quantity of an exact study must be covered by the scene's exact solution.
fn check_covered(file: &StudyFile, scene: &Scene, path: &Path) -> Result<()> {
    let Some(exact) = scene.exact.as_deref() else {
        return Err(Error::input(
            path,
            "reference.exact",
            format!(
                "scene '{}' gives no exact solution; add an [exact] table to {} or measure against a reference solve (reference.exact = false)",
                scene.name,
                scene.file.display()
            ),
        ));
    };
    for &q in &file.quantities {
        if let Some(f) = needs(q).iter().find(|f| !exact.gives(**f)) {
            return Err(Error::input(
                path,
                "quantities",
                format!(
                    "quantity '{q}' needs the exact solution's {} (`{}` in the scene's [exact] table), which scene '{}' does not give; add it there or remove '{q}'",
                    &f.key()["exact.".len()..],
                    f.key(),
                    scene.name
                ),
            ));
        }
    }
    Ok(())
}

/// The time study measures the theorem norm: its scene's exact solution must give the
/// displacement and the stress.
fn check_time_covered(scene: &Scene, path: &Path) -> Result<()> {
    let covered = scene
        .exact
        .as_deref()
        .is_some_and(|e| needs(Quantity::Theorem).iter().all(|f| e.gives(*f)));
    if covered {
        return Ok(());
    }
    Err(Error::input(
        path,
        "time.scene",
        format!(
            "scene '{}' gives no exact displacement and stress, which the time study measures against (reference.exact = true); add them to its [exact] table or choose another scene",
            scene.name
        ),
    ))
}

/// Where a study's numbers come from: gmsh, the .geo, the solver, the cores, the commit.
pub fn provenance(
    study: &LoadedStudy,
    mesh: &crate::mesh::gmsh::GeneratedMesh,
) -> BTreeMap<String, String> {
    let geo = study.scene.geo.file_name().unwrap().to_string_lossy();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    BTreeMap::from([
        ("gmsh".into(), mesh.gmsh_version.clone()),
        ("geo".into(), format!("{geo} (sha256 {})", mesh.geo_hash)),
        (
            "solver".into(),
            format!(
                "{} (tolerance {:.0e})",
                study.file.solver,
                Settings::default().tol
            ),
        ),
        ("cores".into(), cores.to_string()),
        ("commit".into(), crate::verify::commit()),
    ])
}
