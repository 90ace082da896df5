//! The report of `study paper`: the paper's section-5 figures regenerated, with the numbers
//! behind its words.

use crate::error::Result;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, MeshPanel, Panel, Series};
use crate::studies::paper::{PaperResult, Run};
use std::fmt::Write as _;
use std::path::Path;
use crate::verify::kind::Outcome;

fn magnification(runs: &[&Run]) -> f64 {
    let mut umax = 0.0f64;
    let mut size = 0.0f64;
    for r in runs {
        umax = r
            .mesh
            .u
            .iter()
            .fold(umax, |a, u| a.max(u[0].abs()).max(u[1].abs()));
        let xs = r.mesh.nodes.iter().map(|p| p[0]);
        let ys = r.mesh.nodes.iter().map(|p| p[1]);
        let w = xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min);
        let h = ys.clone().fold(f64::NEG_INFINITY, f64::max) - ys.fold(f64::INFINITY, f64::min);
        size = size.max(w.max(h));
    }
    // Round to one significant digit so captions read well.
    let m = 0.08 * size / umax.max(f64::MIN_POSITIVE);
    let p = 10f64.powf(m.log10().floor());
    ((m / p).floor().max(1.0) * p * 1e6).round() / 1e6
}

fn pos(r: &Run, n: usize, mag: f64) -> [f64; 2] {
    let p = r.mesh.nodes[n];
    [p[0] + mag * r.mesh.u[n][0], p[1] + mag * r.mesh.u[n][1]]
}

fn mesh_panel(r: &Run, title: &str, mag: f64) -> MeshPanel {
    MeshPanel {
        title: title.into(),
        triangles: r
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|n| pos(r, n, mag)))
            .collect(),
        body: r.mesh.body.clone(),
        highlight: r
            .mesh
            .contact
            .iter()
            .map(|s| s.map(|n| pos(r, n, mag)))
            .collect(),
        nodes: [
            r.mesh.interface_nodes[0]
                .iter()
                .map(|&n| pos(r, n, mag))
                .collect(),
            r.mesh.interface_nodes[1]
                .iter()
                .map(|&n| pos(r, n, mag))
                .collect(),
        ],
        outline: Vec::new(),
    }
}

fn field_panel(r: &Run, title: &str, mag: f64, values: &[f64]) -> Panel {
    Panel {
        title: title.into(),
        triangles: r
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|n| pos(r, n, mag)))
            .collect(),
        values: values.to_vec(),
        body: r.mesh.body.clone(),
        highlight: r
            .mesh
            .contact
            .iter()
            .map(|s| s.map(|n| pos(r, n, mag)))
            .collect(),
    }
}

fn pressure_plot(path: &Path, title: &str, runs: &[&Run]) -> Result<()> {
    let series: Vec<Series> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| Series {
            label: r.label.clone(),
            points: r.pressure.clone(),
            markers: true,
            line: true,
            color: i,
            thin: false,
            shape: None,
        })
        .collect();
    plot::lines(
        path,
        title,
        "arclength along Gamma_C",
        "contact pressure (N/m)",
        &series,
    )
}

/// The runs of one test: meshes, solve and what contact and plasticity did.
fn runs_table(runs: &[&Run]) -> Table {
    let mut table = Table::new([
        "run",
        "level",
        "triangles (body 1 / 2)",
        "nodes (body 1 / 2)",
        "dofs",
        "time steps",
        "iterations (max per step)",
        "wall time (s)",
        "max interpenetration (m)",
        "contact fraction",
        "plastic fraction",
    ]);
    for r in runs {
        table.row([
            r.label.clone(),
            r.level.to_string(),
            format!("{} / {}", r.triangles[0], r.triangles[1]),
            format!("{} / {}", r.nodes[0], r.nodes[1]),
            r.dofs.to_string(),
            r.steps.to_string(),
            format!("{} ({})", r.iterations.0, r.iterations.1),
            format!("{:.3}", r.wall_s),
            format!("{:.3e}", r.max_penetration),
            format!("{:.3}", r.contact_fraction),
            format!("{:.3}", r.plastic_fraction),
        ]);
    }
    table
}

