//! K_h^pi, the paper's mortar-type condition: one row per body-1 node y_i of a piece,
//! `u^1(y_i).nu_i + (pi_h u^2)(y_i).(-nu_i) <= g_i`, where pi_h is the projection onto body
//! 1's P1 trace space with modified end functions: at the piece's two end nodes body 2's
//! nodal interpolant, inside `int psi (pi_h v - v) = 0` for every P1 psi constant on the
//! piece's first and last segments. The inequality is taken after M^{-1} (the rows are
//! M^{-1} D), and g is the same projection of the gap between the two traces. The
//! integrals are sums over the mortar segments' Gauss points, exact on a straight piece.
//! Its pressure is nodal.

use super::{MortarSegment, Piece, PieceRow};

/// The rows on one piece, one per body-1 node ([`PieceRow::nodal`]).
pub fn rows(piece: &Piece) -> Vec<PieceRow> {
    let (transfer, gaps) = projection(piece, &piece.mortar_segments());
    transfer
        .iter()
        .zip(gaps)
        .enumerate()
        .map(|(i, (row, gap))| PieceRow::nodal(piece, i, row.iter().copied().enumerate(), gap))
        .collect()
}

/// pi_h^1 as the dense matrix M^{-1} D (rows: body-1 nodes, columns: body-2 nodes).
pub fn transfer(piece: &Piece) -> Vec<Vec<f64>> {
    projection(piece, &piece.mortar_segments()).0
}

/// pi_h^1 as the matrix M^{-1} D and the projected gap: the interior rows solve the
/// tridiagonal system of the test functions psi_j against the body-1 hats; the end rows
/// keep the end values (body 2's interpolant where the end node's normal meets it, and
/// the gap there).
fn projection(piece: &Piece, segments: &[MortarSegment]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let m = piece.slave_s.len() - 1; // body-1 elements
    let nm = piece.master_s.len();
    let mut p = vec![vec![0.0; nm]; m + 1];
    let mut gaps = vec![0.0; m + 1];
    let mut ends = [(0, [0.0; 2]); 2];
    for (k, j) in [0, m].into_iter().enumerate() {
        let (meet, gap) = piece.meet_master(piece.slave_s[j]);
        let shape = meet.shape();
        p[j][meet.segment] += shape[0];
        p[j][meet.segment + 1] += shape[1];
        gaps[j] = gap;
        ends[k] = (meet.segment, shape);
    }
    if m < 2 {
        return (p, gaps);
    }
    let integrals = TraceIntegrals::new(segments, m);
    let system = MortarSystem::new(&integrals, m, nm, ends, [gaps[0], gaps[m]]);
    for (r, mut row) in system.solve().into_iter().enumerate() {
        gaps[r + 1] = row.pop().unwrap();
        p[r + 1] = row;
    }
    (p, gaps)
}

/// Integrals of products of trace hats on one piece, and of the body-1 hats against the
/// gap.
struct TraceIntegrals {
    /// int lambda_j lambda_k for k = j-1, j, j+1 (body-1 hats; tridiagonal).
    slave_slave: Vec<[f64; 3]>,
    /// int lambda_j mu_q, sparse over the body-2 hats q.
    slave_master: Vec<Vec<(usize, f64)>>,
    /// int lambda_j g.
    slave_gap: Vec<f64>,
}

impl TraceIntegrals {
    fn new(segments: &[MortarSegment], m: usize) -> Self {
        let mut slave_slave = vec![[0.0f64; 3]; m + 1];
        let mut slave_master: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m + 1];
        let mut slave_gap = vec![0.0; m + 1];
        for segment in segments {
            let (e, f) = (segment.slave, segment.master);
            for g in &segment.points {
                let (l, mu, wt) = (g.slave, g.master, g.weight);
                for a in 0..2 {
                    slave_gap[e + a] += wt * l[a] * g.gap;
                    for b in 0..2 {
                        // slave j = e + a, k = e + b => offset k - j + 1
                        slave_slave[e + a][1 + b - a] += wt * l[a] * l[b];
                        let entry = &mut slave_master[e + a];
                        let q = f + b;
                        match entry.iter_mut().find(|(qq, _)| *qq == q) {
                            Some(v) => v.1 += wt * l[a] * mu[b],
                            None => entry.push((q, wt * l[a] * mu[b])),
                        }
                    }
                }
            }
        }
        TraceIntegrals {
            slave_slave,
            slave_master,
            slave_gap,
        }
    }
}

