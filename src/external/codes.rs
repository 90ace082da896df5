//! `codes`: the report of what real contact codes converge at (reports/codes), assembled
//! from `grade` reports, one per problem and code (`GRADES/PROBLEM/CODE/`), each graded beside
//! this project's mortar and nts on the same meshes. The report leads with which cone each
//! code sides with where the cones differ, and says where the levels cannot tell them apart.

use super::checks::CheckRecord;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::verify::judge::AsymptoteRow;
use crate::verify::quantity::Quantity;
use crate::verify::rates::{Verdict, short_text};
use crate::verify::table::{ErrorRecord, MethodLabel, RateRecord, methods_in_order, read};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One row of reports/codes/errors.csv: one method's error in one quantity on one level of
/// one problem (the cones once per problem).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CodeError {
    pub study: String,
    pub method: MethodLabel,
    pub level: usize,
    pub h: f64,
    pub dofs: usize,
    pub quantity: Quantity,
    pub error: f64,
}

/// One row of reports/codes/rates.csv: what one method's errors in one quantity support on
/// one problem.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CodeRate {
    pub study: String,
    pub method: MethodLabel,
    pub quantity: Quantity,
    pub rate: Option<f64>,
    pub stderr: Option<f64>,
    pub levels_used: String,
    pub successive: String,
    pub verdict: Verdict,
    pub last_rate: Option<f64>,
    /// What the errors give, in a few characters ([`short_text`]).
    pub reads: String,
}

/// One row of reports/codes/checks.csv: a graded level's checks.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CodeCheck {
    pub study: String,
    pub code: String,
    pub level: usize,
    pub error: f64,
    pub residual: f64,
    pub residual_limit: f64,
    pub normal_imbalance: Option<f64>,
    pub tangential: Option<f64>,
    pub pulling: Option<f64>,
    pub pressure_ratio: Option<f64>,
    pub verdict: String,
}

/// One row of reports/codes/asymptotes.csv: a method read against its distance to mortar.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CodeAsymptote {
    pub study: String,
    pub method: MethodLabel,
    pub quantity: Quantity,
    pub distance_verdict: Verdict,
    pub asymptotic_rate: Option<f64>,
    pub asymptotic_stderr: Option<f64>,
    pub distance_sets_rate: Option<bool>,
    pub finest_ratio: Option<f64>,
}

/// The grade reports of one problem.
struct Problem {
    study: String,
    codes: Vec<String>,
    errors: Vec<CodeError>,
    rates: Vec<CodeRate>,
    checks: Vec<CodeCheck>,
    asymptotes: Vec<CodeAsymptote>,
}

/// The folders under `dir`, sorted.
fn folders(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| {
            Error::input(
                dir,
                "--grades",
                format!(
                    "cannot read the folder ({e}); pass the folder of PROBLEM/CODE grade reports"
                ),
            )
        })?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    out.sort();
    Ok(out)
}

fn name(p: &Path) -> String {
    p.file_name()
        .map_or(String::new(), |f| f.to_string_lossy().to_string())
}

