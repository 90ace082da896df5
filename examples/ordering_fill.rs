//! Fill and numeric cost of the stiffness's sparse LDL^T under four orderings, per body,
//! on the meshes of `study speed`'s families (the `rates` scene with h_upper = 0.28 and
//! h_lower = 0.28 / 1.4142 at level 0; level 7 has 2,196,480 dofs) (issue 24, part 2): faer's AMD (the floor's ordering), METIS's
//! nested dissection (`METIS_NodeND` through metis-sys, the maintained raw binding: the
//! `metis` crate wraps only the partitioners), and each of the two on the body's interior
//! with the contact interface's unknowns last (the default solver's ordering with AMD).
//!
//! `cargo run --release --example ordering_fill -- LEVEL...` prints per level and ordering
//! the seconds of the ordering, the stored entries of L (supernodal, the values faer
//! allocates), the flops of the factorization counted from the supernodes, and the
//! seconds of one numeric LDL^T
//! (sequential, bodies one after the other). Timings are single runs: read them with the
//! flops beside them.
use contact_rates::solve::{Problem, interface::interface_last_order, newton::FLOOR_SHIFT};
use contact_rates::{case::Case, contact::Method, fe::Pattern, scene::Scene};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};
use std::time::Instant;

/// The four orderings compared.
#[derive(Clone, Copy, Debug)]
enum Ordering {
    Amd,
    Metis,
    /// METIS on the graph of the nodes (runs of equations with the same pattern column: a
    /// node's two unknowns), expanded to the equations.
    MetisNodes,
    AmdInterfaceLast,
    MetisInterfaceLast,
}

/// The symmetric pattern of `vertices` (indices into `pattern`'s block) without the
/// diagonal, renumbered 0..vertices.len().
fn subgraph(pattern: &Pattern, vertices: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut index = vec![usize::MAX; pattern.n];
    for (k, &v) in vertices.iter().enumerate() {
        index[v] = k;
    }
    let (mut ptr, mut adj) = (vec![0usize], Vec::new());
    for &v in vertices {
        for &r in &pattern.row_idx[pattern.col_ptr[v]..pattern.col_ptr[v + 1]] {
            if r != v && index[r] != usize::MAX {
                adj.push(index[r]);
            }
        }
        ptr.push(adj.len());
    }
    (ptr, adj)
}

/// faer's AMD of a graph (both triangles, no diagonal needed).
fn amd_order(ptr: Vec<usize>, adj: Vec<usize>) -> Vec<usize> {
    let n = ptr.len() - 1;
    let graph = SymbolicSparseColMat::new_checked(n, n, ptr, None, adj);
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let mut buffer =
        MemBuffer::try_new(amd::order_scratch::<usize>(n, graph.row_idx().len())).unwrap();
    amd::order(
        &mut fwd,
        &mut inv,
        graph.as_ref(),
        Default::default(),
        MemStack::new(&mut buffer),
    )
    .unwrap();
    fwd
}

/// METIS's nested dissection of a graph (no diagonal), default options.
fn metis_order(ptr: Vec<usize>, adj: Vec<usize>) -> Vec<usize> {
    let mut n = (ptr.len() - 1) as metis_sys::idx_t;
    let mut xadj: Vec<metis_sys::idx_t> = ptr.iter().map(|&x| x as _).collect();
    let mut adjncy: Vec<metis_sys::idx_t> = adj.iter().map(|&x| x as _).collect();
    let mut perm = vec![0 as metis_sys::idx_t; n as usize];
    let mut iperm = vec![0 as metis_sys::idx_t; n as usize];
    // SAFETY: the arrays have the lengths METIS_NodeND reads (n + 1, xadj[n], n, n);
    // null vertex weights and options select METIS's defaults.
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut n,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    assert_eq!(
        status,
        metis_sys::rstatus_et_METIS_OK,
        "METIS_NodeND failed"
    );
    perm.iter().map(|&p| p as usize).collect()
}

