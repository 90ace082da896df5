//! The floor a solver is judged by (SPEC section 7), measured on the same mesh and
//! machine: what the problem cannot avoid, from scratch. The pattern and values of the
//! elastic stiffness (assembled once), its ordering and symbolic analysis, and then the
//! faster of two ways to solve the systems the problem needs to the solver's tolerance:
//!
//! - **double**: one f64 sparse Cholesky and one forward-backward substitution per system;
//! - **single**: one f32 sparse Cholesky (half the bytes, twice the SIMD lanes) used as
//!   the preconditioner of conjugate gradients in f64, run per system until the relative
//!   residual is the solver's tolerance; where it is not reached within
//!   [`REFINEMENT_BUDGET`] applications, this way does not count and the double one is the
//!   floor.
//!
//! Both ways are timed in every measurement, after the shared part, and both times are
//! reported. The systems are those with distinct right-hand sides
//! ([`right_hand_sides`]): one for an elastic run under a proportional load, whose steps
//! are scalings of one solution, and one per step where a body is viscoplastic. The
//! stiffness is shifted by [`FLOOR_SHIFT`] times its mean diagonal, so that a body held
//! only by contact does not make it singular. The stiffness is block diagonal (one block
//! per body): every phase runs the blocks apart, side by side on rayon's threads, the
//! largest first, as the solver does.

use super::interface::Precision;
use super::linear::OrderedCholesky;
use super::{Problem, ordering, pieces};
use crate::error::Result;
use crate::fe::Pattern;
use rayon::prelude::*;
use std::ops::Range;
use std::time::Instant;

/// Shift added to the stiffness diagonal, relative to its mean diagonal: it makes the
/// stiffness of a body held only by contact positive definite and changes nothing the
/// floor measures (its cost).
pub const FLOOR_SHIFT: f64 = 1e-8;

/// Preconditioner applications per system after which the single way gives up.
pub const REFINEMENT_BUDGET: usize = 30;

/// Pivots of the f32 Cholesky below this, relative to the mean diagonal, are replaced
/// by [`SINGLE_PIVOT_REPLACEMENT`] (see [`OrderedCholesky::factor_single`]): f32 rounds
/// the stiffness by 6e-8 of its entries, more than the 1e-8 shift.
pub const SINGLE_PIVOT_EPSILON: f64 = 1e-6;
/// See [`SINGLE_PIVOT_EPSILON`].
pub const SINGLE_PIVOT_REPLACEMENT: f64 = 1e-6;

/// What one floor measurement found.
#[derive(Debug, Clone, Copy)]
pub struct Floor {
    /// The floor: the shared part plus the faster way (s).
    pub seconds: f64,
    /// The way that was faster.
    pub precision: Precision,
    /// The shared part: the stiffness's pattern and values, each block's ordering and
    /// symbolic analysis (s).
    pub shared_s: f64,
    /// The shared part plus the double way (s).
    pub double_s: f64,
    /// The shared part plus the single way (s); None where conjugate gradients missed the
    /// tolerance within [`REFINEMENT_BUDGET`] applications.
    pub single_s: Option<f64>,
    /// Systems solved: distinct right-hand sides ([`right_hand_sides`]).
    pub systems: usize,
    /// Applications of the f32 factor over all systems, the most of any block (the
    /// blocks run side by side), a block that missed the tolerance included (all its
    /// applications).
    pub single_applications: usize,
    /// Bytes the double way must read: its factor twice per system (L, then L^T), 8 per
    /// entry, summed over the blocks (index arrays left out: a lower bound).
    pub double_bytes: f64,
    /// Bytes the single way read: its factor twice per application, 4 per entry, and
    /// the stiffness once per product, 8 per entry (as [`Floor::double_bytes`]).
    pub single_bytes: f64,
    /// Entries of the Cholesky factor L, summed over the bodies' blocks
    /// ([`ordering::factor_entries`]).
    pub factor_entries: usize,
    /// Flops of one numeric factorization (a multiply-add counts 2), summed over the blocks
    /// ([`ordering::factor_flops`]).
    pub factor_flops: f64,
    /// Nonzeros of the stiffness, both triangles (each product reads them once).
    pub stiffness_entries: usize,
}