/// The tridiagonal system M X = R of the mortar projection's interior rows: test functions
/// psi_j (j = 1..m-1) are lambda_j, plus lambda_0 for j = 1 and lambda_m for j = m-1 (the
/// end elements' functions made constant); M[j][k] = int psi_j lambda_k for k = 1..m-1,
/// R[j][q] = int psi_j mu_q minus the end-value contributions
/// int psi_j (lambda_0 phi(c_a) + lambda_m phi(c_b)); the last column of R is the same for
/// the gap.
struct MortarSystem {
    lower: Vec<f64>,
    diag: Vec<f64>,
    upper: Vec<f64>,
    rhs: Vec<Vec<f64>>,
}

impl MortarSystem {
    fn new(
        integrals: &TraceIntegrals,
        m: usize,
        nm: usize,
        ends: [(usize, [f64; 2]); 2],
        end_gaps: [f64; 2],
    ) -> Self {
        let n = m - 1;
        let get = |j: usize, k: usize| -> f64 {
            if k + 1 < j || k > j + 1 {
                0.0
            } else {
                integrals.slave_slave[j][k + 1 - j]
            }
        };
        let psi_lambda = |j: usize, k: usize| -> f64 {
            let mut v = get(j, k);
            if j == 1 {
                v += get(0, k);
            }
            if j == m - 1 {
                v += get(m, k);
            }
            v
        };
        let mut lower = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut upper = vec![0.0; n];
        let mut rhs = vec![vec![0.0; nm + 1]; n];
        for r in 0..n {
            let j = r + 1;
            diag[r] = psi_lambda(j, j);
            if r > 0 {
                lower[r] = psi_lambda(j, j - 1);
            }
            if r + 1 < n {
                upper[r] = psi_lambda(j, j + 1);
            }
            let mut add_row = |jj: usize| {
                for &(q, v) in &integrals.slave_master[jj] {
                    rhs[r][q] += v;
                }
                rhs[r][nm] += integrals.slave_gap[jj];
            };
            add_row(j);
            if j == 1 {
                add_row(0);
            }
            if j == m - 1 {
                add_row(m);
            }
            for ((segment, shape), (end, gap)) in
                ends.iter().zip([(0, end_gaps[0]), (m, end_gaps[1])])
            {
                let w = psi_lambda(j, end);
                for b in 0..2 {
                    if shape[b] != 0.0 {
                        rhs[r][segment + b] -= w * shape[b];
                    }
                }
                rhs[r][nm] -= w * gap;
            }
        }
        MortarSystem {
            lower,
            diag,
            upper,
            rhs,
        }
    }

    /// X = M^{-1} R by the Thomas algorithm: M is diagonally dominant (a mass matrix with
    /// lumped ends), so no pivoting is needed.
    fn solve(mut self) -> Vec<Vec<f64>> {
        let n = self.diag.len();
        let (diag, rhs) = (&mut self.diag, &mut self.rhs);
        for r in 1..n {
            let factor = self.lower[r] / diag[r - 1];
            diag[r] -= factor * self.upper[r - 1];
            let (prev, cur) = rhs.split_at_mut(r);
            for (c, pv) in cur[0].iter_mut().zip(&prev[r - 1]) {
                *c -= factor * pv;
            }
        }
        for r in (0..n).rev() {
            if r + 1 < n {
                let (cur, next) = rhs.split_at_mut(r + 1);
                for (c, nv) in cur[r].iter_mut().zip(&next[0]) {
                    *c -= self.upper[r] * nv;
                }
            }
            let d = diag[r];
            for c in rhs[r].iter_mut() {
                *c /= d;
            }
        }
        self.rhs
    }
}