/// Write reports/paper (or `dir`).
pub fn write_paper(res: &PaperResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        let mut doc = Doc::new();
        doc.heading(1, "The paper's numerical tests, regenerated")
            .paragraph(format!(
                "Fernandez-Garcia, Hild and Viano, section 5. Their figures are missing from our copy, so each geometry is reconstructed from the text (stated below); the data are the paper's (E, nu, lambda, sigma_Y, loads, T = 1). All runs: `newton` solver, 10 uniform time steps, non-matching meshes unless stated. Regenerate with `cargo run --release -- study paper` ({:.0} s).",
                res.wall_s
            ));
        test1(res, d, &mut doc)?;
        test2(res, d, &mut doc)?;
        test3(res, d, &mut doc)?;
        write(d, "README.md", doc.finish().as_bytes())
    })
}

/// Test 1 (straight contact line): mesh, von Mises, pressure, table.
fn test1(res: &PaperResult, d: &Path, doc: &mut Doc) -> Result<()> {
    let (m1, n1) = (&res.test1[0], &res.test1[1]);
    let mag1 = magnification(&[m1]);
    plot::mesh_panels(
        &d.join("test1_mesh.png"),
        "Test 1 (Fig. 3): non-matching meshes; contact line in red",
        &[mesh_panel(
            m1,
            "body 1 (left, blue) and body 2 (right, orange)",
            0.0,
        )],
    )?;
    plot::field_panels(
        &d.join("test1_von_mises.png"),
        &format!("Test 1 (Fig. 4): von Mises stress at T = 1 with K_h^pi, deformed x{mag1}"),
        "von Mises stress (N/m^2)",
        &[field_panel(m1, "K_h^pi (mortar)", mag1, &m1.mesh.von_mises)],
    )?;
    pressure_plot(
        &d.join("test1_pressure.png"),
        "Test 1: contact pressure along Gamma_C at T = 1",
        &[m1, n1],
    )?;
    doc.heading(2, "Test 1: straight contact line").paragraph(format!(
        "Reconstruction: body 1 = [0,1]x[0,1] embedded on its left side x = 0, body 2 = [1,2]x[0.25,0.75]; symmetry (u_y = 0, zero tangential traction) on the upper and lower sides of both bodies, body 1's right side free outside the contact line; contact line x = 1, 0.25 <= y <= 0.75 (body 1 carries the constraint); a pressure of magnitude 10 t on body 2's right side pushing the bodies together (the paper prints g^2 = (10t, 0); with body 2 on the right this is (-10 t, 0) in our axes). E = 100, nu = 0.3, lambda = 100, sigma_Y = sqrt(10). Mesh sizes 0.12 and 0.0985 give {} and {} triangles (paper: 214 and 141).",
        m1.triangles[0], m1.triangles[1]
    ))
    .image("mesh", "test1_mesh.png")
    .image("von Mises", "test1_von_mises.png")
    .image("pressure", "test1_pressure.png")
    .table(&runs_table(&[m1, n1]))
    .paragraph(format!(
        "Max interpenetration {:.3e} m with K_h^pi against {:.3e} m with K_h^I.",
        m1.max_penetration, n1.max_penetration
    ));
    Ok(())
}