impl Floor {
    /// Each way at the faster of `self` and `other` (two measurements of the same floor:
    /// the same systems, fill and iterations), and the floor as the faster way. Each time
    /// is a whole measurement's (a way's includes its own shared part), and `shared_s` the
    /// faster of the two shared parts: the fastest of each, not one measurement's split.
    pub fn fastest(&self, other: &Floor) -> Floor {
        let double_s = self.double_s.min(other.double_s);
        let shared_s = self.shared_s.min(other.shared_s);
        // The measurement with the faster single way (the one that met the tolerance, if
        // only one did): its time and its work (the same work in both unless one missed).
        let single = match (self.single_s, other.single_s) {
            (None, Some(_)) => other,
            (Some(a), Some(b)) if b < a => other,
            _ => self,
        };
        let single_s = single.single_s;
        let (seconds, precision) = faster_way(double_s, single_s);
        Floor {
            seconds,
            precision,
            shared_s,
            double_s,
            single_s,
            single_applications: single.single_applications,
            single_bytes: single.single_bytes,
            ..*self
        }
    }
}

/// The floor's seconds and way: the single way where it met the tolerance and is faster
/// than the double way, else the double way.
fn faster_way(double_s: f64, single_s: Option<f64>) -> (f64, Precision) {
    match single_s {
        Some(s) if s < double_s => (s, Precision::Single),
        _ => (double_s, Precision::Double),
    }
}

/// Return the heap's free memory to the system (glibc's malloc_trim; nothing elsewhere):
/// the next run pays its page faults as a fresh process would. The floor calls it between
/// its two ways, untimed, so that the single way does not reuse pages the double way
/// touched; the speed study between runs.
pub fn release_free_heap() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // glibc's own function; no crate wraps it more simply than this declaration.
        unsafe extern "C" {
            fn malloc_trim(pad: usize) -> std::ffi::c_int;
        }
        // SAFETY: malloc_trim only releases free pages of the allocator's own arenas.
        unsafe {
            malloc_trim(0);
        }
    }
}

/// [`floor`]'s seconds.
pub fn floor_time(p: &Problem, steps: usize) -> Result<f64> {
    Ok(floor(p, steps)?.seconds)
}

/// The right-hand sides of a run of `steps` uniform steps over [0, T] that need a solve
/// of their own: the load at each step's end over the free dofs. Where no body is
/// viscoplastic, a load parallel to an earlier one (to 1e-12 of its largest entry) is
/// left out: the solver scales that solution. Zero loads are left out; a problem with
/// none gets one system of ones (the floor still factorizes and solves once). [`floor`]
/// puts ones in the part of a body loaded only through contact.
pub fn right_hand_sides(p: &Problem, steps: usize) -> Result<Vec<Vec<f64>>> {
    let model = &p.model;
    let viscoplastic = model.materials.iter().any(|m| m.viscoplastic.is_some());
    let k = model.scene.final_time / steps.max(1) as f64;
    let mut loads: Vec<Vec<f64>> = Vec::new();
    for step in 1..=steps {
        let load = model.restrict(&model.load(step as f64 * k)?);
        let largest = super::inf_norm(&load);
        if largest == 0.0 {
            continue;
        }
        let parallel = |earlier: &Vec<f64>| {
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let scale = dot(&load, earlier) / dot(earlier, earlier);
            load.iter()
                .zip(earlier)
                .all(|(l, e)| (l - scale * e).abs() <= 1e-12 * largest)
        };
        if viscoplastic || !loads.iter().any(parallel) {
            loads.push(load);
        }
    }
    if loads.is_empty() {
        loads.push(vec![1.0; model.n_free]);
    }
    Ok(loads)
}

