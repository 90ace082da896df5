//! `contact-rates judge FILE.csv`: the studies' judge on anyone's table of errors. Columns
//! `h,error`, optionally `level`, `dofs`, `method`, `quantity` (one verdict per method and
//! quantity) and `truth_error` (the reference's own error, per row; a group takes its
//! largest). Rows of a group are judged coarsest first (h decreasing); without a `level`
//! column a row's level is its index in its group. A table refined by a factor below 2
//! (sqrt(2) is common) is judged on rates between levels at least 1.9 apart in h
//! ([`crate::verify::rates::MIN_RATE_SPAN`]).

use crate::error::{Error, Result};
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::plot::{self, Series};
use crate::verify::judge::{Threshold, judge_levels, levels_of};
use crate::verify::rates::{Assessment, Outcome};
use crate::verify::table::{MethodLabel, RateRecord};
use std::path::{Path, PathBuf};

/// The fewest rows a group may have: the judge fits no fewer levels.
const MIN_ROWS: usize = 3;

/// One row of the table.
#[derive(Debug, Clone)]
struct Row {
    method: String,
    quantity: String,
    level: Option<usize>,
    h: f64,
    dofs: f64,
    error: f64,
    truth_error: f64,
}

/// One method's errors in one quantity, judged.
#[derive(Debug, Clone)]
pub struct JudgedGroup {
    /// The method's name ("" where the table has no `method` column).
    pub method: String,
    /// The quantity's name ("" where the table has no `quantity` column).
    pub quantity: String,
    /// (level, h, error), coarsest first.
    pub errors: Vec<(usize, f64, f64)>,
    /// What the errors support.
    pub assessment: Assessment,
    /// The threshold, where it applies to this group.
    pub threshold: Option<f64>,
    /// Its outcome.
    pub outcome: Option<Outcome>,
}

/// What `judge` was asked.
pub struct JudgeRequest {
    /// The table.
    pub file: PathBuf,
    /// A required rate R: pass, fail or unverified per group it applies to.
    pub threshold: Option<f64>,
    /// The groups R applies to: this method only (default every method).
    pub method: Option<String>,
    /// This quantity only (default every quantity).
    pub quantity: Option<String>,
}

