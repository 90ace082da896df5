//! Reports: CSV tables, PNG plots and a README.md per study, written into a temporary folder
//! and swapped in whole, so a failed run leaves the previous report intact.

pub mod paper;
pub mod plot;

use crate::error::{Error, Result};
use crate::io::csv_bytes;
use crate::study::{RateRow, StudyResult};
use plot::{Panel, Series};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The folder of all reports: `reports/` in the crate.
pub fn reports_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// Write `files` (name, bytes) and `pngs` (drawn by closures into the folder) as the folder
/// `dir`, replacing it atomically.
/// Check, before any computing, that the report folder `dir` can be written (its parent is
/// created when missing): a study that runs for minutes must not fail at the end.
pub fn check_writable(dir: &Path) -> Result<()> {
    let parent = dir.parent().unwrap_or(Path::new("."));
    let fix = "pass --out with a writable folder, or make this one writable";
    std::fs::create_dir_all(parent).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!("cannot create it ({e}); {fix}"),
        )
    })?;
    if dir.exists() && !dir.is_dir() {
        return Err(Error::input(
            dir,
            "reports folder",
            format!("exists and is not a folder; {fix}"),
        ));
    }
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    let probe = parent.join(format!(".{name}.probe-{}", std::process::id()));
    std::fs::create_dir(&probe).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!("cannot write here ({e}); {fix}"),
        )
    })?;
    let _ = std::fs::remove_dir(&probe);
    Ok(())
}

/// Write a report folder atomically: fill a temporary sibling, then swap it in, so a failed
/// run leaves the previous report intact.
pub fn write_folder(dir: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let parent = dir.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!(
                "cannot write here ({e}); make the folder writable or run from a writable checkout"
            ),
        )
    })?;
    if let Err(e) = fill(&tmp) {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    if dir.exists() {
        std::fs::rename(dir, &old).map_err(|e| Error::io(dir, e))?;
    }
    std::fs::rename(&tmp, dir).map_err(|e| Error::io(dir, e))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let p = dir.join(name);
    std::fs::write(&p, bytes).map_err(|e| Error::io(p, e))
}

fn fmt_rate(r: &RateRow) -> String {
    if r.rate.is_finite() {
        format!("{:.3} ± {:.3}", r.rate, r.stderr)
    } else {
        "n/a".into()
    }
}

/// Write the report of a study into `dir` (normally reports/NAME).
pub fn write_study(res: &StudyResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "errors.csv", &csv_bytes(&res.errors)?)?;
        write(d, "rates.csv", &csv_bytes(&res.rates)?)?;
        write(d, "levels.csv", &csv_bytes(&res.levels)?)?;
        write(d, "pressure.csv", &csv_bytes(&res.pressure)?)?;
        write(d, "gap.csv", &csv_bytes(&res.gap)?)?;
        plots(res, d)?;
        write(d, "README.md", readme(res).as_bytes())
    })
}

fn methods(res: &StudyResult) -> Vec<String> {
    res.file.methods.clone()
}