/// The elimination order of one body's block under `ordering` (`interface`: the block's
/// equations on Gamma_C).
fn order(block: &Pattern, interface: &[bool], ordering: Ordering) -> Vec<usize> {
    let all: Vec<usize> = (0..block.n).collect();
    let interior: Vec<usize> = (0..block.n).filter(|&e| !interface[e]).collect();
    let last: Vec<usize> = (0..block.n).filter(|&e| interface[e]).collect();
    let then_interface = |inner: Vec<usize>| -> Vec<usize> {
        inner
            .into_iter()
            .map(|k| interior[k])
            .chain(last.iter().copied())
            .collect()
    };
    match ordering {
        Ordering::Amd => {
            let (p, a) = subgraph(block, &all);
            amd_order(p, a)
        }
        Ordering::Metis => {
            let (p, a) = subgraph(block, &all);
            metis_order(p, a)
        }
        Ordering::MetisNodes => {
            let column = |e: usize| &block.row_idx[block.col_ptr[e]..block.col_ptr[e + 1]];
            // Supervariables: runs of consecutive equations with identical columns.
            let mut first = vec![0usize];
            for e in 1..block.n {
                if column(e) != column(e - 1) {
                    first.push(e);
                }
            }
            first.push(block.n);
            let nodes = first.len() - 1;
            let mut node_of = vec![0usize; block.n];
            for v in 0..nodes {
                node_of[first[v]..first[v + 1]].fill(v);
            }
            let (mut ptr, mut adj) = (vec![0usize], Vec::new());
            for v in 0..nodes {
                let mut neighbours: Vec<usize> = column(first[v])
                    .iter()
                    .map(|&r| node_of[r])
                    .filter(|&w| w != v)
                    .collect();
                neighbours.dedup();
                adj.extend(neighbours);
                ptr.push(adj.len());
            }
            metis_order(ptr, adj)
                .into_iter()
                .flat_map(|v| first[v]..first[v + 1])
                .collect()
        }
        Ordering::AmdInterfaceLast => interface_last_order(block, interface).unwrap(),
        Ordering::MetisInterfaceLast => {
            let (p, a) = subgraph(block, &interior);
            then_interface(metis_order(p, a))
        }
    }
}

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
    // A supernode of c columns over r rows below: c^3/3 for its diagonal block, c^2 r for
    // the panel, c r^2 for the update of the rows below (multiply-adds).
    let (begin, end, row_ptr) = (
        sym.supernode_begin(),
        sym.supernode_end(),
        sym.col_ptr_for_row_idx(),
    );
    let flops: f64 = (0..sym.n_supernodes())
        .map(|s| {
            let c = (end[s] - begin[s]) as f64;
            let r = (row_ptr[s + 1] - row_ptr[s]) as f64;
            c * c * c / 3.0 + c * c * r + c * r * r
        })
        .sum();
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
        let case = Case::build(&scene, level, Method::Mortar, &sizes).unwrap();
        let p: &Problem = &case.problem;
        let model = &p.model;
        let n = model.n_free;
        let (pattern, slots) = model.stiffness_pattern(&[], n);
        let mut values = vec![0.0; pattern.nnz()];
        model.add_tangent(&model.elastic_tangents(), &slots, &mut values);
        // The floor's shift: a body held only by contact stays factorizable.
        let mean = (0..n).map(|i| values[pattern.slot(i, i)]).sum::<f64>() / n as f64;
        for i in 0..n {
            values[pattern.slot(i, i)] += FLOOR_SHIFT * mean;
        }
        let mut on_interface = vec![false; n];
        for row in &p.rows {
            for &(d, _) in &row.entries {
                if let Some(&eq) = model.equation.get(d).filter(|&&e| e < n) {
                    on_interface[eq] = true;
                }
            }
        }
        let b = on_interface.iter().filter(|&&x| x).count();
        for ordering in [
            Ordering::Amd,
            Ordering::Metis,
            Ordering::MetisNodes,
            Ordering::AmdInterfaceLast,
            Ordering::MetisInterfaceLast,
        ] {
            let (mut entries, mut flops, mut seconds, mut ordering_s) = (0, 0.0, 0.0, 0.0);
            for range in pattern.diagonal_blocks() {
                let (block, slice) = pattern.block(&range);
                let t = Instant::now();
                let order = order(&block, &on_interface[range.clone()], ordering);
                ordering_s += t.elapsed().as_secs_f64();
                let (e, f, s) = factor(&block, &values[slice], &order);
                entries += e;
                flops += f;
                seconds += s;
            }
            println!(
                "| {level} | {n} | {b} | {ordering:?} | {ordering_s:.2} | {entries} | {flops:.3e} | {seconds:.2} |"
            );
        }
    }
}
