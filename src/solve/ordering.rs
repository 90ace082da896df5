//! The fill-reducing ordering of one diagonal block (a body) of the stiffness, written once
//! for the floor ([`super::floor_time`]), the solver ([`super::interface`]) and
//! `examples/ordering_fill.rs`: faer's AMD, or METIS's nested dissection (`METIS_NodeND`
//! through metis-sys, which builds METIS from its vendored C source) on the graph of the
//! nodes (a node's unknowns collapsed into one vertex), optionally with some equations (the
//! contact interface) last.
//!
//! Measured with `examples/ordering_fill.rs` on the meshes of `study speed` (one numeric
//! LDL^T, sequential, both bodies, interface last): nested dissection needs fewer flops
//! than AMD from 1e4 dofs on (3.9e9 against 2.1e9 at 1.4e5 dofs, 4.5e10 against 1.8e10 at
//! 5.5e5, 4.2e11 against 1.5e11 at 2.2e6), but METIS orders 4-5x slower than AMD: at 5.5e5
//! dofs (bodies of 1.8e5 and 3.7e5 equations) it spends 1.0-1.5 s more ordering than it
//! saves in the numeric factorization (2.0 s against 1.4-1.7 s), at 2.2e6 dofs (7.2e5 and
//! 1.5e6) it saves about 9 s of numeric work (16.1 s against 7.3 s) for 4 s more ordering.
//! [`Method::for_size`] chooses by the block's size ([`METIS_FROM`]).

use super::pieces;
use crate::error::{Error, Result};
use crate::fe::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::Mutex;

/// A fill-reducing ordering.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// faer's approximate minimum degree, on the equations.
    Amd,
    /// METIS's nested dissection (`METIS_NodeND`, fixed seed) on the graph of the nodes.
    Metis,
}

/// Blocks with at least this many equations (ordered ones, the interface excluded) are
/// ordered by METIS, smaller ones by AMD (see the module).
pub const METIS_FROM: usize = 500_000;

/// METIS's random seed (its default, stated: the orderings, hence the factors and the
/// solutions, are the same from run to run).
const METIS_SEED: metis_sys::idx_t = 4321;

/// Refinement iterations of METIS's separators (its default: 10); with coarsening by
/// random matching (default: sorted heavy-edge). Measured at 2.2e6 dofs: 5.9 s instead of
/// 7.2 s to order both bodies, for 1.30e11 flops instead of 1.29e11 (1.49e11 instead of
/// 1.44e11 with the interface last); at 5.5e5 dofs 1.4 s instead of 1.85 s.
const METIS_NITER: metis_sys::idx_t = 1;

/// METIS keeps its random generator's state in globals (GKlib's Mersenne twister, not
/// thread-local): two orderings at once on two threads would draw from one sequence in
/// an order that changes from run to run. One at a time.
static METIS: Mutex<()> = Mutex::new(());

impl Method {
    /// The ordering of a block of `n` equations to order.
    pub fn for_size(n: usize) -> Method {
        if n >= METIS_FROM {
            Method::Metis
        } else {
            Method::Amd
        }
    }
}

/// `f` of each diagonal block (`blocks`: equation ranges) on rayon's threads, the largest
/// block started first (an ordering by METIS waits for the other's, see [`METIS`]: the
/// smaller one then waits less), the results in the blocks' order.
pub fn largest_first<T: Send>(
    blocks: Vec<Range<usize>>,
    f: impl Fn(Range<usize>) -> Result<T> + Sync + Send,
) -> Result<Vec<T>> {
    let mut indexed: Vec<(usize, Range<usize>)> = blocks.into_iter().enumerate().collect();
    indexed.sort_by_key(|(i, r)| (std::cmp::Reverse(r.len()), *i));
    let mut results: Vec<(usize, T)> = indexed
        .into_par_iter()
        .map(|(i, r)| f(r).map(|t| (i, t)))
        .collect::<Result<_>>()?;
    results.sort_by_key(|&(i, _)| i);
    Ok(results.into_iter().map(|(_, t)| t).collect())
}

