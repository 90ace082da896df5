//! The forward and back substitutions with a supernodal factor L (unit lower triangular),
//! and the split of a factor's elimination tree into subtrees that are substituted side by
//! side on rayon's threads.
//!
//! A supernode's columns update only rows of its ancestors in the elimination tree, so two
//! disjoint subtrees are independent in a forward substitution except for the rows of their
//! common ancestors, and in a back substitution they only read those rows. A [`Subtree`] is
//! substituted on a vector of its own (its columns, then the rows outside it that it
//! updates or reads), and the updates of the outside rows are added afterwards, subtree by
//! subtree in a fixed order: the sums, hence the results, do not depend on the threads.
//! The supernodes outside every subtree (the top of the tree: separators and the contact
//! interface) are substituted after them (forward) or before them (back).
//!
//! Why: the two bodies are factorized apart, one block each, and their substitutions ran
//! side by side, but the blocks differ in size (at 137,472 dofs of `rates`: 45,312 and
//! 92,160 equations), so the larger one set the time: one preconditioner solve 9.3 ms on
//! two threads against 13.5 ms on one.
//!
//! Arithmetic: a subtree's vector is in the arithmetic X of [`Lift`]: f32 beside newton's
//! f32 factor, f64 beside an f64 one; the tops (separators, and the contact interface
//! whose dense blocks are f64) stay in f64. Why: with f32 the subtrees read half the
//! bytes of their vector and use twice the SIMD lanes, and the preconditioner's error is
//! the f32 factor's already. Measured with `examples/substitutions.rs` (one preconditioner
//! solve, 2 threads, two runs alternating): at 137,472 dofs 7.23-7.26 -> 5.99-6.13 ms
//! fastest of 50 (median 7.87-7.88 -> 6.31-6.44 ms), at 34,432 dofs 1.34-1.40 -> 1.24-1.32
//! ms fastest of 100; newton's preconditioner applications per `rates` run stay 28 and 24.

use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A stored value of the factor: f64, or f32 for a preconditioner; also the arithmetic
/// of a substitution ([`Lift`]).
pub trait Value:
    faer::traits::RealField
    + Copy
    + Send
    + Sync
    + Default
    + std::ops::Add<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::AddAssign
    + std::ops::SubAssign
    + std::iter::Sum
    + 'static
{
    /// Zero.
    const ZERO: Self;
    /// The value in f64.
    fn get(self) -> f64;
    /// The value rounded from f64.
    fn from_f64(v: f64) -> Self;
}
impl Value for f64 {
    const ZERO: Self = 0.0;
    fn get(self) -> f64 {
        self
    }
    fn from_f64(v: f64) -> Self {
        v
    }
}
impl Value for f32 {
    const ZERO: Self = 0.0;
    fn get(self) -> f64 {
        self as f64
    }
    fn from_f64(v: f64) -> Self {
        v as f32
    }
}

/// The arithmetic X of a substitution with a factor of precision T: f64 (any factor), or
/// f32 beside an f32 factor (half the bytes of the vector, twice the SIMD lanes).
pub trait Lift<T>: Value {
    /// The value in X.
    fn lift(t: T) -> Self;
}
impl<T: Value> Lift<T> for f64 {
    fn lift(t: T) -> f64 {
        t.get()
    }
}
impl Lift<f32> for f32 {
    fn lift(t: f32) -> f32 {
        t
    }
}