fn plots(res: &StudyResult, d: &Path) -> Result<()> {
    // Error against h for the theorem quantity, with fitted lines.
    let mut series = Vec::new();
    for (i, m) in methods(res).iter().enumerate() {
        let rows: Vec<_> = res
            .errors
            .iter()
            .filter(|r| &r.method == m && r.quantity == "theorem")
            .collect();
        let rate = res
            .rates
            .iter()
            .find(|r| &r.method == m && r.quantity == "theorem")
            .unwrap();
        let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.h, r.error)).collect();
        series.push(Series {
            label: format!("{m} (theorem norm)"),
            points: pts,
            markers: true,
            line: false,
            color: i,
            thin: false,
        });
        // Fitted line over the levels used.
        let used: Vec<_> = rows
            .iter()
            .filter(|r| {
                rate.levels_used
                    .split(' ')
                    .any(|l| l == r.level.to_string())
            })
            .collect();
        if rate.rate.is_finite() && used.len() >= 2 {
            let fit = crate::study::rates::fit(
                &used.iter().map(|r| r.h).collect::<Vec<_>>(),
                &used.iter().map(|r| r.error).collect::<Vec<_>>(),
            )
            .unwrap();
            let hs = [
                used.iter().map(|r| r.h).fold(f64::INFINITY, f64::min),
                used.iter().map(|r| r.h).fold(0.0, f64::max),
            ];
            series.push(Series {
                label: format!("{m} fit: slope {:.2} ± {:.2}", fit.rate, fit.stderr),
                points: hs
                    .iter()
                    .map(|&h| (h, (fit.intercept + fit.rate * h.ln()).exp()))
                    .collect(),
                markers: false,
                line: true,
                color: i,
                thin: false,
            });
        }
    }
    for (i, m) in methods(res).iter().enumerate() {
        let pts: Vec<(f64, f64)> = res
            .errors
            .iter()
            .filter(|r| &r.method == m && r.quantity == "l2_pressure")
            .map(|r| (r.h, r.error))
            .collect();
        if !pts.is_empty() {
            series.push(Series {
                label: format!("{m} (contact pressure, L2(Gamma_C))"),
                points: pts,
                markers: true,
                line: true,
                color: i,
                thin: true,
            });
        }
    }
    plot::loglog(
        &d.join("error_vs_h.png"),
        &format!("{}: error against h", res.name),
        "h (max element diameter)",
        "relative error (theorem norm)",
        &series,
        &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
    )?;
    // Error against wall time.
    let series: Vec<Series> = methods(res)
        .iter()
        .enumerate()
        .map(|(i, m)| Series {
            label: format!("{m}"),
            points: res
                .errors
                .iter()
                .filter(|r| &r.method == m && r.quantity == "theorem")
                .map(|r| (r.wall_s.max(1e-4), r.error))
                .collect(),
            markers: true,
            line: true,
            color: i,
            thin: false,
        })
        .collect();
    plot::loglog(
        &d.join("error_vs_time.png"),
        &format!(
            "{}: error against solve time ({} solver)",
            res.name, res.file.solver
        ),
        "wall time of the solve (s)",
        "relative error (theorem norm)",
        &series,
        &[],
    )?;
    // Profiles along Gamma_C at T.
    for (name, data, ylabel) in [
        ("pressure", &res.pressure, "contact pressure (force/length)"),
        ("gap", &res.gap, "normal gap -[u.nu] (length)"),
    ] {
        let mut labels: Vec<String> = methods(res);
        labels.push("reference".into());
        let series: Vec<Series> = labels
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let mut pts: Vec<(f64, f64)> = data
                    .iter()
                    .filter(|p| &p.label == l)
                    .map(|p| (p.x, p.value))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                pts.dedup_by(|a, b| a.0 == b.0);
                Series {
                    label: if l == "reference" {
                        format!("reference (level {}, matching)", res.reference.0)
                    } else {
                        format!("{l} (level {})", res.profile_level)
                    },
                    points: pts,
                    markers: l != "reference",
                    line: true,
                    color: if l == "reference" { 2 } else { i },
                    thin: l == "reference",
                }
            })
            .collect();
        plot::lines(
            &d.join(format!("{name}.png")),
            &format!(
                "{}: {name} along Gamma_C at T = {}",
                res.name, res.scene.final_time
            ),
            "x along Gamma_C",
            ylabel,
            &series,
        )?;
    }
    // Deformed meshes coloured by von Mises.
    let panels: Vec<Panel> = res
        .deformed
        .iter()
        .map(|m| Panel {
            title: format!("{} (level {})", m.label, res.profile_level),
            triangles: m.triangles.clone(),
            values: m.von_mises.clone(),
            body: m.body.clone(),
            highlight: Vec::new(),
        })
        .collect();
    if !panels.is_empty() {
        let mag = res.deformed[0].magnification;
        plot::field_panels(
            &d.join("von_mises.png"),
            &format!(
                "{}: von Mises stress at T = {}, displacements magnified x{mag:.1}",
                res.name, res.scene.final_time
            ),
            "von Mises stress",
            &panels,
        )?;
    }
    Ok(())
}