/// The elimination order of one block (pattern with both triangles and the diagonal):
/// the equations not marked in `last`, ordered by `method` (None: [`Method::for_size`]),
/// then the marked ones in equation order. `first`: the block's first equation, to name
/// it in [`pieces`].
pub fn order(
    block: &Pattern,
    last: &[bool],
    method: Option<Method>,
    first: usize,
) -> Result<Vec<usize>> {
    let n = block.n;
    let ordered: Vec<usize> = (0..n).filter(|&e| !last[e]).collect();
    let method = method.unwrap_or_else(|| Method::for_size(ordered.len()));
    let inner = pieces::time(
        match method {
            Method::Amd => "order.amd",
            Method::Metis => "order.metis",
        },
        first,
        || match method {
            Method::Amd => amd_order(block, &ordered),
            Method::Metis => metis_order(block, &ordered),
        },
    )?;
    Ok(inner
        .into_iter()
        .map(|k| ordered[k])
        .chain((0..n).filter(|&e| last[e]))
        .collect())
}

/// faer's AMD of the equations `vertices` of `block` (their subgraph, numbered by their
/// position in `vertices`).
fn amd_order(block: &Pattern, vertices: &[usize]) -> Result<Vec<usize>> {
    let (col_ptr, row_idx) = (&block.col_ptr, &block.row_idx);
    let mut index = vec![usize::MAX; block.n];
    for (k, &e) in vertices.iter().enumerate() {
        index[e] = k;
    }
    let (mut ptr, mut rows) = (vec![0usize], Vec::new());
    for &e in vertices {
        rows.extend(
            row_idx[col_ptr[e]..col_ptr[e + 1]]
                .iter()
                .map(|&r| index[r])
                .filter(|&r| r != usize::MAX),
        );
        ptr.push(rows.len());
    }
    let m = vertices.len();
    let graph = SymbolicSparseColMat::new_checked(m, m, ptr, None, rows);
    let (mut fwd, mut inv) = (vec![0usize; m], vec![0usize; m]);
    let mut buffer = MemBuffer::try_new(amd::order_scratch::<usize>(m, graph.row_idx().len()))
        .map_err(|_| Error::NotConverged("out of memory in the ordering".into()))?;
    amd::order(
        &mut fwd,
        &mut inv,
        graph.as_ref(),
        Default::default(),
        MemStack::new(&mut buffer),
    )
    .map_err(|e| Error::NotConverged(format!("ordering failed: {e:?}")))?;
    Ok(fwd)
}

