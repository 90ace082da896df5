//! The report of `grade`: errors.csv and rates.csv in the studies' columns (the graded
//! code's label in `method`), error_vs_h.png with the fitted slopes in the legend, and a
//! README.md that leads with how the graded code compares with this project's cones.

use super::grade::{Graded, Storage};
use crate::error::Result;
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::verify::judge::RateRow;
use crate::verify::judge::SEPARATES;
use crate::verify::quantity::Quantity;
use crate::verify::rates::{ROUNDOFF, Verdict};
use crate::verify::table::{ErrorRecord, MethodLabel, RateRecord, methods_in_order};
use std::path::Path;

/// How a graded code's finest errors compare with one cone's ([`Graded::differences`]).
struct ConeDifference {
    cone: MethodLabel,
    /// The quantities beyond [`SEPARATES`]: (quantity, graded / cone), furthest from 1 first.
    beyond: Vec<(Quantity, f64)>,
    /// The ratio furthest from 1 over every compared quantity.
    furthest: f64,
    /// How many quantities were compared.
    compared: usize,
}

impl Graded {
    /// The methods in the order of the report: the graded code first.
    fn methods(&self) -> Vec<MethodLabel> {
        methods_in_order(self.errors.iter().map(|r| &r.method))
    }

    fn rate(&self, method: &MethodLabel, q: Quantity) -> Option<&RateRow> {
        self.rates
            .iter()
            .find(|r| &r.method == method && r.quantity == q)
    }

    fn error(&self, method: &MethodLabel, level: usize, q: Quantity) -> Option<&ErrorRecord> {
        self.errors
            .iter()
            .find(|r| &r.method == method && r.level == level && r.quantity == q)
    }

    /// A method's colour and marker in the plots: a cone's as in every study's plots
    /// (mortar, nts, lac), the graded code the next.
    fn style_index(method: &MethodLabel) -> usize {
        match method.cone() {
            Some(m) => plot::method_style(m),
            None => crate::contact::Method::ALL.len(),
        }
    }

    /// The quantities the graded code and the cones are compared in at the finest level:
    /// measured for all of them, the verdicts of all of them plain enough to compare
    /// ([`Verdict::compares_cones`]), not a distance or a best approximation.
    fn compared_quantities(&self) -> Vec<Quantity> {
        let methods = self.methods();
        Quantity::ALL
            .into_iter()
            .filter(|q| !q.is_distance() && !q.is_best_approximation())
            .filter(|&q| {
                // Round-off errors are no discretization's: their ratios are noise.
                methods.iter().all(|m| {
                    self.rate(m, q).is_some_and(|r| {
                        r.assessment.verdict.compares_cones()
                            && r.assessment.verdict != Verdict::RoundOff
                    })
                })
            })
            .collect()
    }

    /// Per cone, the quantities whose error at the finest level differs from the graded
    /// code's by more than [`SEPARATES`] either way: (cone, [(quantity, graded / cone)],
    /// the largest ratio of any compared quantity either way), ratios furthest from 1 first.
    fn differences(&self) -> Option<(usize, Vec<ConeDifference>)> {
        let level = self.levels.last()?.level;
        let label = MethodLabel::External(self.label.clone());
        let quantities = self.compared_quantities();
        let mut out = Vec::new();
        for cone in self.methods().into_iter().filter(|m| m.cone().is_some()) {
            let mut ratios: Vec<(Quantity, f64)> = quantities
                .iter()
                .filter_map(|&q| {
                    let mine = self.error(&label, level, q)?.error;
                    let theirs = self.error(&cone, level, q)?.error;
                    (mine > 0.0 && theirs > 0.0).then(|| (q, mine / theirs))
                })
                .collect();
            ratios.sort_by(|a, b| b.1.ln().abs().total_cmp(&a.1.ln().abs()));
            let furthest = ratios.first().map_or(1.0, |r| r.1);
            let compared = ratios.len();
            ratios.retain(|r| !(1.0 / SEPARATES..=SEPARATES).contains(&r.1));
            out.push(ConeDifference {
                cone,
                beyond: ratios,
                furthest,
                compared,
            });
        }
        Some((level, out))
    }