fn readme(res: &StudyResult) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Study `{}`\n\n{}\n", res.name, res.description);
    let _ = writeln!(s, "Scene `{}`: {}\n", res.scene.name, res.scene.description);
    let _ = writeln!(
        s,
        "Regenerate with `cargo run --release -- study {}` ({:.0} s on this machine, {} cores). Solver `{}`, {} uniform time steps over [0, {}].\n",
        res.name,
        res.wall_s,
        res.provenance.get("cores").cloned().unwrap_or_default(),
        res.file.solver,
        res.file.steps,
        res.scene.final_time
    );
    let _ = writeln!(s, "![error against h](error_vs_h.png)\n");
    let _ = writeln!(
        s,
        "## Rates\n\nLeast-squares slope of log(error) against log(h) over the levels used (± standard error), rate against dofs, and successive rates between neighbouring levels. The `theorem` quantity is max_n (||u - u_ref||_H1 + ||sigma - sigma_ref||_L2) over both bodies, relative to the reference's; Theorem 3.1 predicts h^(3/4) for mortar (K_h^pi) and h^(1/2) for nts (K_h^I).\n"
    );
    let _ = writeln!(
        s,
        "| method | quantity | rate in h | levels used | rate in dofs | successive | threshold | pass |\n|---|---|---|---|---|---|---|---|"
    );
    for r in &res.rates {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.method,
            r.quantity,
            fmt_rate(r),
            r.levels_used,
            crate::io::fmt3(r.rate_dofs),
            r.successive,
            r.threshold
                .map(|t| if t < 0.01 {
                    format!("error <= {t:.0e}")
                } else {
                    format!("rate >= {t:.2}")
                })
                .unwrap_or_default(),
            r.pass
                .map(|p| if p { "yes" } else { "**no**" })
                .unwrap_or("")
        );
    }
    let _ = writeln!(
        s,
        "\n## Errors\n\n| method | level | h | dofs | Gamma_C nodes (body 1 / body 2) | theorem | l2_pressure | max_penetration | iterations (max per step) | contact fraction | plastic fraction | solve (s) | fitted |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for l in &res.levels {
        let e = |q: &str| {
            res.errors
                .iter()
                .find(|r| r.method == l.method && r.level == l.level && r.quantity == q)
                .map(|r| format!("{:.3e}", r.error))
                .unwrap_or_default()
        };
        let wall = res
            .errors
            .iter()
            .find(|r| r.method == l.method && r.level == l.level)
            .map(|r| r.wall_s)
            .unwrap_or(0.0);
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {} | {} / {} | {} | {} | {} | {} ({}) | {:.3} | {:.3} | {:.2} | {} |",
            l.method,
            l.level,
            l.h,
            l.dofs,
            l.slave_nodes,
            l.master_nodes,
            e("theorem"),
            e("l2_pressure"),
            e("max_penetration"),
            l.iterations,
            l.max_step_iterations,
            l.contact_fraction,
            l.plastic_fraction,
            wall,
            if l.flagged {
                "no (within 5x of the reference error)"
            } else {
                "yes"
            }
        );
    }
    let _ = writeln!(
        s,
        "\n## Reference\n\nMatching meshes on Gamma_C (where K_h^pi = K_h^I is conforming), level {} (h = {:.4}, {} dofs, solved in {:.1} s). Its own error in the theorem norm, estimated from the two coarser reference levels with the nested-space model d(L, R)^2 = e_L^2 - e_R^2, e_L = C h^p (fitted p = {:.2}): **{:.3e}** relative. Levels whose error is within a factor 5 of it are left out of the fits.\n",
        res.reference.0,
        res.reference.1,
        res.reference.2,
        res.reference.3,
        res.reference_error.1,
        res.reference_error.0
    );
    if let Some((runs, fit)) = &res.time_study {
        let _ = writeln!(
            s,
            "## Rate in time\n\nFixed mesh (level {}), k halved, against a reference with {} steps on the same mesh:\n\n| steps | k | theorem error |\n|---|---|---|",
            res.file.time.as_ref().unwrap().level,
            res.file.time.as_ref().unwrap().reference_steps
        );
        for (n, k, e) in runs {
            let _ = writeln!(s, "| {n} | {k:.4} | {e:.3e} |");
        }
        if let Some(f) = fit {
            let _ = writeln!(
                s,
                "\nRate in k: **{:.3} ± {:.3}** (backward Euler: 1).\n",
                f.rate, f.stderr
            );
        }
    }
    let _ = writeln!(
        s,
        "## Contact and plasticity at T\n\n![pressure](pressure.png)\n\n![gap](gap.png)\n\n![von Mises](von_mises.png)\n"
    );
    let _ = writeln!(s, "## Cost\n\n![error against time](error_vs_time.png)\n");
    let _ = writeln!(s, "## Provenance\n");
    for (k, v) in &res.provenance {
        let _ = writeln!(s, "- {k}: {v}");
    }
    let _ = writeln!(
        s,
        "- mesh family: {} = {} at level 0, h1/h2 = {}, levels {:?}; reference parameters {:?}",
        res.file.mesh.size_parameter_1,
        res.file.mesh.coarsest,
        res.file.mesh.ratio,
        res.file.mesh.levels,
        res.file.reference.parameters
    );
    let _ = writeln!(
        s,
        "\nData: `errors.csv`, `rates.csv`, `levels.csv`, `pressure.csv`, `gap.csv`."
    );
    s
}