/// Test 2 (the patch test): deformed sigma_22, pressure, table, the paper's words measured.
fn test2(res: &PaperResult, d: &Path, doc: &mut Doc) -> Result<()> {
    let (m2, n2) = (&res.test2[0], &res.test2[1]);
    let mag2 = magnification(&[m2, n2]);
    let t = &res.test2_numbers;
    plot::field_panels(
        &d.join("test2_deformed.png"),
        &format!("Test 2 (Figs. 5, 6): sigma_22 at T = 1, deformed x{mag2}, contact line in red"),
        "sigma_22 (N/m^2)",
        &[
            field_panel(m2, "K_h^pi (mortar): constant stress", mag2, &m2.mesh.s22),
            field_panel(n2, "K_h^I (node-on-segment)", mag2, &n2.mesh.s22),
        ],
    )?;
    pressure_plot(
        &d.join("test2_pressure.png"),
        "Test 2: contact pressure along Gamma_C at T = 1 (exact: 10)",
        &[m2, n2],
    )?;
    doc.heading(2, "Test 2: local against global contact conditions (patch test)")
        .paragraph("Reconstruction: two stacked unit blocks, upper [0,1]x[1,2] (body 1), lower [0,1]x[0,1]; symmetry on both right sides (u_x = 0) and on the bottom (u_y = 0); pressure g^1 = (0, -10 t) on the top; no body force; E = 3e5, nu = 0.3, lambda = 100, sigma_Y = sqrt(10). The upper block is held vertically only by contact. Exact solution: sigma = diag(0, -10 t) in both bodies (the paper prints sigma_22 = 10 t for the compressive stress).")
        .image("deformed", "test2_deformed.png")
        .image("pressure", "test2_pressure.png")
        .table(&runs_table(&[m2, n2]))
        .paragraph("The paper's words, measured:")
        .list([
            format!(
                "K_h^pi, \"the obtained stress field is constant\": max over all triangles and steps of |sigma - diag(0, -10 t)| / (10 t) = **{:.2e}**; at T: max |sigma_11| = {:.2e}, max |sigma_12| = {:.2e}, sigma_22 in [{:.12}, {:.12}].",
                t.mortar_stress_error,
                t.mortar_s11_s12.0,
                t.mortar_s11_s12.1,
                t.mortar_s22.0,
                t.mortar_s22.1,
            ),
            format!(
                "K_h^pi, \"no interpenetration\": largest interpenetration {:.2e} of max |u|.",
                t.mortar_penetration
            ),
            format!(
                "K_h^I, \"non negligible penetration\": largest interpenetration {:.3e} m = **{:.2e}** of max |u|.",
                t.nts_penetration.0, t.nts_penetration.1
            ),
            format!(
                "K_h^I, \"artificial stresses near the contact zone\": largest |sigma - exact| / 10 at T = **{:.3}**, in the triangle centred at ({:.3}, {:.3}).",
                t.nts_stress_error.0, t.nts_stress_error.1[0], t.nts_stress_error.1[1]
            ),
        ]);
    Ok(())
}

/// Test 3 (piecewise-straight contact line): meshes, von Mises, pressure, agreement with
/// matching meshes.
fn test3(res: &PaperResult, d: &Path, doc: &mut Doc) -> Result<()> {
    let (m3, n3, mm3) = (&res.test3[0], &res.test3[1], &res.test3[2]);
    test3_figures(res, d)?;
    let mut agreement = Table::new(["level", "h", "relative difference"]);
    for (l, h, dd) in &res.test3_agreement {
        agreement.row([l.to_string(), format!("{h:.4}"), format!("{dd:.3e}")]);
    }
    doc.heading(2, "Test 3: piecewise-straight contact line")
        .paragraph("Reconstruction: lower body (body 2) between y = 0 (embedded) and the contact line (0,1)-(0.6,1)-(0.9,1.3)-(1.1,1.3)-(1.4,1)-(2,1) (five straight pieces, a trapezoidal bump), u_x = 0 on its vertical sides; upper body (body 1) between the contact line and y = 2, u_x = 0 on its vertical sides, g^1 = (0, -10 t) on its top. E = 100, nu = 0.3, lambda = 1000, sigma_Y = sqrt(10). Mesh sizes 0.15 (body 1) and 0.11 (body 2); the matching meshes let body 1 reuse body 2's contact lines. Corner nodes carry one constraint per piece.")
        .image("meshes", "test3_meshes.png")
        .image("von Mises", "test3_von_mises.png")
        .image("matching", "test3_matching.png")
        .image("matching von Mises", "test3_matching_von_mises.png")
        .image("pressure", "test3_pressure.png")
        .table(&runs_table(&[m3, n3, mm3]))
        .paragraph("\"Good agreement\" with the matching meshes, measured: relative difference of the K_h^pi solutions on non-matching and matching meshes in the theorem norm max_n (||u - u_m||_H1 + ||sigma - sigma_m||_L2) / max_n (||u_m||_H1 + ||sigma_m||_L2), both meshes refined together:")
        .table(&agreement);
    if res.test3_agreement.len() >= 2 {
        let hs: Vec<f64> = res.test3_agreement.iter().map(|a| a.1).collect();
        let ds: Vec<f64> = res.test3_agreement.iter().map(|a| a.2).collect();
        if let Some(f) = crate::verify::rates::fit(&hs, &ds) {
            doc.paragraph(format!(
                "The difference shrinks like h^{:.2} (least squares over the levels above).",
                f.rate
            ));
        }
    }
    Ok(())
}