/// The table read and every group judged, in order of first appearance.
pub fn judge_file(req: &JudgeRequest) -> Result<Vec<JudgedGroup>> {
    let rows = read_rows(&req.file)?;
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in &rows {
        let k = (r.method.clone(), r.quantity.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (name, value) in [("--method", &req.method), ("--quantity", &req.quantity)] {
        if let Some(v) = value {
            let known = keys
                .iter()
                .any(|k| if name == "--method" { &k.0 } else { &k.1 } == v);
            if !known {
                return Err(Error::input(
                    &req.file,
                    name.trim_start_matches("--"),
                    format!(
                        "no row has {} '{v}'; give one the table has, or leave {name} out",
                        name.trim_start_matches("--")
                    ),
                ));
            }
        }
    }
    keys.into_iter()
        .map(|(method, quantity)| {
            let mut group: Vec<&Row> = rows
                .iter()
                .filter(|r| r.method == method && r.quantity == quantity)
                .collect();
            group.sort_by(|a, b| b.h.total_cmp(&a.h));
            if group.len() < MIN_ROWS {
                let which = match (method.is_empty(), quantity.is_empty()) {
                    (true, true) => "the table".to_string(),
                    _ => format!("method '{method}', quantity '{quantity}'"),
                };
                return Err(Error::input(
                    &req.file,
                    "rows",
                    format!(
                        "{which} has {} row(s); a verdict needs at least {MIN_ROWS} levels: add the errors of finer (or coarser) meshes",
                        group.len()
                    ),
                ));
            }
            let levels = levels_of(
                group
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (r.level.unwrap_or(i), r.h, r.dofs, r.error)),
            );
            let truth = group.iter().map(|r| r.truth_error).fold(0.0f64, f64::max);
            let applies = req.method.as_ref().is_none_or(|m| *m == method)
                && req.quantity.as_ref().is_none_or(|q| *q == quantity);
            let threshold = req.threshold.filter(|_| applies);
            let (assessment, outcome) =
                judge_levels(&levels, truth, false, threshold.map(Threshold::Rate)).map_err(
                    |e| {
                        Error::input(
                            &req.file,
                            "h",
                            format!("method '{method}', quantity '{quantity}': {e}"),
                        )
                    },
                )?;
            Ok(JudgedGroup {
                errors: levels.iter().map(|l| (l.level, l.h, l.error)).collect(),
                method,
                quantity,
                assessment,
                threshold,
                outcome,
            })
        })
        .collect()
}

/// The header row of `reader` (the file `path`): refused where the file is empty, or where
/// it is one cell holding another separator (';', a tab, spaces).
fn checked_headers(
    path: &Path,
    reader: &mut csv::Reader<std::fs::File>,
) -> Result<csv::StringRecord> {
    let headers = reader
        .headers()
        .map_err(|e| Error::input(path, "header", format!("{e}")))?
        .clone();
    if headers.iter().all(|h| h.is_empty()) {
        return Err(Error::input(
            path,
            "file",
            "the file is empty: give a header row h,error (and optionally level, dofs, method, quantity, truth_error) and one row per level",
        ));
    }
    if headers.len() == 1 {
        if let Some(sep) = [';', '\t', ' ']
            .into_iter()
            .find(|c| headers[0].contains(*c))
        {
            let name = match sep {
                ';' => "';'",
                '\t' => "a tab",
                _ => "spaces",
            };
            return Err(Error::input(
                path,
                "header",
                format!(
                    "the header is one column, '{}': its cells are separated by {name}; separate them by commas (h,error)",
                    &headers[0]
                ),
            ));
        }
    }
    Ok(headers)
}

/// A row the CSV reader refused, as one error naming the file and the row: a short or long
/// row says how many cells it has against the header.
fn row_error(path: &Path, row: usize, e: &csv::Error) -> Error {
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!(
            "it has {len} cell(s) and the header {expected_len}: give every row a value for each column of the header"
        ),
        _ => format!("{e}"),
    };
    Error::input(path, format!("row {row}"), message)
}

/// The rows of `path`, every cell checked: one error naming the file, the row (1 = the
/// first after the header) and the column.
fn read_rows(path: &Path) -> Result<Vec<Row>> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| {
            Error::input(
                path,
                "file",
                format!("cannot read ({e}); give a CSV file with a header row"),
            )
        })?;
    let headers = checked_headers(path, &mut reader)?;
    let col = |name: &str| headers.iter().position(|h| h == name);
    let need = |name: &str| {
        col(name).ok_or_else(|| {
            Error::input(
                path,
                name,
                format!(
                    "no column '{name}' (the header has: {}); the table needs columns h,error and may have level, dofs, method, quantity, truth_error",
                    headers.iter().collect::<Vec<_>>().join(", ")
                ),
            )
        })
    };
    let (h_col, e_col) = (need("h")?, need("error")?);
    let mut rows = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let row = i + 1;
        let record = record.map_err(|e| row_error(path, row, &e))?;
        let cell = |c: usize| record.get(c).unwrap_or("");
        let number = |name: &str, c: usize, positive: bool| -> Result<f64> {
            let text = cell(c);
            let v: f64 = text.parse().map_err(|_| {
                Error::input(
                    path,
                    format!("row {row}, column {name}"),
                    format!("'{text}' is not a number"),
                )
            })?;
            let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
            if !ok {
                let want = if positive {
                    "a positive number"
                } else {
                    "a number >= 0"
                };
                return Err(Error::input(
                    path,
                    format!("row {row}, column {name}"),
                    format!("{text}: give {want}"),
                ));
            }
            Ok(v)
        };
        rows.push(Row {
            method: col("method").map_or(String::new(), |c| cell(c).to_string()),
            quantity: col("quantity").map_or(String::new(), |c| cell(c).to_string()),
            level: match col("level") {
                Some(c) => Some(cell(c).parse().map_err(|_| {
                    Error::input(
                        path,
                        format!("row {row}, column level"),
                        format!("'{}' is not a level (0, 1, 2, ...)", cell(c)),
                    )
                })?),
                None => None,
            },
            h: number("h", h_col, true)?,
            error: number("error", e_col, false)?,
            dofs: match col("dofs") {
                Some(c) => number("dofs", c, true)?,
                None => f64::NAN,
            },
            truth_error: match col("truth_error") {
                Some(c) => number("truth_error", c, false)?,
                None => 0.0,
            },
        });
    }
    if rows.is_empty() {
        return Err(Error::input(
            path,
            "rows",
            "no rows after the header; give one row per level",
        ));
    }
    Ok(rows)
}