/// sum_k l_k x_k, with eight partial sums (one AVX-512 register of f64, two of AVX2; half
/// a register in f32, where the count was kept, not measured again): one running sum is
/// bound by the latency of the addition. Measured in f64 with
/// `examples/substitutions.rs` (one preconditioner solve, 2 threads, fastest of 100): back
/// substitution 0.675 -> 0.48 ms at 34,432 dofs and 4.7 -> 3.9-4.0 ms at 137,472 against
/// four partial sums; sixteen were slower (0.58 ms: the columns' off-diagonal parts are
/// short, and more of each falls to the serial remainder), and two columns at a time
/// slower still (0.68-0.77 ms).
fn dot<T: Value, X: Lift<T>>(l: &[T], x: &[X]) -> X {
    const W: usize = 8;
    let mut sums = [X::ZERO; W];
    let (l_chunks, x_chunks) = (l.chunks_exact(W), x.chunks_exact(W));
    let rest: X = (l_chunks.remainder().iter().zip(x_chunks.remainder()))
        .map(|(&a, &b)| X::lift(a) * b)
        .sum();
    for (a, b) in l_chunks.zip(x_chunks) {
        for k in 0..W {
            sums[k] += X::lift(a[k]) * b[k];
        }
    }
    sums.iter().copied().sum::<X>() + rest
}

/// One supernode as the substitutions see it: (first column, width, off-diagonal row
/// indices, values: the width columns of the diagonal block and the off-diagonal rows,
/// column-major).
pub type Supernode<'a, T, I> = (usize, usize, &'a [I], &'a [T]);

/// A row index as stored: usize in faer's structure, u32 in a [`Subtree`]'s own (half the
/// bytes of a copy made once per mesh).
pub trait Row: Copy + Send + Sync + 'static {
    /// The index.
    fn at(self) -> usize;
}
impl Row for usize {
    fn at(self) -> usize {
        self
    }
}
impl Row for u32 {
    fn at(self) -> usize {
        self as usize
    }
}

/// Columns whose off-diagonal parts one pass of [`forward`] adds into the rows below a
/// supernode: each row's partial sum is loaded and stored once per four columns instead of
/// once per column. Each row's terms are still added in column order: the same bits.
/// Measured with `examples/substitutions.rs` (one preconditioner solve, fastest of 50,
/// three runs alternating with the column-by-column loop, same bits): forward substitution
/// at 34,432 dofs 1.03-1.07 -> 0.93-0.95 ms on one thread, at 137,472 dofs 3.27-3.75 ->
/// 3.14-3.37 ms on two. Eight columns per pass were no faster (1.01-1.10 ms), and the
/// same grouping of the back substitution's dot products (four chains of additions side
/// by side, by hand in AVX-512 or left to LLVM) was slower (1.18-1.39 against 1.02-1.05
/// ms): it computes the off-diagonal dots before the diagonal block's, a second pass over
/// each supernode.
const COLUMNS: usize = 4;

/// x <- L^{-1} x over `supernodes` (increasing). Per supernode: the triangular solve on
/// its diagonal block, column by column; then the off-diagonal rows' sums
/// `sum_j L_kj x_j` over the columns with x_j != 0, [`COLUMNS`] columns per pass,
/// gathered once and scattered once. A solve reads the factor once.
pub fn forward<'a, T: Value, I: Row, X: Lift<T>>(
    supernodes: impl Iterator<Item = Supernode<'a, T, I>>,
    x: &mut [X],
) {
    let mut below = Vec::new();
    let mut nonzero = Vec::new();
    for (start, width, pattern, values) in supernodes {
        let p = pattern.len();
        let rows = width + p;
        nonzero.clear();
        for j in 0..width {
            let xj = x[start + j];
            if xj == X::ZERO {
                continue;
            }
            nonzero.push(j);
            let column = &values[j * rows..j * rows + width];
            for (xi, &l) in x[start + j + 1..start + width]
                .iter_mut()
                .zip(&column[j + 1..width])
            {
                *xi -= X::lift(l) * xj;
            }
        }
        below.clear();
        below.resize(p, X::ZERO);
        let below = &mut below[..p];
        let off = |j: usize| &values[j * rows + width..(j + 1) * rows];
        let mut groups = nonzero.chunks_exact(COLUMNS);
        for group in &mut groups {
            let [c0, c1, c2, c3] = [off(group[0]), off(group[1]), off(group[2]), off(group[3])];
            let [x0, x1, x2, x3] = [
                x[start + group[0]],
                x[start + group[1]],
                x[start + group[2]],
                x[start + group[3]],
            ];
            let (c0, c1, c2, c3) = (&c0[..p], &c1[..p], &c2[..p], &c3[..p]);
            for k in 0..p {
                let mut t = below[k];
                t += X::lift(c0[k]) * x0;
                t += X::lift(c1[k]) * x1;
                t += X::lift(c2[k]) * x2;
                t += X::lift(c3[k]) * x3;
                below[k] = t;
            }
        }
        for &j in groups.remainder() {
            let xj = x[start + j];
            for (bk, &l) in below.iter_mut().zip(off(j)) {
                *bk += X::lift(l) * xj;
            }
        }
        for (&i, &bk) in pattern.iter().zip(&*below) {
            x[i.at()] -= bk;
        }
    }
}