impl Problem {
    /// The grade reports `dir/CODE/` of one problem: each code's rows, the cones' once.
    fn read(dir: &Path) -> Result<Self> {
        let study = name(dir);
        let mut p = Problem {
            study: study.clone(),
            codes: Vec::new(),
            errors: Vec::new(),
            rates: Vec::new(),
            checks: Vec::new(),
            asymptotes: Vec::new(),
        };
        let dirs = folders(dir)?;
        // The cones' rows once, from the report that grades the most levels.
        let mut cones_from = 0;
        let mut most = 0;
        for (i, d) in dirs.iter().enumerate() {
            let errors: Vec<ErrorRecord> = read(&d.join("errors.csv"))?;
            let mut levels: Vec<usize> = errors.iter().map(|r| r.level).collect();
            levels.sort();
            levels.dedup();
            if levels.len() > most {
                (most, cones_from) = (levels.len(), i);
            }
        }
        for (i, code_dir) in dirs.iter().enumerate() {
            let code = name(code_dir);
            let first = i == cones_from;
            let keep = |m: &MethodLabel| m.name() == code || (first && m.cone().is_some());
            let errors: Vec<ErrorRecord> = read(&code_dir.join("errors.csv"))?;
            p.errors.extend(
                errors
                    .into_iter()
                    .filter(|r| keep(&r.method))
                    .map(|r| CodeError {
                        study: study.clone(),
                        method: r.method,
                        level: r.level,
                        h: r.h,
                        dofs: r.dofs,
                        quantity: r.quantity,
                        error: r.error,
                    }),
            );
            let rates: Vec<RateRecord> = read(&code_dir.join("rates.csv"))?;
            p.rates.extend(
                rates
                    .into_iter()
                    .filter(|r| keep(&r.method))
                    .map(|r| CodeRate {
                        study: study.clone(),
                        reads: short_text(r.verdict, r.rate, r.last_rate),
                        method: r.method,
                        quantity: r.quantity,
                        rate: r.rate,
                        stderr: r.stderr,
                        levels_used: r.levels_used,
                        successive: r.successive,
                        verdict: r.verdict,
                        last_rate: r.last_rate,
                    }),
            );
            let checks: Vec<CheckRecord> = read(&code_dir.join("checks.csv"))?;
            p.checks.extend(checks.into_iter().map(|c| CodeCheck {
                study: study.clone(),
                code: code.clone(),
                level: c.level,
                error: c.error,
                residual: c.residual,
                residual_limit: c.residual_limit,
                normal_imbalance: c.normal_imbalance,
                tangential: c.tangential,
                pulling: c.pulling,
                pressure_ratio: c.pressure_ratio,
                verdict: c.verdict,
            }));
            let asymptotes = code_dir.join("asymptotes.csv");
            if asymptotes.exists() {
                let rows: Vec<AsymptoteRow> = read(&asymptotes)?;
                p.asymptotes
                    .extend(
                        rows.into_iter()
                            .filter(|r| keep(&r.method))
                            .map(|r| CodeAsymptote {
                                study: study.clone(),
                                method: r.method,
                                quantity: r.quantity,
                                distance_verdict: r.distance_verdict,
                                asymptotic_rate: r.asymptotic_rate,
                                asymptotic_stderr: r.asymptotic_stderr,
                                distance_sets_rate: r.distance_sets_rate,
                                finest_ratio: r.finest_ratio,
                            }),
                    );
            }
            p.codes.push(code);
        }
        Ok(p)
    }

    /// The key quantity: the theorem norm, or l2_stress where no displacement is graded.
    fn key(&self) -> Quantity {
        key_of(self.errors.iter().map(|r| r.quantity))
    }

    fn methods(&self) -> Vec<MethodLabel> {
        methods_in_order(self.errors.iter().map(|r| &r.method))
    }

    fn finest(&self, m: &MethodLabel, q: Quantity) -> Option<&CodeError> {
        self.errors
            .iter()
            .filter(|r| &r.method == m && r.quantity == q)
            .max_by_key(|r| r.level)
    }

    fn rate(&self, m: &MethodLabel, q: Quantity) -> Option<&CodeRate> {
        self.rates
            .iter()
            .find(|r| &r.method == m && r.quantity == q)
    }

    fn levels(&self) -> String {
        let levels: Vec<usize> = self.errors.iter().map(|r| r.level).collect();
        format!(
            "{}-{}",
            levels.iter().min().unwrap_or(&0),
            levels.iter().max().unwrap_or(&0)
        )
    }
}

/// A problem's key quantity among the quantities it measures: the theorem norm, or
/// l2_stress where no displacement is graded (patch: no theorem-norm rows).
fn key_of(mut quantities: impl Iterator<Item = Quantity>) -> Quantity {
    match quantities.any(|q| q == Quantity::Theorem) {
        true => Quantity::Theorem,
        false => Quantity::L2Stress,
    }
}

/// Below this relative error a key error is round-off (the patch test's): exact.
const EXACT: f64 = 1e-9;