/// rates.csv (the studies' columns, the outcome in `pass`) and error_vs_h.png into `dir`,
/// all or nothing.
pub fn write_report(groups: &[JudgedGroup], file: &Path, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        let rows: Vec<RateRecord<String>> = groups
            .iter()
            .map(|g| {
                RateRecord::from_parts(
                    MethodLabel::parse(&g.method),
                    g.quantity.clone(),
                    None,
                    &g.assessment,
                    g.threshold,
                    g.outcome,
                )
            })
            .collect();
        write(d, "rates.csv", &csv_bytes(&rows)?)?;
        let mut series = Vec::new();
        for (i, g) in groups.iter().enumerate() {
            let name = group_name(g);
            series.push(Series {
                label: format!("{name}: {}", g.assessment.describe().replace("**", "")),
                points: g
                    .errors
                    .iter()
                    .map(|e| (e.1, e.2))
                    .filter(|p| p.1 > 0.0)
                    .collect(),
                markers: true,
                line: false,
                color: i,
                thin: false,
                shape: None,
            });
            if let Some(f) = g
                .assessment
                .fit
                .filter(|_| g.assessment.verdict.supports_rate())
            {
                let hs: Vec<f64> = g
                    .errors
                    .iter()
                    .filter(|e| g.assessment.used.contains(&e.0))
                    .map(|e| e.1)
                    .collect();
                let legend = format!("{name} fit: slope {:.2} ± {:.2}", f.rate, f.stderr);
                series.extend(plot::fit_line(legend, f.rate, f.intercept, &hs, i));
            }
        }
        plot::loglog(
            &d.join("error_vs_h.png"),
            &format!("{}: error against h", file.display()),
            "h",
            "error",
            &series,
            &[(0.5, "1/2"), (1.0, "1"), (2.0, "2")],
        )
    })
}

/// "method quantity", leaving out what the table did not name ("errors" where it names
/// neither).
pub fn group_name(g: &JudgedGroup) -> String {
    match (g.method.is_empty(), g.quantity.is_empty()) {
        (true, true) => "errors".into(),
        (true, false) => g.quantity.clone(),
        (false, true) => g.method.clone(),
        (false, false) => format!("{} {}", g.method, g.quantity),
    }
}

/// A group's verdict as one plain line: its rate or why there is none, the successive rates,
/// and the threshold's outcome with the numbers that decided it. The group's name leads
/// where the table names methods or quantities.
pub fn verdict_line(g: &JudgedGroup) -> String {
    let line = g.assessment.verdict_line(g.threshold.zip(g.outcome));
    match g.method.is_empty() && g.quantity.is_empty() {
        true => line,
        false => format!("{}: {line}", group_name(g)),
    }
}

/// One line per group ([`verdict_line`]).
pub fn console(groups: &[JudgedGroup]) -> String {
    groups.iter().map(|g| verdict_line(g) + "\n").collect()
}