/// METIS's nested dissection of the equations `vertices` of `block` (numbered by their
/// position in `vertices`), on the graph of the nodes: runs of consecutive equations with
/// the same column (a node's unknowns) are one vertex, and are eliminated together.
fn metis_order(block: &Pattern, vertices: &[usize]) -> Result<Vec<usize>> {
    let (col_ptr, row_idx) = (&block.col_ptr, &block.row_idx);
    let column = |e: usize| &row_idx[col_ptr[e]..col_ptr[e + 1]];
    // first[v]..first[v + 1]: the positions in `vertices` of node v's equations.
    let mut first = vec![0usize];
    for k in 1..vertices.len() {
        let (a, b) = (vertices[k - 1], vertices[k]);
        if b != a + 1 || column(a) != column(b) {
            first.push(k);
        }
    }
    first.push(vertices.len());
    let nodes = first.len() - 1;
    let mut node_of = vec![usize::MAX; block.n];
    for v in 0..nodes {
        for &e in &vertices[first[v]..first[v + 1]] {
            node_of[e] = v;
        }
    }
    let too_large = || Error::NotConverged("graph too large for METIS's 32-bit indices".into());
    let (mut xadj, mut adjncy): (Vec<metis_sys::idx_t>, Vec<metis_sys::idx_t>) =
        (vec![0], Vec::new());
    for v in 0..nodes {
        // The rows are increasing and the node numbers increase with them: repeated
        // neighbours are adjacent.
        let mut previous = usize::MAX;
        for &r in column(vertices[first[v]]) {
            let w = node_of[r];
            if w != usize::MAX && w != v && w != previous {
                adjncy.push(w.try_into().map_err(|_| too_large())?);
                previous = w;
            }
        }
        xadj.push(adjncy.len().try_into().map_err(|_| too_large())?);
    }
    let mut n: metis_sys::idx_t = nodes.try_into().map_err(|_| too_large())?;
    let mut perm = vec![0 as metis_sys::idx_t; nodes];
    let mut iperm = vec![0 as metis_sys::idx_t; nodes];
    if nodes > 0 {
        let mut options = [0 as metis_sys::idx_t; metis_sys::METIS_NOPTIONS as usize];
        let _one_at_a_time = METIS.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: the arrays have the lengths METIS reads (options: METIS_NOPTIONS; xadj:
        // n + 1; adjncy: xadj[n]; perm, iperm: n); null vertex weights.
        let status = unsafe {
            metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
            options[metis_sys::moptions_et_METIS_OPTION_SEED as usize] = METIS_SEED;
            options[metis_sys::moptions_et_METIS_OPTION_NITER as usize] = METIS_NITER;
            options[metis_sys::moptions_et_METIS_OPTION_CTYPE as usize] =
                metis_sys::mctype_et_METIS_CTYPE_RM as metis_sys::idx_t;
            metis_sys::METIS_NodeND(
                &mut n,
                xadj.as_mut_ptr(),
                adjncy.as_mut_ptr(),
                std::ptr::null_mut(),
                options.as_mut_ptr(),
                perm.as_mut_ptr(),
                iperm.as_mut_ptr(),
            )
        };
        if status != metis_sys::rstatus_et_METIS_OK {
            return Err(Error::NotConverged(format!(
                "METIS_NodeND failed ({status})"
            )));
        }
    }
    Ok(perm
        .iter()
        .flat_map(|&v| first[v as usize]..first[v as usize + 1])
        .collect())
}

/// (columns, rows below) of each supernode of a supernodal factor.
fn supernode_shapes(
    symbolic: &SymbolicSupernodalCholesky<usize>,
) -> impl Iterator<Item = (usize, usize)> + '_ {
    let (begin, end, row_ptr) = (
        symbolic.supernode_begin(),
        symbolic.supernode_end(),
        symbolic.col_ptr_for_row_idx(),
    );
    (0..symbolic.n_supernodes()).map(move |s| (end[s] - begin[s], row_ptr[s + 1] - row_ptr[s]))
}

/// The flops of a supernodal factorization (a multiply-add counts 2, as in a dense
/// Cholesky's n^3/3): a supernode of c columns over r rows below costs c^3/3 for its
/// diagonal block, c^2 r for its panel (c^2 r / 2 multiply-adds) and c r^2 for the update
/// of the lower triangle of the rows below (c r^2 / 2 multiply-adds).
pub fn flops(symbolic: &SymbolicSupernodalCholesky<usize>) -> f64 {
    supernode_shapes(symbolic).map(supernode_flops).sum()
}

/// [`flops`] of one supernode of c columns over r rows below.
fn supernode_flops((c, r): (usize, usize)) -> f64 {
    let (c, r) = (c as f64, r as f64);
    c * c * c / 3.0 + c * c * r + c * r * r
}

/// The flops of one numeric factorization with `symbolic` (a multiply-add counts 2): [`flops`] for a
/// supernodal factor, and for a simplicial one the same count per column (a supernode of
/// one column).
pub fn factor_flops(symbolic: &SymbolicCholesky<usize>) -> f64 {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let col_ptr = s.col_ptr();
            // Each column a supernode of one column over its entries below the diagonal.
            (0..s.ncols())
                .map(|j| supernode_flops((1, (col_ptr[j + 1] - col_ptr[j]).saturating_sub(1))))
                .sum()
        }
        SymbolicCholeskyRaw::Supernodal(s) => flops(s),
    }
}