/// x <- L^{-T} x over `supernodes` (decreasing).
pub fn back<'a, T: Value, I: Row, X: Lift<T>>(
    supernodes: impl Iterator<Item = Supernode<'a, T, I>>,
    x: &mut [X],
) {
    let mut below = Vec::new();
    for (start, width, pattern, values) in supernodes {
        let rows = width + pattern.len();
        below.clear();
        below.extend(pattern.iter().map(|&i| x[i.at()]));
        for j in (0..width).rev() {
            let column = &values[j * rows..(j + 1) * rows];
            x[start + j] -= dot(&column[width..], &below)
                + dot(&column[j + 1..width], &x[start + j + 1..start + width]);
        }
    }
}

/// The supernodal structure of a factor: per supernode its first column (and one past
/// the last: `begin[s + 1]`), its off-diagonal rows (`rows[row_ptr[s]..row_ptr[s + 1]]`)
/// and its values (`val_ptr[s]..val_ptr[s + 1]`).
#[derive(Clone, Copy)]
pub struct Structure<'a> {
    /// First column of each supernode, and n at the end.
    pub begin: &'a [usize],
    /// Start of each supernode's off-diagonal rows in `rows`.
    pub row_ptr: &'a [usize],
    /// Off-diagonal rows, increasing per supernode.
    pub rows: &'a [usize],
    /// Start of each supernode's values.
    pub val_ptr: &'a [usize],
}

impl<'a> Structure<'a> {
    /// Number of supernodes.
    pub fn n_supernodes(&self) -> usize {
        self.begin.len() - 1
    }

    /// Supernode `s` of the factor with values `values`, in the block's own numbering.
    pub fn supernode<T: Value>(&self, values: &'a [T], s: usize) -> Supernode<'a, T, usize> {
        (
            self.begin[s],
            self.begin[s + 1] - self.begin[s],
            self.pattern(s),
            &values[self.val_ptr[s]..self.val_ptr[s + 1]],
        )
    }

    fn pattern(&self, s: usize) -> &'a [usize] {
        &self.rows[self.row_ptr[s]..self.row_ptr[s + 1]]
    }

    /// The values a substitution reads in supernode `s` (its cost).
    fn weight(&self, s: usize) -> usize {
        self.val_ptr[s + 1] - self.val_ptr[s]
    }

    /// The supernode of each column.
    fn of_column(&self) -> Vec<usize> {
        let mut of_column = vec![0; *self.begin.last().unwrap_or(&0)];
        for s in 0..self.n_supernodes() {
            of_column[self.begin[s]..self.begin[s + 1]].fill(s);
        }
        of_column
    }

    /// The children of each supernode in the elimination tree (a supernode's parent is
    /// the supernode of its first off-diagonal row), and the roots.
    fn tree(&self, of_column: &[usize]) -> (Vec<Vec<usize>>, Vec<usize>) {
        let mut children = vec![Vec::new(); self.n_supernodes()];
        let mut roots = Vec::new();
        for s in 0..self.n_supernodes() {
            match self.pattern(s).first() {
                Some(&i) => children[of_column[i]].push(s),
                None => roots.push(s),
            }
        }
        (children, roots)
    }
}