/// The elastic stiffness of `model` over its free dofs (pattern with both triangles,
/// values in pattern order) with [`FLOOR_SHIFT`] times its mean diagonal added to the
/// diagonal, and that mean diagonal.
pub fn shifted_stiffness(model: &crate::fe::Model) -> (Pattern, Vec<f64>, f64) {
    let n = model.n_free;
    let (pattern, slots) = model.stiffness_pattern(&[], n);
    let mut values = vec![0.0; pattern.nnz()];
    model.add_tangent(&model.elastic_tangents(), &slots, &mut values);
    let diagonal: Vec<usize> = (0..n).map(|i| pattern.slot(i, i)).collect();
    let mean = diagonal.iter().map(|&s| values[s]).sum::<f64>() / n.max(1) as f64;
    for &s in &diagonal {
        values[s] += FLOOR_SHIFT * mean;
    }
    (pattern, values, mean)
}

/// One body's block: its equations, pattern, values' slots and factorizations.
struct Block {
    range: Range<usize>,
    pattern: Pattern,
    entries: Range<usize>,
    system: OrderedCholesky,
}

/// Measure the floor of `p` for a run of `steps` steps (see the module).
pub fn floor(p: &Problem, steps: usize) -> Result<Floor> {
    let mut loads = right_hand_sides(p, steps)?;
    let tol = super::Settings::default().tol;
    let t0 = Instant::now();
    let model = &p.model;
    let (pattern, values, mean_diagonal) =
        pieces::time("floor.stiffness", 0, || shifted_stiffness(model));
    // Shared: each block's ordering and symbolic analysis.
    let mut blocks = ordering::largest_first(pattern.diagonal_blocks(), |range| {
        let first = range.start;
        let (block, entries) = pieces::time("floor.block", first, || pattern.block(&range));
        let order = ordering::order(&block, &vec![false; block.n], None, first)?;
        let system = OrderedCholesky::new(&block, &order)?;
        pieces::record("floor.symbolic", first, system.symbolic_s);
        Ok(Block {
            range,
            pattern: block,
            entries,
            system,
        })
    })?;
    blocks.sort_by_key(|b| std::cmp::Reverse(b.range.len()));
    // A body loaded only through contact (its part of a load zero) gets ones there: the
    // solver's systems move it, and the floor's must cost it as much.
    for b in &blocks {
        for load in &mut loads {
            if load[b.range.clone()].iter().all(|&v| v == 0.0) {
                load[b.range.clone()].fill(1.0);
            }
        }
    }
    let shared_s = t0.elapsed().as_secs_f64();

    let t = Instant::now();
    blocks
        .par_iter_mut()
        .try_for_each(|b| solve_double(b, &values, &loads))?;
    let double_s = shared_s + t.elapsed().as_secs_f64();
    release_free_heap();

    let t = Instant::now();
    let epsilon = (SINGLE_PIVOT_EPSILON * mean_diagonal) as f32;
    let replacement = (SINGLE_PIVOT_REPLACEMENT * mean_diagonal) as f32;
    let outcomes = blocks
        .par_iter_mut()
        .map(|b| solve_single(b, &values, &loads, tol, (epsilon, replacement)))
        .collect::<Result<Vec<_>>>()?;
    let single_s = shared_s + t.elapsed().as_secs_f64();
    let single_s = outcomes.iter().all(|o| o.2).then_some(single_s);

    let (seconds, precision) = faster_way(double_s, single_s);
    pieces::record("floor.total", 0, seconds);
    Ok(Floor {
        seconds,
        precision,
        shared_s,
        double_s,
        single_s,
        systems: loads.len(),
        single_applications: outcomes.iter().map(|o| o.0).max().unwrap_or(0),
        double_bytes: blocks
            .iter()
            .map(|b| (loads.len() * 2 * b.system.factor_entries() * 8) as f64)
            .sum(),
        single_bytes: blocks
            .iter()
            .zip(&outcomes)
            .map(|(b, &(applications, products, _))| {
                (applications * 2 * b.system.factor_entries() * 4 + products * b.pattern.nnz() * 8)
                    as f64
            })
            .sum(),
        factor_entries: blocks.iter().map(|b| b.system.factor_entries()).sum(),
        factor_flops: blocks.iter().map(|b| b.system.factor_flops()).sum(),
        stiffness_entries: pattern.nnz(),
    })
}