/// The fill of a Cholesky factor: the entries of L on and below its diagonal that the
/// factor stores and computes with. A simplicial factor stores exactly the structural
/// nonzeros; a supernodal one (faer's, with relaxed supernodes) also the explicit zeros
/// of its amalgamated supernodes: a supernode of c columns over r rows below counts
/// c (c + 1) / 2 + c r (the dense upper triangle of its diagonal block, stored but never
/// used, is not counted).
pub fn factor_entries(symbolic: &SymbolicCholesky<usize>) -> usize {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => s.len_val(),
        SymbolicCholeskyRaw::Supernodal(s) => supernodal_entries(s),
    }
}

/// [`factor_entries`] of a supernodal factor.
pub fn supernodal_entries(symbolic: &SymbolicSupernodalCholesky<usize>) -> usize {
    supernode_shapes(symbolic)
        .map(|(c, r)| c * (c + 1) / 2 + c * r)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;
    use faer::perm::PermRef;
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::linalg::cholesky::{
        CholeskySymbolicParams, SymmetricOrdering, factorize_symbolic_cholesky,
    };

    /// Goal: the fill of a simplicial factor is the structural fill of the ordering
    /// (computed here by eliminating the graph vertex by vertex), and a supernodal factor
    /// of the same ordering stores at least that (its relaxed supernodes add zeros).
    /// Geometry: the 5-point Laplacian's pattern on a 30 x 30 grid; ordering: AMD.
    #[test]
    fn simplicial_fill_is_the_structural_fill_and_supernodal_stores_at_least_it() {
        let m = 30;
        let id = |i: usize, j: usize| i * m + j;
        let mut entries = Vec::new();
        for i in 0..m {
            for j in 0..m {
                entries.push((id(i, j), id(i, j)));
                if i + 1 < m {
                    entries.extend([(id(i, j), id(i + 1, j)), (id(i + 1, j), id(i, j))]);
                }
                if j + 1 < m {
                    entries.extend([(id(i, j), id(i, j + 1)), (id(i, j + 1), id(i, j))]);
                }
            }
        }
        let pattern = Pattern::from_entries(m * m, entries);
        let n = pattern.n;
        let order = order(&pattern, &vec![false; n], Some(Method::Amd), 0).unwrap();
        let mut position = vec![0usize; n];
        for (p, &e) in order.iter().enumerate() {
            position[e] = p;
        }
        let graph = SymbolicSparseColMat::new_checked(
            n,
            n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let fill = |threshold| {
            let symbolic = factorize_symbolic_cholesky(
                graph.as_ref(),
                Side::Lower,
                SymmetricOrdering::Custom(PermRef::new_checked(&order, &position, n)),
                CholeskySymbolicParams {
                    supernodal_flop_ratio_threshold: threshold,
                    ..Default::default()
                },
            )
            .unwrap();
            let supernodal = matches!(symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_));
            (factor_entries(&symbolic), supernodal)
        };
        // Eliminate the vertices in `order`: each one's later neighbours become a clique;
        // the column of L of a vertex is itself and its later neighbours at elimination.
        let mut adjacent: Vec<std::collections::BTreeSet<usize>> = (0..n)
            .map(|e| {
                pattern.row_idx[pattern.col_ptr[e]..pattern.col_ptr[e + 1]]
                    .iter()
                    .map(|&r| position[r])
                    .filter(|&p| p != position[e])
                    .collect()
            })
            .collect();
        adjacent = (0..n)
            .map(|p| std::mem::take(&mut adjacent[order[p]]))
            .collect();
        let mut exact = 0;
        for p in 0..n {
            let later: Vec<usize> = adjacent[p].iter().copied().filter(|&q| q > p).collect();
            exact += 1 + later.len();
            for &a in &later {
                for &b in &later {
                    if a != b {
                        adjacent[a].insert(b);
                    }
                }
            }
        }
        let (simplicial, s) = fill(SupernodalThreshold::FORCE_SIMPLICIAL);
        let (supernodal, t) = fill(SupernodalThreshold::FORCE_SUPERNODAL);
        assert!(!s && t, "the two kinds of factor");
        assert_eq!(simplicial, exact);
        assert!(supernodal >= exact, "{supernodal} < {exact}");
    }
}