/// Errors within this ratio of each other (5 %) cannot tell the cones apart at one level.
const INDISTINCT: f64 = 1.05;

/// What a code's key error at its finest level says of the cones on that level.
enum Side {
    /// The code or the cones lack the level.
    Unknown,
    /// Mortar is exact there (the patch test): the exact cones, whether the code is too, and
    /// its error over each inexact cone's.
    MortarExact {
        exact: Vec<Method>,
        code_exact: bool,
        ratios: Vec<(Method, f64)>,
    },
    /// Every cone within [`INDISTINCT`] of the others.
    Indistinct {
        level: usize,
        ratios: Vec<(Method, f64)>,
    },
    /// The cones nearest the code's error in ratio (the nearest and any within
    /// [`INDISTINCT`] of it), with the code's error over each cone's.
    Nearest {
        cones: Vec<Method>,
        level: usize,
        ratios: Vec<(Method, f64)>,
    },
}

/// Which cone `code`'s key error at its finest level is nearest (in ratio) on that level,
/// or that the cones are within 5 % of each other there; where mortar is exact (the patch
/// test), whether the code is too.
fn side(p: &Problem, code: &MethodLabel) -> Side {
    let key = p.key();
    let Some(finest) = p.finest(code, key) else {
        return Side::Unknown;
    };
    let cones: Vec<(Method, f64)> = p
        .methods()
        .iter()
        .filter_map(|m| m.cone())
        .filter_map(|m| {
            let e = p.errors.iter().find(|r| {
                r.method == MethodLabel::Cone(m) && r.quantity == key && r.level == finest.level
            })?;
            Some((m, e.error))
        })
        .collect();
    let Some(&(_, mortar)) = cones.iter().find(|c| c.0.is_reference()) else {
        return Side::Unknown;
    };
    let x = finest.error;
    let level = finest.level;
    if mortar <= EXACT {
        return Side::MortarExact {
            exact: cones.iter().filter(|c| c.1 <= EXACT).map(|c| c.0).collect(),
            code_exact: x <= EXACT,
            ratios: cones
                .iter()
                .filter(|c| c.1 > EXACT)
                .map(|&(m, e)| (m, x / e))
                .collect(),
        };
    }
    let ratios: Vec<(Method, f64)> = cones.iter().map(|&(m, e)| (m, x / e)).collect();
    let far = |a: f64, b: f64| (a / b).ln().abs();
    let within = |a: f64, b: f64| far(a, b) < INDISTINCT.ln();
    if cones.iter().all(|a| cones.iter().all(|b| within(a.1, b.1))) {
        return Side::Indistinct { level, ratios };
    }
    let mut by_distance = cones.clone();
    by_distance.sort_by(|a, b| far(x, a.1).total_cmp(&far(x, b.1)));
    let nearest = by_distance[0].1;
    Side::Nearest {
        cones: by_distance
            .iter()
            .filter(|c| within(c.1, nearest))
            .map(|c| c.0)
            .collect(),
        level,
        ratios,
    }
}

/// "1.002 times mortar's, 3.1 times nts's": the code's error over each cone's.
fn ratios_text(ratios: &[(Method, f64)]) -> String {
    // Three decimals, or three digits where the ratio is small.
    let parts: Vec<String> = ratios
        .iter()
        .map(|(m, r)| match *r < 0.01 {
            true => format!("{r:.2e} times {m}'s"),
            false => format!("{r:.3} times {m}'s"),
        })
        .collect();
    parts.join(", ")
}

impl Side {
    /// The table cell.
    fn cell(&self) -> String {
        match self {
            Side::Unknown => "-".into(),
            Side::MortarExact {
                exact,
                code_exact: true,
                ..
            } => format!("exact, as {}", names(exact)),
            Side::MortarExact {
                exact,
                code_exact: false,
                ratios,
            } => {
                format!(
                    "not exact, unlike {} ({})",
                    names(exact),
                    ratios_text(ratios)
                )
            }
            Side::Indistinct { level, ratios } => format!(
                "cones within 5% of each other at level {level} ({})",
                ratios_text(ratios)
            ),
            Side::Nearest {
                cones,
                level,
                ratios,
            } => format!(
                "{} ({} at level {level})",
                names(cones),
                ratios_text(ratios)
            ),
        }
    }
}