/// Write the report of `study speed`.
pub fn write_speed(res: &crate::study::speed::SpeedResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "speed.csv", &csv_bytes(&res.rows)?)?;
        let combos = [
            ("mortar", "newton", 0usize),
            ("nts", "newton", 1),
            ("mortar", "paper", 3),
            ("nts", "paper", 2),
        ];
        let series: Vec<Series> = combos
            .iter()
            .map(|(m, so, c)| Series {
                label: format!("{m}, {so}"),
                points: res
                    .rows
                    .iter()
                    .filter(|r| r.method == *m && r.solver == *so)
                    .filter_map(|r| r.error.map(|e| (r.wall_s.max(1e-4), e)))
                    .collect(),
                markers: true,
                line: true,
                color: *c,
                thin: *so == "paper",
            })
            .filter(|s| !s.points.is_empty())
            .collect();
        plot::loglog(
            &d.join("work_precision.png"),
            "speed: error against wall time (rates scene, 4 steps)",
            "wall time of the time loop (s)",
            "relative error (theorem norm)",
            &series,
            &[],
        )?;
        let mut series = Vec::new();
        for (m, so, c) in combos {
            let rows: Vec<_> = res
                .rows
                .iter()
                .filter(|r| r.method == m && r.solver == so)
                .collect();
            if rows.is_empty() {
                continue;
            }
            let x: Vec<f64> = rows.iter().map(|r| r.dofs as f64).collect();
            let y: Vec<f64> = rows.iter().map(|r| r.wall_s).collect();
            // Exponent over the levels with at least 1e4 dofs (below, fixed costs dominate).
            let big: Vec<usize> = (0..x.len()).filter(|&i| x[i] >= 1e4).collect();
            let fit = crate::study::rates::fit(
                &big.iter().map(|&i| x[i]).collect::<Vec<_>>(),
                &big.iter().map(|&i| y[i]).collect::<Vec<_>>(),
            );
            let label = match fit {
                Some(f) => format!("{m}, {so}: time ~ dofs^{:.2}", f.rate),
                None => format!("{m}, {so}"),
            };
            series.push(Series {
                label,
                points: x.iter().copied().zip(y.iter().copied()).collect(),
                markers: true,
                line: true,
                color: c,
                thin: so == "paper",
            });
        }
        let floor: Vec<(f64, f64)> = res
            .rows
            .iter()
            .filter(|r| r.method == "mortar" && r.solver == "newton")
            .map(|r| (r.dofs as f64, r.floor_s))
            .collect();
        series.push(Series {
            label: "floor (mortar): assembly + 1 factorization + 2 solves per step".into(),
            points: floor,
            markers: false,
            line: true,
            color: 2,
            thin: true,
        });
        plot::loglog(
            &d.join("time_vs_dofs.png"),
            "speed: wall time against dofs",
            "free dofs",
            "wall time (s)",
            &series,
            &[],
        )?;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# Study `speed`\n\nWhat each accuracy costs on the `rates` scene (h1/h2 = 1.4142, {} time steps). Every run's time loop is compared with the floor measured in the same run on the same KKT matrix: assembling it once, one numeric factorization, and two triangular solves per time step. The one-off set-up per mesh (pattern, entry-to-slot map, symbolic analysis) is in neither and is shown apart. Runs below {} dofs are timed {} times, solver and floor alternately, and the fastest of each is kept (single timings of 0.01-0.1 s scatter by a factor 2 on this shared 2-core machine). Errors are in the theorem norm against a matching-mesh reference at level {} ({} dofs), shown where the reference is at least 3 levels finer. `peak RSS` is the process's peak so far. Regenerate with `cargo run --release -- study speed` ({:.0} s).\n",
            crate::study::speed::STEPS,
            crate::study::speed::REPEATS.0,
            crate::study::speed::REPEATS.1,
            res.reference.0,
            res.reference.1,
            res.wall_s
        );
        let _ = writeln!(
            s,
            "![work precision](work_precision.png)\n\n![time against dofs](time_vs_dofs.png)\n"
        );
        let _ = writeln!(
            s,
            "| family | method | solver | level | dofs | iterations | factorizations | time loop (s) | floor (s) | ratio to floor | set-up (s) | factorizations (s) | solves (s) | assembly (s) | constitutive (s) | peak RSS (GiB) | error |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        for r in &res.rows {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} |",
                r.family,
                r.method,
                r.solver,
                r.level,
                r.dofs,
                r.iterations,
                r.factorizations,
                r.wall_s,
                r.floor_s,
                r.ratio_to_floor,
                r.setup_s,
                r.factor_s,
                r.solve_s,
                r.assembly_s,
                r.constitutive_s,
                r.peak_rss_gib
                    .map(|g| format!("{g:.1}"))
                    .unwrap_or_default(),
                r.error.map(|e| format!("{e:.3e}")).unwrap_or_default()
            );
        }
        for m in ["mortar", "nts"] {
            let finest = crate::study::speed::PAPER_LEVELS.iter().max().unwrap();
            let nw = res
                .rows
                .iter()
                .find(|r| r.method == m && r.solver == "newton" && r.level == *finest);
            let pp = res
                .rows
                .iter()
                .find(|r| r.method == m && r.solver == "paper" && r.level == *finest);
            if let (Some(a), Some(b)) = (nw, pp) {
                let _ = writeln!(
                    s,
                    "\n{m}, level {finest}: newton {:.3} s ({:.2} x the floor), paper {:.3} s at the same final tolerance: newton is {:.1} x faster.",
                    a.wall_s,
                    a.ratio_to_floor,
                    b.wall_s,
                    b.wall_s / a.wall_s
                );
            }
        }
        write(d, "README.md", s.as_bytes())
    })
}