/// The double way on one block: the f64 factorization and one substitution per load.
fn solve_double(b: &mut Block, values: &[f64], loads: &[Vec<f64>]) -> Result<()> {
    let first = b.range.start;
    b.system.factor(&values[b.entries.clone()])?;
    pieces::record("floor.numeric", first, b.system.factor_s);
    pieces::time("floor.solves", first, || {
        for load in loads {
            let mut x = load[b.range.clone()].to_vec();
            b.system.solve(&mut x);
        }
    });
    b.system.drop_double();
    Ok(())
}

/// The single way on one block: the f32 factorization, then conjugate gradients per
/// load to `tol`. The preconditioner applications and the products over all loads, and
/// whether every load met `tol`.
fn solve_single(
    b: &mut Block,
    values: &[f64],
    loads: &[Vec<f64>],
    tol: f64,
    (epsilon, replacement): (f32, f32),
) -> Result<(usize, usize, bool)> {
    let first = b.range.start;
    let t = Instant::now();
    let block_values = &values[b.entries.clone()];
    let single: Vec<f32> = block_values.iter().map(|&v| v as f32).collect();
    b.system.factor_single(&single, epsilon, replacement)?;
    drop(single);
    pieces::record("floor.numeric_single", first, t.elapsed().as_secs_f64());
    let product = |x: &[f64], y: &mut [f64]| symmetric_product(&b.pattern, block_values, x, y);
    // 10 eps |A| |x|_inf (|A| built at the first call).
    let abs = std::cell::OnceCell::new();
    let attainable = |x: &[f64]| {
        let abs: &Vec<f64> = abs.get_or_init(|| block_values.iter().map(|v| v.abs()).collect());
        let x: Vec<f64> = x.iter().map(|v| v.abs()).collect();
        let mut y = vec![0.0; x.len()];
        symmetric_product(&b.pattern, abs, &x, &mut y);
        10.0 * f64::EPSILON * super::inf_norm(&y)
    };
    let system = &b.system;
    let precondition = |r: &[f64], z: &mut [f64]| {
        let mut v: Vec<f32> = r.iter().map(|&x| x as f32).collect();
        system.solve_single(&mut v);
        z.iter_mut().zip(&v).for_each(|(z, &v)| *z = v as f64);
    };
    Ok(pieces::time("floor.refinement", first, || {
        let (mut applications, mut products, mut converged) = (0, 0, true);
        for load in loads {
            let b = &load[b.range.clone()];
            let solved = conjugate_gradients(&product, &attainable, &precondition, b, tol);
            applications += solved.applications;
            products += solved.products;
            converged &= solved.converged;
        }
        (applications, products, converged)
    }))
}

/// y = A x for a symmetric matrix stored with both triangles (CSC `pattern`, `values`):
/// row j of A is its column j, so each y_j is one column's gather.
fn symmetric_product(pattern: &Pattern, values: &[f64], x: &[f64], y: &mut [f64]) {
    for (j, yj) in y.iter_mut().enumerate() {
        let slots = pattern.col_ptr[j]..pattern.col_ptr[j + 1];
        *yj = pattern.row_idx[slots.clone()]
            .iter()
            .zip(&values[slots])
            .map(|(&i, v)| v * x[i])
            .sum();
    }
}

/// What [`conjugate_gradients`] found.
pub struct Solved {
    /// The solution (the last iterate where it missed the tolerance).
    pub x: Vec<f64>,
    /// Whether it met the tolerance within [`REFINEMENT_BUDGET`] applications.
    pub converged: bool,
    /// Preconditioner applications.
    pub applications: usize,
    /// Products with the matrix or its absolute value (one per application, one per check
    /// of the true residual and one per measure of its round-off).
    pub products: usize,
}