/// "mortar", "mortar and lac".
fn names(cones: &[Method]) -> String {
    let v: Vec<String> = cones.iter().map(|m| m.to_string()).collect();
    v.join(" and ")
}

/// Assemble the report of the grade reports under `grades` into `out`, all or nothing.
pub fn codes_report(grades: &Path, out: &Path) -> Result<()> {
    let problems = folders(grades)?
        .iter()
        .map(|d| Problem::read(d))
        .collect::<Result<Vec<_>>>()?;
    if problems.is_empty() {
        return Err(Error::input(
            grades,
            "--grades",
            "holds no PROBLEM/CODE grade reports; run the workflow (`snakemake --cores 2`, workflow/Snakefile)",
        ));
    }
    write_folder(out, |d| {
        let errors: Vec<&CodeError> = problems.iter().flat_map(|p| &p.errors).collect();
        write(d, "errors.csv", &csv_bytes(&errors)?)?;
        let rates: Vec<&CodeRate> = problems.iter().flat_map(|p| &p.rates).collect();
        write(d, "rates.csv", &csv_bytes(&rates)?)?;
        let checks: Vec<&CodeCheck> = problems.iter().flat_map(|p| &p.checks).collect();
        write(d, "checks.csv", &csv_bytes(&checks)?)?;
        let asymptotes: Vec<&CodeAsymptote> = problems.iter().flat_map(|p| &p.asymptotes).collect();
        write(d, "asymptotes.csv", &csv_bytes(&asymptotes)?)?;
        for p in &problems {
            plot_problem(p, d)?;
        }
        write(d, "README.md", readme(&problems).as_bytes())
    })
}

/// The key error against h of every method on one problem, `error_vs_h_STUDY.png`.
fn plot_problem(p: &Problem, d: &Path) -> Result<()> {
    let key = p.key();
    let series: Vec<Series> = p
        .methods()
        .iter()
        .enumerate()
        .map(|(i, m)| Series {
            label: format!(
                "{m}: {}",
                p.rate(m, key).map_or("-".into(), |r| r.reads.clone())
            ),
            points: p
                .errors
                .iter()
                .filter(|r| &r.method == m && r.quantity == key)
                .map(|r| (r.h, r.error))
                .collect(),
            markers: true,
            line: true,
            color: i,
            thin: m.cone().is_some(),
            shape: None,
        })
        .collect();
    plot::loglog(
        &d.join(format!("error_vs_h_{}.png", p.study)),
        &format!("{}: error against h", p.study),
        "h (max element diameter)",
        &format!("relative error ({key})"),
        &series,
        &[(0.5, "1/2"), (1.0, "1")],
    )
}

/// The README: per problem, each code's key rate, the cone it sides with, its contact
/// quantities and its distance to mortar.
fn readme(problems: &[Problem]) -> String {
    let mut doc = Doc::new();
    doc.heading(1, "What real contact codes converge at");
    doc.paragraph(SETUP).list(lead(problems));
    let flagged: Vec<String> = problems
        .iter()
        .flat_map(|p| &p.checks)
        .filter(|c| c.verdict != "converged")
        .map(|c| format!("{} {} level {}", c.study, c.code, c.level))
        .collect();
    doc.paragraph(match flagged.is_empty() {
        true => format!(
            "Every graded level passed grade's checks ({} levels: equilibrium residual, Gamma_C's forces, the pressure's resultant; checks.csv).",
            problems.iter().map(|p| p.checks.len()).sum::<usize>()
        ),
        false => format!("**Not converged, no rate claimed**: {}.", flagged.join(", ")),
    });
    for p in problems {
        section(&mut doc, p);
    }
    doc.heading(2, "How it is made");
    doc.paragraph("The workflow in workflow/Snakefile (`snakemake --cores 2`; docs/verify-your-code.md#the-workflow) exports each problem, solves each level with examples/grade_getfem.py (both bricks) and examples/grade_kratos.py, grades every solution with `contact-rates grade` beside this project's cones, and assembles this folder with `contact-rates codes --grades DIR --out reports/codes`; it remakes only what changed. errors.csv, rates.csv, checks.csv and asymptotes.csv hold every row, with the problem in the `study` column.");
    doc.finish()
}