/// Test 3's figures (Figs. 8-11 and the pressure): non-matching and matching meshes,
/// initial and deformed, von Mises stress.
fn test3_figures(res: &PaperResult, d: &Path) -> Result<()> {
    let (m3, n3, mm3) = (&res.test3[0], &res.test3[1], &res.test3[2]);
    let mag3 = magnification(&[m3, mm3]);
    plot::mesh_panels(
        &d.join("test3_meshes.png"),
        &format!("Test 3 (Fig. 8): non-matching meshes, initial and deformed x{mag3} with K_h^pi"),
        &[
            mesh_panel(m3, "initial", 0.0),
            mesh_panel(m3, &format!("deformed x{mag3}"), mag3),
        ],
    )?;
    plot::field_panels(
        &d.join("test3_von_mises.png"),
        &format!(
            "Test 3 (Fig. 9): von Mises stress at T = 1, non-matching meshes, K_h^pi, deformed x{mag3}"
        ),
        "von Mises stress (N/m^2)",
        &[field_panel(
            m3,
            "non-matching, K_h^pi",
            mag3,
            &m3.mesh.von_mises,
        )],
    )?;
    plot::mesh_panels(
        &d.join("test3_matching.png"),
        &format!("Test 3 (Fig. 10): matching meshes, initial and deformed x{mag3}"),
        &[
            mesh_panel(mm3, "initial", 0.0),
            mesh_panel(mm3, &format!("deformed x{mag3}"), mag3),
        ],
    )?;
    plot::field_panels(
        &d.join("test3_matching_von_mises.png"),
        &format!("Test 3 (Fig. 11): von Mises stress at T = 1, matching meshes, deformed x{mag3}"),
        "von Mises stress (N/m^2)",
        &[field_panel(mm3, "matching", mag3, &mm3.mesh.von_mises)],
    )?;
    pressure_plot(
        &d.join("test3_pressure.png"),
        "Test 3: contact pressure along Gamma_C at T = 1",
        &[m3, n3, mm3],
    )?;
    Ok(())
}

/// What `study paper` prints: Test 2's numbers, Test 3's agreement, and where the report
/// went.
pub fn console(res: &PaperResult, dir: &Path) -> String {
    let mut s = String::new();
    let t = &res.test2_numbers;
    let _ = writeln!(
        s,
        "Test 2: mortar stress error {:.2e}, nts interpenetration {:.3e} ({:.2e} of max |u|), nts spurious stress {:.3}",
        t.mortar_stress_error, t.nts_penetration.0, t.nts_penetration.1, t.nts_stress_error.0
    );
    for (l, h, d) in &res.test3_agreement {
        let _ = writeln!(
            s,
            "Test 3: level {l} h {h:.4}: non-matching vs matching {d:.3e}"
        );
    }
    let _ = writeln!(s, "wrote {} ({:.1} s)", dir.display(), res.wall_s);
    s
}

/// The kind's outcome writes this report.
impl Outcome for PaperResult {
    fn write(&self, dir: &Path) -> Result<()> {
        write_paper(self, dir)
    }
    fn console(&self, dir: &Path) -> String {
        console(self, dir)
    }
}
