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
use crate::verify::quantity::Quantity;
use crate::verify::rates::Verdict;
use crate::verify::table::{ErrorRecord, MethodLabel, RateRecord, methods_in_order};
use std::path::Path;

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
        for (i, m) in self.methods().iter().enumerate() {
            let rows: Vec<&ErrorRecord> = self
                .errors
                .iter()
                .filter(|r| &r.method == m && r.quantity == self.key)
                .collect();
            let verdict = match self.rate(m, self.key) {
                Some(r) if r.supported_fit().is_none() => format!(": {}", r.short_text()),
                _ => String::new(),
            };
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
        if self.compared {
            if let Some(table) = self.contact_table() {
                doc.paragraph(format!(
                    "On Gamma_C, where mortar and nts differ, at the finest level ({}):",
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
        doc.image("error against h", "error_vs_h.png");
        doc.heading(2, format!("{} per level", self.key));
        doc.table(&self.key_table());
        doc.heading(2, "Rates");
        doc.paragraph("Every quantity judged as the studies judge it (docs/studies.md): a rate only over a trailing window of levels whose successive rates agree; `falling` and `rising` (a rate in transition), `pre-asymptotic`, `too few levels` and `not converging` say why a rate is flagged or missing.");
        doc.table(&self.rate_table());
        doc.heading(2, "The graded files");
        doc.table(&self.level_table());
        doc.heading(2, "Checks");
        doc.paragraph(CHECKS_TEXT);
        doc.table(&self.check_table());
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

    fn rate_table(&self) -> Table {
        let mut table = Table::new([
            "method",
            "quantity",
            "rate in h",
            "verdict",
            "levels fitted",
            "successive rates",
            "threshold",
        ]);
        for r in &self.rates {
            let a = &r.assessment;
            table.row([
                format!("{}", r.method),
                format!("{}", r.quantity),
                a.fit
                    .map_or("-".into(), |f| format!("{:.3} ± {:.3}", f.rate, f.stderr)),
                a.verdict.name().to_string(),
                if a.used.is_empty() {
                    "-".into()
                } else {
                    crate::verify::table::join(&a.used)
                },
                a.successive_text(),
                match (r.threshold, r.outcome) {
                    (Some(t), Some(o)) => format!(">= {}: {}", t.value(), o.shouted()),
                    _ => "-".into(),
                },
            ]);
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
        out.push_str(&self.lead());
        out.push('\n');
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

const CHECKS_TEXT: &str = "Before a level gives a rate, grade checks that it is a converged solution of a P1 discretization of this problem. The equilibrium residual r of the P1 problem on the file's mesh (its stress, or C eps(u_h); the exported loads; the supports' and Gamma_C's dofs held), in energy, delta = sqrt(r^T K^-1 r) / ||u_h||_E, is the energy distance to the field in equilibrium with the exported loads (Gamma_C held), whose energy error it adds to in squares: the bound printed beside each error, with, where it exceeds 1/20 of the error, the key error of that field (measured in the key norm). A code that integrates the loads with its own rule leaves one, of the size lambda_q the common plain rules leave on the same mesh (centroid, 3 interior points, 3 x 3 Gauss, Dunavant 16, none split at the loads' kinks): a load that is t^k times a field of (x, y) makes a load rule's residual scale as t^k from step to step, an iteration's not, and the part that does not, delta_w, is measured. A level is refused as unconverged where delta exceeds 1/20 of its error and either delta_w exceeds 1/20 of its error or delta exceeds 3 lambda_q; and whatever the cause where delta exceeds 1/2 of its error. On Gamma_C, the two sides' normal forces equal, no tangential and no pulling force, each to 1e-3 of the resultant, or, where the residual is no iteration's, to 3 (delta / lambda_q) times what the common rules' load differences alone put into that check, where larger. The pressure's resultant at T is read against the exact one's: a negative ratio or a constant factor is refused (docs/verify-your-code.md).";