/// A subtree of one block's elimination tree (closed under descendants), with its own
/// numbering: its columns 0..k, then the rows outside it that its supernodes touch.
pub struct Subtree {
    /// Its supernodes, increasing.
    supernodes: Vec<usize>,
    /// Its columns (increasing): local 0..k.
    columns: Vec<usize>,
    /// Rows outside the subtree its supernodes touch (increasing): local k.. .
    outside: Vec<usize>,
    /// Per supernode (in `supernodes`' order): local first column.
    start: Vec<usize>,
    /// Per supernode: start of its local off-diagonal rows in `rows` (and the end).
    row_ptr: Vec<usize>,
    /// Off-diagonal rows in local numbering.
    rows: Vec<u32>,
    /// Values of the subtree (weight of [`Structure::weight`]).
    weight: usize,
}

impl Subtree {
    /// The subtree below `root` (its descendants: `children` lists them). `of_column`:
    /// [`Structure::of_column`].
    fn new(
        structure: &Structure,
        children: &[Vec<usize>],
        root: usize,
        of_column: &[usize],
    ) -> Self {
        // Per supernode: in the subtree; per column: local number.
        let mut inside = vec![false; structure.n_supernodes()];
        let mut local = vec![0; of_column.len()];
        let mut supernodes = vec![root];
        let mut next = 0;
        while next < supernodes.len() {
            supernodes.extend_from_slice(&children[supernodes[next]]);
            next += 1;
        }
        supernodes.sort_unstable();
        let mut columns = Vec::new();
        let mut start = Vec::with_capacity(supernodes.len());
        for &s in &supernodes {
            inside[s] = true;
            start.push(columns.len());
            for c in structure.begin[s]..structure.begin[s + 1] {
                local[c] = columns.len();
                columns.push(c);
            }
        }
        let mut outside: Vec<usize> = supernodes
            .iter()
            .flat_map(|&s| structure.pattern(s).iter().copied())
            .filter(|&i| !inside[of_column[i]])
            .collect();
        outside.sort_unstable();
        outside.dedup();
        let k = columns.len();
        for (j, &i) in outside.iter().enumerate() {
            local[i] = k + j;
        }
        let mut row_ptr = vec![0];
        let mut rows = Vec::new();
        for &s in &supernodes {
            rows.extend(structure.pattern(s).iter().map(|&i| local[i] as u32));
            row_ptr.push(rows.len());
        }
        let weight = supernodes.iter().map(|&s| structure.weight(s)).sum();
        Subtree {
            supernodes,
            columns,
            outside,
            start,
            row_ptr,
            rows,
            weight,
        }
    }

    /// The subtree's supernodes in local numbering, increasing.
    fn local<'a, T: Value>(
        &'a self,
        structure: &'a Structure,
        values: &'a [T],
    ) -> impl DoubleEndedIterator<Item = Supernode<'a, T, u32>> + 'a {
        self.supernodes.iter().enumerate().map(move |(k, &s)| {
            (
                self.start[k],
                structure.begin[s + 1] - structure.begin[s],
                &self.rows[self.row_ptr[k]..self.row_ptr[k + 1]],
                &values[structure.val_ptr[s]..structure.val_ptr[s + 1]],
            )
        })
    }
}

/// One block's elimination tree split: subtrees, and the top (every other supernode,
/// increasing: closed under ancestors).
pub struct Split {
    /// Disjoint subtrees.
    subtrees: Vec<Subtree>,
    /// Supernodes in no subtree, increasing.
    top: Vec<usize>,
}

/// Subtrees below this many values are not split further (their halves would cost less
/// than the scheduling).
const SMALLEST_SPLIT: usize = 20_000;

/// Subtrees are split until none holds more than this fraction of all the blocks' work:
/// four or more pieces for two threads, scheduled as they come free.
const LARGEST_SHARE: f64 = 0.2;

/// The tops may hold at most this fraction of the blocks' work.
const TOP_SHARE: f64 = 0.15;

