//! Fill and numeric cost of the stiffness's sparse LDL^T under four orderings, per body,
//! on the meshes of `study speed`'s families (the `rates` scene with h_upper = 0.28 and
//! h_lower = 0.28 / 1.4142 at level 0; level 7 has 2,196,480 dofs) (issue 24, part 2):
//! faer's AMD, METIS's nested dissection on the graph of the nodes (`METIS_NodeND` through
//! metis-sys), and each of the two on the body's interior with the contact interface's
//! unknowns last (the solver's ordering), all from `solve::ordering` (which chooses
//! between AMD and METIS by size for the floor and the solver).
//!
//! `cargo run --release --example ordering_fill -- LEVEL...` prints per level and ordering
//! the seconds of the ordering, the stored entries of L (supernodal, the values faer
//! allocates), the flops of the factorization counted from the supernodes, and the
//! seconds of one numeric LDL^T
//! (sequential, bodies one after the other). Timings are single runs: read them with the
//! flops beside them.
use contact_rates::solve::ordering::{self, Method};
use contact_rates::solve::{Problem, floor::shifted_stiffness};
use contact_rates::{case::Case, contact::Method as ContactMethod, fe::Pattern, scene::Scene};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};
use std::time::Instant;

/// The four orderings compared: (name, method, interface last).
const ORDERINGS: [(&str, Method, bool); 4] = [
    ("Amd", Method::Amd, false),
    ("MetisNodes", Method::Metis, false),
    ("AmdInterfaceLast", Method::Amd, true),
    ("MetisInterfaceLast", Method::Metis, true),
];

/// (stored entries of L, flops, seconds of one numeric LDL^T) of `values` on `block` in
/// the order `order`.
fn factor(block: &Pattern, values: &[f64], order: &[usize]) -> (usize, f64, f64) {
    let n = block.n;
    let mut position = vec![0usize; n];
    for (p, &e) in order.iter().enumerate() {
        position[e] = p;
    }
    let pattern =
        SymbolicSparseColMat::new_checked(n, n, block.col_ptr.clone(), None, block.row_idx.clone());
    let symbolic = factorize_symbolic_cholesky(
        pattern.as_ref(),
        Side::Lower,
        SymmetricOrdering::Custom(PermRef::new_checked(order, &position, n)),
        CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .unwrap();
    let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
        unreachable!("supernodal forced")
    };
    let flops = ordering::flops(sym);
    let mut l_values = vec![0.0; symbolic.len_val()];
    let mut buffer = MemBuffer::try_new(
        symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
    )
    .unwrap();
    let t = Instant::now();
    symbolic
        .factorize_numeric_ldlt(
            &mut l_values,
            SparseColMatRef::new(pattern.as_ref(), values),
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut buffer),
            Default::default(),
        )
        .unwrap();
    (symbolic.len_val(), flops, t.elapsed().as_secs_f64())
}

fn main() {
    let scene = Scene::load("rates").unwrap();
    let levels: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("levels are integers"))
        .collect();
    println!(
        "| level | dofs | interface dofs | ordering | ordering (s) | entries of L | flops | numeric LDL^T (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for level in levels {
        let sizes = [
            ("h_upper".to_string(), 0.28),
            ("h_lower".to_string(), 0.28 / 1.4142),
        ];
        let case = Case::build(&scene, level, ContactMethod::Mortar, &sizes).unwrap();
        let p: &Problem = &case.problem;
        let model = &p.model;
        let n = model.n_free;
        // The floor's shift: a body held only by contact stays factorizable.
        let (pattern, values, _) = shifted_stiffness(model);
        let mut on_interface = vec![false; n];
        for row in &p.rows {
            for &(d, _) in &row.entries {
                if let Some(&eq) = model.equation.get(d).filter(|&&e| e < n) {
                    on_interface[eq] = true;
                }
            }
        }
        let b = on_interface.iter().filter(|&&x| x).count();
        for (name, method, interface_last) in ORDERINGS {
            let (mut entries, mut flops, mut seconds, mut ordering_s) = (0, 0.0, 0.0, 0.0);
            for range in pattern.diagonal_blocks() {
                let (block, slice) = pattern.block(&range);
                let t = Instant::now();
                let last = match interface_last {
                    true => on_interface[range.clone()].to_vec(),
                    false => vec![false; block.n],
                };
                let order = ordering::order(&block, &last, Some(method), range.start).unwrap();
                ordering_s += t.elapsed().as_secs_f64();
                let (e, f, s) = factor(&block, &values[slice], &order);
                entries += e;
                flops += f;
                seconds += s;
            }
            println!(
                "| {level} | {n} | {b} | {name} | {ordering_s:.2} | {entries} | {flops:.3e} | {seconds:.2} |"
            );
        }
    }
}