/// The codes graded and how (the set-up, not a finding: the findings follow from the rows).
const SETUP: &str = "Solvers of other projects, on the problems `export` writes: GetFEM 5.4's integral (mortar-type) and nodal (node-on-segment) contact bricks, and Kratos 10.4's mortar contact by the augmented Lagrangian method. Each is read beside this project's cones (mortar K_h^pi, nts K_h^I and lac, the local average contact) on the same meshes, by the same judge.";

/// The lead, from the rows: per problem which cone each code sides with at its finest level
/// (or that the cones cannot be told apart there), and where a distance to mortar has a
/// rate the judge supports.
fn lead(problems: &[Problem]) -> Vec<String> {
    let mut out = Vec::new();
    for p in problems {
        let key = p.key();
        let codes: Vec<MethodLabel> = p
            .methods()
            .into_iter()
            .filter(|m| m.cone().is_none())
            .collect();
        let sides: Vec<(MethodLabel, Side)> =
            codes.iter().map(|c| (c.clone(), side(p, c))).collect();
        let line = match sides.first().map(|s| &s.1) {
            Some(Side::Indistinct { level, .. })
                if sides.iter().all(|s| matches!(s.1, Side::Indistinct { .. })) =>
            {
                format!(
                    "`{}` ({key}): the cones are within 5% of each other at level {level}, so no code can be told apart there",
                    p.study
                )
            }
            _ => {
                let parts: Vec<String> = sides
                    .iter()
                    .map(|(c, s)| match s {
                        Side::Nearest {
                            cones,
                            level,
                            ratios,
                        } => format!(
                            "{c} sides with {} at level {level} ({})",
                            names(cones),
                            ratios_text(ratios)
                        ),
                        other => format!("{c}: {}", other.cell()),
                    })
                    .collect();
                format!("`{}` ({key}): {}", p.study, parts.join("; "))
            }
        };
        out.push(line);
    }
    let mut supported = Vec::new();
    for p in problems {
        let Some(distance) = crate::verify::judge::DECOMPOSED
            .iter()
            .find(|(q, _)| *q == p.key())
            .map(|(_, d)| *d)
        else {
            continue;
        };
        let rated: Vec<String> = p
            .methods()
            .iter()
            .filter_map(|m| {
                let r = p.rate(m, distance)?;
                let (rate, se) = (r.rate?, r.stderr?);
                (r.verdict == Verdict::Fitted).then(|| format!("{m} {rate:.3} ± {se:.3}"))
            })
            .collect();
        if !rated.is_empty() {
            supported.push(format!("`{}` ({})", p.study, rated.join(", ")));
        }
    }
    out.push(match supported.is_empty() {
        true => "No distance to mortar in the key quantity has a rate the judge supports on these levels.".into(),
        false => format!(
            "The distance to mortar in the key quantity has a rate the judge supports (fitted) in {}; nowhere else on these levels (rates.csv, `cone_distance`, `cone_distance_l2_stress` for patch).",
            supported.join("; ")
        ),
    });
    out
}