/// Split the elimination trees of the blocks `structures` into subtrees: starting from
/// the roots, the heaviest subtree is replaced by its children (its root joins its
/// block's top) while it holds more than [`LARGEST_SHARE`] of the work, the tops hold
/// less than [`TOP_SHARE`] and it is worth splitting ([`SMALLEST_SPLIT`]). The split
/// depends on the structures only, never on the threads at hand.
pub fn split(structures: &[Structure]) -> Vec<Split> {
    let of_column: Vec<Vec<usize>> = structures.iter().map(Structure::of_column).collect();
    let (children, roots): (Vec<Vec<Vec<usize>>>, Vec<Vec<usize>>) = (structures.iter())
        .zip(&of_column)
        .map(|(st, of)| st.tree(of))
        .unzip();
    // Subtree weights, children before parents (a child's index is below its parent's).
    let weights: Vec<Vec<usize>> = structures
        .iter()
        .zip(&children)
        .map(|(st, ch)| {
            let mut w: Vec<usize> = (0..st.n_supernodes()).map(|s| st.weight(s)).collect();
            for s in 0..w.len() {
                w[s] += ch[s].iter().map(|&c| w[c]).sum::<usize>();
            }
            w
        })
        .collect();
    let total: usize = structures
        .iter()
        .map(|st| (0..st.n_supernodes()).map(|s| st.weight(s)).sum::<usize>())
        .sum();
    // Candidates (block, root), the heaviest last.
    let weight = |&(b, s): &(usize, usize)| weights[b][s];
    let mut candidates: Vec<(usize, usize)> = (roots.iter().enumerate())
        .flat_map(|(b, r)| r.iter().map(move |&s| (b, s)))
        .collect();
    let mut tops: Vec<Vec<usize>> = vec![Vec::new(); structures.len()];
    let mut top_work = 0;
    loop {
        candidates.sort_by_key(|c| (weight(c), std::cmp::Reverse(*c)));
        let Some(&(b, s)) = candidates.last() else {
            break;
        };
        let own = structures[b].weight(s);
        if (weight(&(b, s)) as f64) <= LARGEST_SHARE * total as f64
            || weight(&(b, s)) < SMALLEST_SPLIT
            || (top_work + own) as f64 > TOP_SHARE * total as f64
        {
            break;
        }
        candidates.pop();
        tops[b].push(s);
        top_work += own;
        candidates.extend(children[b][s].iter().map(|&c| (b, c)));
    }
    // Per block, the subtrees heaviest first: the order they are scheduled in. Each built
    // on its own, on rayon's threads: the same subtrees on any number.
    candidates.reverse();
    let subtrees: Vec<Subtree> = candidates
        .par_iter()
        .map(|&(b, root)| Subtree::new(&structures[b], &children[b], root, &of_column[b]))
        .collect();
    let mut splits: Vec<Split> = (tops.into_iter())
        .map(|mut top| {
            top.sort_unstable();
            Split {
                subtrees: Vec::new(),
                top,
            }
        })
        .collect();
    for (&(b, _), subtree) in candidates.iter().zip(subtrees) {
        splits[b].subtrees.push(subtree);
    }
    splits
}