/// Write the report of `study stability`.
pub fn write_stability(res: &crate::study::stability::StabilityResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "stability.csv", &csv_bytes(&res.rows)?)?;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# Study `stability`\n\nHard cases, each run with every solver and both cones (level 1 of the `rates` scene with 4 steps unless stated). A failure is a result: `converged = no` with the solver's reason. `error` is the largest nodal difference to newton's solution of the same discrete problem, relative to the largest displacement. Regenerate with `cargo run --release -- study stability` ({:.0} s).\n",
            res.wall_s
        );
        for (name, file) in [
            ("stiff viscosity", "stiff_viscosity"),
            ("omega sweep", "omega_sweep"),
            ("modulus contrast", "modulus_contrast"),
            ("slivers", "slivers"),
        ] {
            let rows: Vec<_> = res
                .rows
                .iter()
                .filter(|r| r.case == name && r.method == "mortar")
                .collect();
            let mut its = Vec::new();
            let mut errs = Vec::new();
            for (i, so) in ["newton", "paper", "qp"].iter().enumerate() {
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.solver == *so && r.converged)
                    .map(|r| (r.value, r.mean_step_iterations.max(1e-3)))
                    .collect();
                if !pts.is_empty() {
                    its.push(Series {
                        label: format!("{so} (converged runs)"),
                        points: pts,
                        markers: true,
                        line: true,
                        color: i,
                        thin: false,
                    });
                }
                let pe: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.solver == *so && r.converged && r.error > 0.0)
                    .map(|r| (r.value, r.error))
                    .collect();
                if !pe.is_empty() {
                    errs.push(Series {
                        label: format!("{so}: difference to newton"),
                        points: pe,
                        markers: true,
                        line: true,
                        color: i,
                        thin: false,
                    });
                }
            }
            let xlabel = match name {
                "stiff viscosity" => "k E / lambda",
                "modulus contrast" => "E2 / E1",
                "slivers" => "largest aspect ratio of a triangle",
                _ => "omega / automatic omega",
            };
            plot::loglog(
                &d.join(format!("{file}_iterations.png")),
                &format!("{name}: mean iterations per step (mortar)"),
                xlabel,
                "iterations per step",
                &its,
                &[],
            )?;
            if !errs.is_empty() {
                plot::loglog(
                    &d.join(format!("{file}_error.png")),
                    &format!("{name}: difference to newton (mortar)"),
                    xlabel,
                    "relative nodal difference",
                    &errs,
                    &[],
                )?;
            }
        }
        let mut cases: Vec<&str> = Vec::new();
        for r in &res.rows {
            if !cases.contains(&r.case.as_str()) {
                cases.push(&r.case);
            }
        }
        for c in cases {
            let _ = writeln!(s, "## {c}\n");
            let note = match c {
                "stiff viscosity" => {
                    "k = 0.25, E = 100; lambda set so that k E / lambda sweeps 1e-2..1e4. The paper's fixed point (4.2)-(4.3) is a contraction only while k L < 1."
                }
                "modulus contrast" => "E of the lower block = 100 x E2/E1, upper block E = 100.",
                "mesh-size ratio" => "Level 0 with h_upper = 0.2 sqrt(r), h_lower = 0.2 / sqrt(r).",
                "slivers" => {
                    "The upper block's first layer along Gamma_C is a structured strip (the `strip` parameter of meshes/two_blocks.geo), one triangle pair per contact edge: the thinner the strip, the flatter the triangles that carry the constraint. The largest aspect ratio (longest edge over the altitude onto it) is measured on the mesh."
                }
                "units rescaled" => {
                    "scenes/rates-units.toml: the rates scene with lengths x 1e3 (gmsh writes the .msh scaled, `unit = 1000`), moduli, yield stress, viscosity and tractions x 1e6. `error` here is the largest nodal difference of u / 1e3 to the same solver's solution in the original units, relative to its largest displacement; the reason says whether the iterations per step are identical."
                }
                "newton iterations across levels" => {
                    "The study rates family (h_upper = 0.3, h_lower = 0.3 / 1.4142), levels 0-5 (118 to 112,896 dofs): newton's iterations per step do not grow with h."
                }
                _ => "",
            };
            if !note.is_empty() {
                let _ = writeln!(s, "{note}\n");
            }
            for (case, file) in [
                ("stiff viscosity", "stiff_viscosity"),
                ("omega sweep", "omega_sweep"),
                ("modulus contrast", "modulus_contrast"),
                ("slivers", "slivers"),
            ] {
                if c == case {
                    let _ = writeln!(s, "![iterations]({file}_iterations.png)\n");
                    if d.join(format!("{file}_error.png")).exists() {
                        let _ = writeln!(s, "![error]({file}_error.png)\n");
                    }
                }
            }
            let _ = writeln!(
                s,
                "| parameter | method | solver | converged | max / mean iterations per step | error | max penetration | wall (s) | reason |\n|---|---|---|---|---|---|---|---|---|"
            );
            for r in res.rows.iter().filter(|r| r.case == c) {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} / {:.1} | {} | {} | {:.3} | {} |",
                    r.parameter,
                    r.method,
                    r.solver,
                    if r.converged { "yes" } else { "**no**" },
                    r.max_step_iterations,
                    r.mean_step_iterations,
                    if r.error.is_finite() {
                        format!("{:.2e}", r.error)
                    } else {
                        String::new()
                    },
                    if r.max_penetration.is_finite() {
                        format!("{:.2e}", r.max_penetration)
                    } else {
                        String::new()
                    },
                    r.wall_s,
                    r.reason.replace('|', "/")
                );
            }
            let _ = writeln!(s);
        }
        write(d, "README.md", s.as_bytes())
    })
}