fn section(doc: &mut Doc, p: &Problem) {
    let key = p.key();
    doc.heading(2, format!("{} (levels {})", p.study, p.levels()));
    let mortar_exact = p
        .finest(&MethodLabel::Cone(crate::contact::Method::reference()), key)
        .is_some_and(|r| r.error <= EXACT);
    let mut table = Table::new([
        "method",
        "levels",
        &format!("{key} rate (verdict)"),
        "finest error",
        "sides with",
        "l2_pressure (finest, reads)",
        "distance to mortar / e_mortar (finest)",
        "distance's verdict, asymptotic rate",
    ]);
    for m in p.methods() {
        let rate = p.rate(&m, key);
        let pressure = p.finest(&m, Quantity::L2Pressure).map_or("-".into(), |r| {
            format!(
                "{:.3e}, {}",
                r.error,
                p.rate(&m, Quantity::L2Pressure)
                    .map_or("-".into(), |r| r.reads.clone())
            )
        });
        let asymptote = p
            .asymptotes
            .iter()
            .find(|a| a.method == m && a.quantity == key);
        let levels: Vec<usize> = p
            .errors
            .iter()
            .filter(|r| r.method == m && r.quantity == key)
            .map(|r| r.level)
            .collect();
        table.row([
            format!("`{m}`"),
            format!(
                "{}-{}",
                levels.iter().min().unwrap_or(&0),
                levels.iter().max().unwrap_or(&0)
            ),
            rate.map_or("-".into(), |r| match (r.verdict, r.rate, r.stderr) {
                (Verdict::Fitted, Some(v), Some(s)) => format!("{v:.3} ± {s:.3} (fitted)"),
                _ => format!("{} ({})", r.reads, r.verdict.name()),
            }),
            p.finest(&m, key)
                .map_or("-".into(), |r| format!("{:.4e}", r.error)),
            match m.cone() {
                Some(_) => "-".into(),
                None => side(p, &m).cell(),
            },
            pressure,
            match mortar_exact {
                true => "- (mortar exact)".into(),
                false => asymptote
                    .and_then(|a| a.finest_ratio)
                    .map_or("-".into(), |r| format!("{r:.3}")),
            },
            asymptote.map_or("-".into(), |a| {
                format!(
                    "{}{}",
                    a.distance_verdict.name(),
                    a.asymptotic_rate
                        .map_or(String::new(), |r| format!(", tends to {r:.3}"))
                )
            }),
        ]);
    }
    doc.table(&table);
    doc.image(
        &format!("{}: error against h", p.study),
        &format!("error_vs_h_{}.png", p.study),
    );
}

/// The codes report's part of docs/results.md, from reports/codes/rates.csv: per problem,
/// what each method's key error supports (the theorem norm, l2_stress where no
/// displacement is graded), in a few characters ([`short_text`]).
pub fn results_section(reports: &Path) -> Result<String> {
    let path = reports.join("codes").join("rates.csv");
    let rates: Vec<CodeRate> = read(&path)?;
    let methods = methods_in_order(rates.iter().map(|r| &r.method));
    let mut studies: Vec<&str> = Vec::new();
    for r in &rates {
        if !studies.contains(&r.study.as_str()) {
            studies.push(&r.study);
        }
    }
    let mut doc = Doc::new();
    doc.heading(
        2,
        format!("[`codes`]({}/codes/README.md): GetFEM and Kratos graded beside the cones on the exported problems", crate::report::markdown::DOCS_REPORTS),
    )
    .paragraph("Each problem's key error (Theorem 3.1's norm; `l2_stress` on patch, whose exact solution has no displacement) judged for each code and each cone on the same meshes (reports/codes/rates.csv, column `reads`); the codes report leads with which cone each code sides with.");
    let mut header = vec!["problem".to_string(), "quantity".to_string()];
    header.extend(methods.iter().map(|m| m.to_string()));
    let mut table = Table::new(header);
    for study in studies {
        let key = key_of(
            rates
                .iter()
                .filter(|r| r.study == study)
                .map(|r| r.quantity),
        );
        let mut row = vec![format!("`{study}`"), format!("`{key}`")];
        row.extend(methods.iter().map(|m| {
            rates
                .iter()
                .find(|r| r.study == study && &r.method == m && r.quantity == key)
                .map_or("-".into(), |r| r.reads.clone())
        }));
        table.row(row);
    }
    doc.table(&table);
    Ok(doc.finish())
}