/// A lock that a panic elsewhere does not poison for the substitutions (they only read
/// and write numbers).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// x <- L^{-1} x for every block (`x`: the blocks' vectors, elimination order), the
/// subtrees in the factor's own arithmetic T and the tops in f64 (see the module). The
/// subtrees of all blocks are tasks on rayon's threads, the blocks with the most work
/// first; the task that finishes a block's last subtree adds their updates of the outside
/// rows (subtree by subtree, in a fixed order) and substitutes the block's top, while the
/// other threads go on with the next subtrees.
pub fn forward_blocks<T: Lift<T>>(
    splits: &[Split],
    structures: &[Structure],
    values: &[&[T]],
    x: &mut [Vec<f64>],
) {
    let blocks: Vec<Mutex<&mut Vec<f64>>> = x.iter_mut().map(Mutex::new).collect();
    let parts: Vec<Vec<Mutex<Vec<T>>>> = (splits.iter())
        .map(|s| s.subtrees.iter().map(|_| Mutex::new(Vec::new())).collect())
        .collect();
    let remaining: Vec<AtomicUsize> = (splits.iter())
        .map(|s| AtomicUsize::new(s.subtrees.len()))
        .collect();
    let top = |b: usize| {
        let mut xb = lock(&blocks[b]);
        for (subtree, part) in splits[b].subtrees.iter().zip(&parts[b]) {
            let z = std::mem::take(&mut *lock(part));
            let k = subtree.columns.len();
            for (&i, &v) in subtree.columns.iter().zip(&z[..k]) {
                xb[i] = v.get();
            }
            for (&i, &v) in subtree.outside.iter().zip(&z[k..]) {
                xb[i] += v.get();
            }
        }
        let (split, st, v) = (&splits[b], &structures[b], values[b]);
        forward(split.top.iter().map(|&s| st.supernode(v, s)), &mut xb);
    };
    rayon::scope_fifo(|scope| {
        for b in by_work(splits) {
            if splits[b].subtrees.is_empty() {
                scope.spawn_fifo(move |_| top(b));
            }
            for (t, subtree) in splits[b].subtrees.iter().enumerate() {
                let (top, blocks, parts, remaining) = (&top, &blocks, &parts, &remaining);
                scope.spawn_fifo(move |_| {
                    let mut z: Vec<T> = {
                        let xb = lock(&blocks[b]);
                        subtree
                            .columns
                            .iter()
                            .map(|&i| T::from_f64(xb[i]))
                            .collect()
                    };
                    z.resize(subtree.columns.len() + subtree.outside.len(), T::ZERO);
                    forward(subtree.local(&structures[b], values[b]), &mut z);
                    *lock(&parts[b][t]) = z;
                    if remaining[b].fetch_sub(1, Ordering::AcqRel) == 1 {
                        top(b);
                    }
                });
            }
        }
    });
}

/// x <- L^{-T} x for every block: each block's top, then its subtrees, as tasks on
/// rayon's threads (the blocks with the most work first).
pub fn back_blocks<T: Lift<T>>(
    splits: &[Split],
    structures: &[Structure],
    values: &[&[T]],
    x: &mut [Vec<f64>],
) {
    let blocks: Vec<Mutex<&mut Vec<f64>>> = x.iter_mut().map(Mutex::new).collect();
    let subtree = |b: usize, subtree: &Subtree| {
        let mut z: Vec<T> = {
            let xb = lock(&blocks[b]);
            (subtree.columns.iter())
                .chain(&subtree.outside)
                .map(|&i| T::from_f64(xb[i]))
                .collect()
        };
        back(subtree.local(&structures[b], values[b]).rev(), &mut z);
        let mut xb = lock(&blocks[b]);
        for (&i, &v) in subtree.columns.iter().zip(&z) {
            xb[i] = v.get();
        }
    };
    rayon::scope_fifo(|scope| {
        for b in by_work(splits) {
            let (subtree, blocks) = (&subtree, &blocks);
            scope.spawn_fifo(move |scope| {
                {
                    let (split, st, v) = (&splits[b], &structures[b], values[b]);
                    let mut xb = lock(&blocks[b]);
                    back(split.top.iter().rev().map(|&s| st.supernode(v, s)), &mut xb);
                }
                for t in &splits[b].subtrees {
                    scope.spawn_fifo(move |_| subtree(b, t));
                }
            });
        }
    });
}

/// The blocks, the most work first.
fn by_work(splits: &[Split]) -> Vec<usize> {
    let work = |s: &Split| s.subtrees.iter().map(|t| t.weight).sum::<usize>();
    let mut order: Vec<usize> = (0..splits.len()).collect();
    order.sort_by_key(|&b| (std::cmp::Reverse(work(&splits[b])), b));
    order
}
