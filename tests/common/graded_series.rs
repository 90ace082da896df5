//! Solutions of this project's solver written as an outside code writes them, for the
//! tests of `grade` (tests/test_grade_outside_code.rs, tests/test_grade_checks.rs): the mesh
//! of both bodies, the displacement, the P0 stress and the nodal pressure at the slave nodes
//! (0 elsewhere), one .vtu per step and a .pvd per level.
#![allow(dead_code)]

#[path = "solution_files.rs"]
mod solution_files;

use contact_rates::case::Case;
use contact_rates::solve::State;
pub use solution_files::{Encoding, Options, Solution};
use std::path::Path;

/// A solver state as an outside code writes it, with the displacement `u`.
pub fn outside(case: &Case, state: &State, u: &[f64]) -> Solution {
    let p = &case.problem;
    let m = &p.model;
    let mut pressure = vec![0.0; m.n_nodes];
    for (row, l) in p.rows.iter().zip(&state.lambda) {
        pressure[p.interface.pieces[row.piece].slave_nodes[row.i]] = row.pressure(*l);
    }
    Solution {
        points: (0..m.n_nodes).map(|g| m.position(g)).collect(),
        triangles: m.elements.iter().map(|e| e.nodes).collect(),
        body: m.elements.iter().map(|e| e.body as u8 + 1).collect(),
        displacement: (0..m.n_nodes).map(|g| [u[2 * g], u[2 * g + 1]]).collect(),
        stress: state.sigma.iter().map(|s| [s[0], s[1], s[2]]).collect(),
        pressure,
    }
}

/// `s` as a compressed appended-raw VTU at `path`.
pub fn write_vtu(path: &Path, s: &Solution) {
    let mut o = Options::new(Encoding::AppendedRaw);
    o.compressed = true;
    o.block_bytes = 1 << 15;
    std::fs::write(path, s.vtu("Float64").write(&o)).unwrap();
}

/// The states t_1..t_N (`states[0]` is t_0, not written) as `dir/level_L.pvd` with one
/// .vtu per step, each solution changed by `edit` before it is written.
pub fn write_states(
    dir: &Path,
    level: usize,
    case: &Case,
    states: &[State],
    edit: impl Fn(&mut Solution),
) {
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    for (n, s) in states.iter().enumerate().skip(1) {
        let name = format!("level_{level}_step_{n}.vtu");
        let mut written = outside(case, s, &s.u);
        edit(&mut written);
        write_vtu(&dir.join(&name), &written);
        pvd.push_str(&format!(
            "<DataSet timestep=\"{:e}\" file=\"{name}\"/>\n",
            s.time
        ));
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(dir.join(format!("level_{level}.pvd")), pvd).unwrap();
}