    /// The report's first paragraph: where the graded code differs from each cone at the
    /// finest level, and which cone it sides with.
    fn summary(&self) -> Option<String> {
        let (level, cones) = self.differences()?;
        if cones.is_empty() || cones.iter().any(|c| c.compared == 0) {
            return None;
        }
        // Three significant digits: 179x, 18.6x, 1.86x.
        let times = |r: f64| match r {
            r if r >= 100.0 => format!("{r:.0}x"),
            r if r >= 10.0 => format!("{r:.1}x"),
            r => format!("{r:.2}x"),
        };
        let ratio = |r: f64| match r >= 1.0 {
            true => format!("{} larger", times(r)),
            false => format!("{} smaller", times(1.0 / r)),
        };
        let mut parts = Vec::new();
        for c in &cones {
            parts.push(match c.beyond.is_empty() {
                true => format!(
                    "it agrees with {} within {SEPARATES}x in all {} quantities compared (furthest: a ratio of {:.3})",
                    c.cone, c.compared, c.furthest
                ),
                false => format!(
                    "it differs from {} in {} of {}: {}",
                    c.cone,
                    c.beyond.len(),
                    c.compared,
                    c.beyond
                        .iter()
                        .map(|(q, r)| format!("`{q}` {}", ratio(*r)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        let sides: Vec<String> = cones
            .iter()
            .filter(|c| c.beyond.is_empty())
            .map(|c| c.cone.to_string())
            .collect();
        let sides = match sides.len() {
            0 => "It sides with none of the cones.".to_string(),
            _ => format!("It sides with {}.", sides.join(" and ")),
        };
        let plot = match Self::plotted(&cones).is_empty() {
            true => "",
            false => " The second plot shows the contact quantities that differ most.",
        };
        Some(format!(
            "**What differs.** At the finest level ({level}), in the quantities where every method's verdict allows a comparison (an error ratio beyond {SEPARATES}x either way separates two methods), `{}`: {}. {sides}{plot} The glossary at the end defines each quantity.",
            self.label,
            parts.join("; ")
        ))
    }

    /// Write the report folder `dir`, all or nothing.
    pub fn write(&self, dir: &Path) -> Result<()> {
        write_folder(dir, |d| {
            write(d, "errors.csv", &csv_bytes(&self.errors)?)?;
            write(d, "checks.csv", &csv_bytes(&self.checks)?)?;
            let rates: Vec<RateRecord> = self.rates.iter().map(RateRow::record).collect();
            write(d, "rates.csv", &csv_bytes(&rates)?)?;
            let decomposition = crate::verify::judge::decomposition(&self.errors);
            if !decomposition.is_empty() {
                write(d, "decomposition.csv", &csv_bytes(&decomposition)?)?;
                let asymptotes = crate::verify::judge::asymptotes(&self.rates, &self.errors);
                write(d, "asymptotes.csv", &csv_bytes(&asymptotes)?)?;
            }
            self.plot(d)?;
            write(d, "README.md", self.readme().as_bytes())
        })
    }

    /// The key quantity's error against h per method, with each fitted slope.
    fn plot(&self, d: &Path) -> Result<()> {
        let mut series = Vec::new();
        for m in &self.methods() {
            let rows: Vec<&ErrorRecord> = self
                .errors
                .iter()
                .filter(|r| &r.method == m && r.quantity == self.key)
                .collect();
            let verdict = match self.rate(m, self.key) {
                Some(r) if r.supported_fit().is_none() => format!(": {}", r.short_text()),
                _ => String::new(),
            };
            let i = Self::style_index(m);
            series.push(Series {
                label: format!("{m}{verdict}"),
                points: rows.iter().map(|r| (r.h, r.error)).collect(),
                markers: true,
                line: false,
                color: i,
                thin: false,
                shape: None,
            });
            if let Some((legend, rate, intercept, hs)) =
                self.rate(m, self.key).and_then(|r| r.line(&rows))
            {
                series.extend(plot::fit_line(
                    format!("{m} {legend}"),
                    rate,
                    intercept,
                    &hs,
                    i,
                ));
            }
        }
        plot::loglog(
            &d.join("error_vs_h.png"),
            &format!("{}: error against h", self.label),
            "h (max element diameter)",
            &format!("relative error ({})", self.key),
            &series,
            &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
        )?;
        self.plot_differences(d)
    }

    /// The contact quantities (where contact conditions differ) beyond [`SEPARATES`] from
    /// some cone, furthest from 1 first, three at most so that the legend leaves the data
    /// visible: what contact_vs_h.png draws.
    fn plotted_quantities(&self) -> Vec<Quantity> {
        self.differences()
            .map_or(Vec::new(), |(_, cones)| Self::plotted(&cones))
    }

    /// [`Graded::plotted_quantities`] of the comparisons `cones`.
    fn plotted(cones: &[ConeDifference]) -> Vec<Quantity> {
        let mut shown: Vec<(Quantity, f64)> = cones.iter().flat_map(|c| c.beyond.clone()).collect();
        shown.sort_by(|a, b| b.1.ln().abs().total_cmp(&a.1.ln().abs()));
        let mut quantities: Vec<Quantity> = Vec::new();
        for (q, _) in shown.into_iter().filter(|s| s.0.is_contact()) {
            if !quantities.contains(&q) && quantities.len() < 3 {
                quantities.push(q);
            }
        }
        quantities
    }

    /// The quantities of [`Graded::plotted_quantities`], every method's errors against h:
    /// colour the quantity, marker the method. Nothing where no contact quantity differs.
    fn plot_differences(&self, d: &Path) -> Result<()> {
        let quantities = self.plotted_quantities();
        if quantities.is_empty() {
            return Ok(());
        }
        let mut series = Vec::new();
        for (c, &q) in quantities.iter().enumerate() {
            for m in &self.methods() {
                let points: Vec<(f64, f64)> = self
                    .errors
                    .iter()
                    .filter(|r| &r.method == m && r.quantity == q && r.error > ROUNDOFF)
                    .map(|r| (r.h, r.error))
                    .collect();
                let rate = self.rate(m, q).map_or("-".into(), RateRow::short_text);
                series.push(Series::of_quantity(
                    format!("{m} {q}: {rate}"),
                    points,
                    c,
                    Self::style_index(m),
                    m.cone().is_some(),
                ));
            }
        }
        plot::loglog(
            &d.join("contact_vs_h.png"),
            &format!(
                "where {} differs from the cones (colour: quantity)",
                self.label
            ),
            "h (max element diameter)",
            "relative error",
            &series,
            &[(0.5, "1/2"), (1.0, "1"), (2.0, "2")],
        )
    }

    /// README.md.
    fn readme(&self) -> String {
        let mut doc = Doc::new();
        let what = match &self.study {
            Some(s) => format!("study `{s}` (scene `{}`)", self.scene),
            None => format!("scene `{}`", self.scene),
        };
        doc.heading(1, format!("Grade of `{}` on {what}", self.label));
        if let Some(summary) = self.summary() {
            doc.paragraph(summary);
        }
        doc.paragraph(self.lead());
        if !self.flagged.is_empty() {
            doc.paragraph(format!(
                "**Not converged**: {}. Such a level's errors are left out of errors.csv and of every rate (checks.csv keeps its key error).",
                self.flagged.join("; ")
            ));
        }
        if !self.failures.is_empty() {
            doc.paragraph(format!(
                "**Threshold missed**: {}.",
                self.failures.join("; ")
            ));
        }
        if !self.unverified.is_empty() {
            doc.paragraph(format!(
                "**Threshold unverified** (neither met nor missed: the errors support no rate, and the last successive rate is not below it): {}.",
                self.unverified.join("; ")
            ));
        }
        doc.image("error against h", "error_vs_h.png");
        if !self.plotted_quantities().is_empty() {
            doc.image("where the errors differ", "contact_vs_h.png");
        }
        doc.heading(2, "Rates");
        doc.paragraph("Each quantity judged as the studies judge it (docs/studies.md#rates): a rate only over a trailing window of levels whose successive rates agree; otherwise the verdict says why there is none (glossary below). The fitted levels and successive rates of every cell are in rates.csv.");
        doc.table(&self.rate_table());
        if self.compared {
            if let Some(table) = self.contact_table() {
                doc.paragraph(format!(
                    "On Gamma_C, where the cones differ, the errors at the finest level ({}):",
                    self.levels.last().map_or(0, |l| l.level)
                ));
                doc.table(&table);
            }
        }
        if let Some(table) = self.distance_table() {
            doc.paragraph("Each method read against its distance D to mortar's solution on the same level (through the intersection of the two meshes for the graded code): D - e_mortar <= e <= D + e_mortar, so the error tends to min(r_D, r_mortar) once D's rate is supported (decomposition.csv, asymptotes.csv; docs/studies.md#rates):");
            doc.table(&table);
        }
        doc.list(&self.notes);
        doc.paragraph(format!("Graded with `{}`.", self.command));
        doc.heading(2, format!("{} per level", self.key));
        doc.table(&self.key_table());
        doc.heading(2, "The graded files");
        doc.table(&self.level_table());
        doc.heading(2, "Checks");
        doc.paragraph(CHECKS_TEXT);
        doc.table(&self.check_table());
        doc.heading(2, "Glossary");
        let named: Vec<Quantity> = Quantity::ALL
            .into_iter()
            .filter(|&q| self.errors.iter().any(|e| e.quantity == q))
            .collect();
        doc.line(crate::verify::quantity::glossary(&named));
        doc.finish()
    }

    /// The first paragraph: the graded code's key rate and verdict beside the cones'.
    fn lead(&self) -> String {
        let rate = |m: &MethodLabel| {
            self.rate(m, self.key)
                .map_or("no rate".into(), |r| r.describe_with_verdict())
        };
        let label = MethodLabel::External(self.label.clone());
        let when = match self.levels.iter().all(|l| l.times.len() == 1) {
            true => "at T",
            false => "max over the steps",
        };
        let norm = match self.key {
            Quantity::Theorem => format!(
                "Theorem 3.1's norm (||u - u_h||_H1 + ||sigma - sigma_h||_L2, {when}, relative)"
            ),
            q => format!("{q} (relative)"),
        };
        let mut text = format!(
            "Against the exact solution, `{}`'s error in {norm} falls at rate {} in h",
            self.label,
            rate(&label)
        );
        if self.compared {
            let cones: Vec<String> = self
                .methods()
                .iter()
                .filter(|m| m.cone().is_some())
                .map(|m| format!("{m} {}", rate(m)))
                .collect();
            text.push_str(&format!(
                "; this project's cones on the same problem and levels: {}",
                cones.join(", ")
            ));
            if let Some(ratio) = self.finest_ratios() {
                text.push_str(&format!(". On the finest level its error is {ratio}"));
            }
        }
        text.push('.');
        text
    }

    /// "x times mortar's and y times nts's" on the finest level, if all three have it.
    fn finest_ratios(&self) -> Option<String> {
        let level = self.levels.last()?.level;
        let label = MethodLabel::External(self.label.clone());
        let mine = self.error(&label, level, self.key)?.error;
        let parts: Vec<String> = self
            .methods()
            .iter()
            .filter(|m| m.cone().is_some())
            .filter_map(|m| {
                let e = self.error(m, level, self.key)?.error;
                Some(format!("{:.3} times {m}'s", mine / e))
            })
            .collect();
        (!parts.is_empty()).then(|| parts.join(" and "))
    }

    /// The contact quantities at the finest level: each method's error and the graded
    /// code's error over each cone's (None without such quantities).
    fn contact_table(&self) -> Option<Table> {
        let level = self.levels.last()?.level;
        let label = MethodLabel::External(self.label.clone());
        let cones: Vec<MethodLabel> = self
            .methods()
            .into_iter()
            .filter(|m| m.cone().is_some())
            .collect();
        let mut header = vec!["quantity".to_string(), self.label.clone()];
        header.extend(cones.iter().map(|m| format!("{m}")));
        header.extend(cones.iter().map(|m| format!("{} / {m}", self.label)));
        let mut table = Table::new(header);
        for q in Quantity::CONTACT {
            let Some(mine) = self.error(&label, level, q).map(|r| r.error) else {
                continue;
            };
            // Its error measures the load quadrature (round-off), not the discretization.
            if self
                .rate(&label, q)
                .is_some_and(|r| r.assessment.verdict == Verdict::FixedByEquilibrium)
            {
                continue;
            }
            let theirs: Vec<Option<f64>> = cones
                .iter()
                .map(|m| self.error(m, level, q).map(|r| r.error))
                .collect();
            let mut row = vec![format!("`{q}`"), format!("{mine:.3e}")];
            row.extend(
                theirs
                    .iter()
                    .map(|e| e.map_or("-".into(), |e| format!("{e:.3e}"))),
            );
            row.extend(theirs.iter().map(|e| match e {
                Some(e) if *e > 0.0 => format!("{:.3}", mine / e),
                _ => "-".into(),
            }));
            table.row(row);
        }
        (!table.is_empty()).then_some(table)
    }

    /// Each method other than mortar read against its distance to mortar.
    fn distance_table(&self) -> Option<Table> {
        let mut table = Table::new([
            "method",
            "quantity",
            "observed",
            "D (distance to mortar)",
            "largest abs(pythagorean)",
            "D / e_mortar, finest level",
            "asymptotic rate",
        ]);
        for a in crate::verify::judge::asymptotes(&self.rates, &self.errors) {
            let dq = crate::verify::judge::DECOMPOSED
                .into_iter()
                .find(|(q, _)| *q == a.quantity)
                .map(|(_, d)| d)?;
            let describe = |q: Quantity| {
                self.rate(&a.method, q)
                    .map_or("-".into(), |r| r.assessment.describe().replace("**", ""))
            };
            table.row([
                a.method.to_string(),
                format!("`{}`", a.quantity),
                describe(a.quantity),
                describe(dq),
                a.largest_pythagorean
                    .map_or("-".into(), |v| format!("{v:.1e}")),
                a.finest_ratio.map_or("-".into(), |v| format!("{v:.2}")),
                a.describe(),
            ]);
        }
        (!table.is_empty()).then_some(table)
    }

    fn key_table(&self) -> Table {
        let methods = self.methods();
        let label = MethodLabel::External(self.label.clone());
        let mut header = vec!["level".to_string(), "h".into()];
        header.extend(methods.iter().map(|m| format!("{m}")));
        for m in methods.iter().filter(|m| m.cone().is_some()) {
            header.push(format!("{} / {m}", self.label));
        }
        header.push(format!("{}: residual bound delta", self.label));
        header.push(format!("{}: error without it", self.label));
        let mut table = Table::new(header);
        for l in &self.levels {
            let mut row = vec![l.level.to_string(), format!("{:.5}", l.h)];
            for m in &methods {
                row.push(
                    self.error(m, l.level, self.key)
                        .map_or("-".into(), |r| format!("{:.4e}", r.error)),
                );
            }
            let check = self.checks.iter().find(|c| c.level == l.level);
            let mine = self.error(&label, l.level, self.key).map(|r| r.error);
            for m in methods.iter().filter(|m| m.cone().is_some()) {
                let theirs = self.error(m, l.level, self.key).map(|r| r.error);
                row.push(match (mine, theirs) {
                    (Some(a), Some(b)) => format!("{:.3}", a / b),
                    _ => "-".into(),
                });
            }
            row.push(check.map_or("-".into(), |c| format!("{:.2e}", c.residual)));
            row.push(match (mine, check.and_then(|c| c.error_shift)) {
                (Some(e), Some(s)) => format!("{:.4e} ({:+.2}%)", e * (1.0 + s), 100.0 * s),
                _ => "-".into(),
            });
            table.row(row);
        }
        table
    }

    /// One row per quantity, one column per method: the rate or what replaces it
    /// ([`RateRow::short_text`]), with the threshold's outcome where one applies.
    fn rate_table(&self) -> Table {
        let methods = self.methods();
        let mut header = vec!["quantity".to_string()];
        header.extend(methods.iter().map(|m| m.to_string()));
        let mut table = Table::new(header);
        for q in Quantity::ALL {
            if !self.rates.iter().any(|r| r.quantity == q) {
                continue;
            }
            let mut row = vec![format!("`{q}`")];
            for m in &methods {
                row.push(self.rate(m, q).map_or("-".into(), |r| {
                    let cell = match r.supported_fit() {
                        Some(f) => format!("{:.3} ± {:.3}", f.rate, f.stderr),
                        None => r.short_text(),
                    };
                    match (r.threshold, r.outcome) {
                        (Some(t), Some(o)) => format!("{cell} (>= {}: {})", t.value(), o.shouted()),
                        _ => cell,
                    }
                }));
            }
            table.row(row);
        }
        table
    }

    fn level_table(&self) -> Table {
        let mut table = Table::new([
            "level",
            "file",
            "h",
            "dofs",
            "triangles",
            "steps graded",
            "stress",
            "pressure",
        ]);
        for l in &self.levels {
            table.row([
                l.level.to_string(),
                format!(
                    "`{}`",
                    l.file
                        .file_name()
                        .map_or(String::new(), |f| f.to_string_lossy().to_string())
                ),
                format!("{:.5}", l.h),
                l.dofs.to_string(),
                l.triangles.to_string(),
                match l.storage {
                    Storage::Vtu => "T only".into(),
                    _ => format!("{} of {}", l.times.len(), self.steps),
                },
                if l.stress_given {
                    "given".into()
                } else {
                    "E eps(u_h)".into()
                },
                if l.pressure_given {
                    "given".into()
                } else {
                    "-".into()
                },
            ]);
        }
        table
    }

    /// Per level, what was checked of the file (checks.csv).
    fn check_table(&self) -> Table {
        let mut table = Table::new([
            "level",
            "error",
            "residual delta (limit)",
            "load rules' lambda_q",
            "not scaling with the load",
            "cause",
            "normal imbalance",
            "tangential",
            "pulling",
            "force limits",
            "pressure resultant / exact",
            "verdict",
        ]);
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2e}"));
        for c in &self.checks {
            table.row([
                c.level.to_string(),
                format!("{:.4e}", c.error),
                format!("{:.2e} ({:.2e})", c.residual, c.residual_limit),
                opt(c.load_rule_residual),
                opt(c.residual_off_load),
                c.residual_cause.clone().unwrap_or_else(|| "-".into()),
                opt(c.normal_imbalance),
                opt(c.tangential),
                opt(c.pulling),
                match (c.imbalance_limit, c.tangential_limit, c.pulling_limit) {
                    (Some(a), Some(b), Some(p)) => format!("{a:.1e} / {b:.1e} / {p:.1e}"),
                    _ => "-".into(),
                },
                c.pressure_ratio.map_or("-".into(), |r| format!("{r:.6}")),
                c.verdict.clone(),
            ]);
        }
        table
    }

    /// The console summary.
    pub fn console(&self, dir: &Path) -> String {
        let mut out = String::new();
        // One line per method's verdict in the key quantity, the graded code first.
        for m in self.methods() {
            if let Some(r) = self.rate(&m, self.key) {
                out.push_str(&r.verdict_line());
                out.push('\n');
            }
        }
        if let Some(summary) = self.summary() {
            out.push_str(&summary.replace("**", ""));
            out.push('\n');
        }
        for f in &self.flagged {
            out.push_str(&format!("NOT CONVERGED: {f}\n"));
        }
        for n in &self.notes {
            out.push_str(&format!("note: {n}\n"));
        }
        out.push_str(&format!("wrote {}\n", dir.display()));
        out
    }
}

const CHECKS_TEXT: &str = "Before a level gives a rate, grade checks that it is a converged P1 solution of this problem. Equilibrium: the residual of the P1 problem on the file's mesh with the exported loads, in energy, delta (at most how much it moves the error; printed beside each error), told apart from a load rule's residual (lambda_q, what the common plain rules leave on the same mesh) and from an unconverged solve (delta_w, its part that does not scale with the load): refused where delta exceeds 1/20 of the error and is an iteration's, and where it exceeds 1/2 of the error whatever the cause. Gamma_C: the two sides' normal forces equal, no tangential and no pulling force, to 1e-3 of the resultant (wider, in proportion, for a code's own load rule). The pressure's resultant against the exact one's: a negative ratio or a constant factor is refused. The rules and why: docs/verify-your-code.md, section 3.";
