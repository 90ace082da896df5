//! The polygonal boundaries against their curves in a convergence report, for a scene
//! whose levels are split on its curves: per level the largest sagitta, the slivers' area
//! and the exact solution's theorem norm on them beside each method's theorem-norm error, each
//! series judged by the one rule ([`crate::verify::rates::assess`]). The errors are
//! integrals over the discrete domain Omega_h, with the exact fields evaluated there as
//! expressions on the plane: the slivers are what Omega_h leaves out of Omega (or adds),
//! the part an error over Omega would differ by.

use super::StudyResult;
use crate::report::markdown::{Doc, Table};
use crate::verify::geometry::GeometryRow;
use crate::verify::judge::levels_of;
use crate::verify::quantity::Quantity;
use crate::verify::rates::assess;

/// The judged rate of one column of geometry.csv.
fn judged(rows: &[GeometryRow], value: impl Fn(&GeometryRow) -> Option<f64>) -> String {
    let levels = levels_of(
        rows.iter()
            .filter_map(|g| value(g).map(|v| (g.level, g.h, 0.0, v))),
    );
    assess(&levels, 0.0).map_or("-".into(), |a| a.describe())
}

/// The section, where the study's levels are split on the scene's curves.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    if res.geometry.is_empty() {
        return;
    }
    let methods = &res.file.methods;
    let mut header: Vec<String> = [
        "level",
        "h",
        "largest sagitta",
        "slivers' area / |Omega_h|",
        "exact theorem norm on the slivers (relative)",
    ]
    .map(String::from)
    .to_vec();
    header.extend(methods.iter().map(|m| format!("{m}: theorem error")));
    header.push("slivers / smallest theorem error".into());
    let mut table = Table::new(header);
    let mut worst = 0.0f64;
    for g in &res.geometry {
        let errors: Vec<Option<f64>> = methods
            .iter()
            .map(|&m| res.error(m, g.level, Quantity::Theorem))
            .collect();
        let smallest = errors.iter().flatten().fold(f64::INFINITY, |a, &b| a.min(b));
        let share = g.sliver_energy.map(|e| e / smallest).filter(|r| r.is_finite());
        worst = worst.max(share.unwrap_or(0.0));
        let mut cells = vec![
            g.level.to_string(),
            format!("{:.4}", g.h),
            format!("{:.3e}", g.max_sagitta),
            format!("{:.3e}", g.relative_area),
            g.sliver_energy.map_or("-".into(), |e| format!("{e:.3e}")),
        ];
        cells.extend(errors.iter().map(|e| e.map_or("-".into(), |e| format!("{e:.3e}"))));
        cells.push(share.map_or("-".into(), |r| format!("{r:.3}")));
        table.row(cells);
    }
    doc.heading(2, "The polygonal boundaries against the curves")
        .paragraph(format!(
            "Every level is level 0 split in a gmsh session that has the .geo's curves (`refinement = \"curved\"`: gmsh's RefineMesh puts each new boundary node on its curve), so the boundary nodes lie on the arcs and the chords converge to them: the largest sagitta rate {}, the slivers' area rate {} (geometry.csv; read from each mesh: the circle through a boundary edge and its neighbours). The errors are integrals over the discrete domain Omega_h, the exact fields evaluated there as expressions on the plane; the slivers between the chords and the arcs lie outside it (on a convex arc) or outside Omega (on a concave one). The exact solution's theorem norm on them, relative to its norm on Omega_h (rate {}), is at most {worst:.3} of the smallest relative theorem-norm error at any level: measured over Omega instead (a convex arc's sliver lies outside Omega_h, where the error is at most the exact solution there if u_h is extended by 0 or better; a concave arc's lies inside Omega_h, and an error over Omega leaves it out), an error would be at most {:.3} (= 1 + {worst:.3}) times the one printed{}.",
            judged(&res.geometry, |g| Some(g.max_sagitta)),
            judged(&res.geometry, |g| Some(g.relative_area)),
            judged(&res.geometry, |g| g.sliver_energy),
            1.0 + worst,
            match worst < 1.0 {
                true => ", with the rate unchanged where both fall at one rate",
                false => ": the slivers are not below what the errors measure",
            },
        ))
        .table(&table);
}