/// Preconditioned conjugate gradients from zero for A x = `b`, until the true residual
/// |b - A x|_inf is at most `tol` |b|_inf, or at most the round-off of computing A x
/// itself, `attainable(x)` (10 eps |A| |x| in the inf-norm), where that is larger: there
/// no f64 answer, the double way's included, has a smaller residual (measured: the
/// `rates` upper body, held only by contact, at level 3: 1.1-1.7e-10 |b| where
/// eps |A| |x| = 1.2e-10 |b|; the clamped body with ones at level 6: the f64 Cholesky's
/// answer at 6.4e-10 |b|). Not converged (and the work done counted) when
/// [`REFINEMENT_BUDGET`] applications do not reach it. Written by hand: twenty lines, and
/// the preconditioner is faer's factorization.
pub fn conjugate_gradients(
    product: &dyn Fn(&[f64], &mut [f64]),
    attainable: &dyn Fn(&[f64]) -> f64,
    precondition: &dyn Fn(&[f64], &mut [f64]),
    b: &[f64],
    tol: f64,
) -> Solved {
    let n = b.len();
    let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let target = tol * super::inf_norm(b);
    if target == 0.0 {
        return Solved {
            x: vec![0.0; n],
            converged: true,
            applications: 0,
            products: 0,
        };
    }
    let (mut x, mut r) = (vec![0.0; n], b.to_vec());
    let (mut z, mut q) = (vec![0.0; n], vec![0.0; n]);
    let (mut applications, mut products) = (0, 0);
    // 10 eps |A| |x|_inf: the last measured (at any x), and the one at the current x (set
    // to None at each update of x; each a product with |A|, so measured at most once per x).
    let mut round_off: Option<f64> = None;
    let mut here: Option<f64>;
    let mut absolute_products = 0;
    let mut measure = |x: &[f64], here: &mut Option<f64>| {
        *here.get_or_insert_with(|| {
            absolute_products += 1;
            attainable(x)
        })
    };
    while applications < REFINEMENT_BUDGET {
        // A restart from the true residual: the recurrence's drifts by round-off.
        precondition(&r, &mut z);
        applications += 1;
        let mut d = z.clone();
        let mut rz = dot(&r, &z);
        loop {
            product(&d, &mut q);
            products += 1;
            let alpha = rz / dot(&d, &q);
            x.iter_mut().zip(&d).for_each(|(x, d)| *x += alpha * d);
            here = None;
            r.iter_mut().zip(&q).for_each(|(r, q)| *r -= alpha * q);
            let residual = super::inf_norm(&r);
            if residual <= target || applications == REFINEMENT_BUDGET {
                break;
            }
            // The recurrence's residual keeps falling below the round-off of A x while the
            // true one stays at it: stop there too (confirmed below from the true residual,
            // a restart where it misses). Measured once, then again where reached.
            let threshold = *round_off.get_or_insert_with(|| measure(&x, &mut here));
            if residual <= threshold {
                let now = measure(&x, &mut here);
                round_off = Some(now);
                if residual <= now {
                    break;
                }
            }
            precondition(&r, &mut z);
            applications += 1;
            let rz_next = dot(&r, &z);
            d.iter_mut()
                .zip(&z)
                .for_each(|(d, z)| *d = z + rz_next / rz * *d);
            rz = rz_next;
        }
        product(&x, &mut q);
        products += 1;
        r.iter_mut()
            .zip(b.iter().zip(&q))
            .for_each(|(r, (b, q))| *r = b - q);
        let residual = super::inf_norm(&r);
        if residual <= target || residual <= measure(&x, &mut here) {
            return Solved {
                x,
                converged: true,
                applications,
                products: products + absolute_products,
            };
        }
    }
    Solved {
        x,
        converged: false,
        applications,
        products: products + absolute_products,
    }
}
