// Reference: issue 76 (contact across an initial gap); Theorem 3.1 of the paper (h^(3/4)
//   for K_h^pi, h^(1/2) for K_h^I, stated without a gap) and Drouet and Hild (2017) for
//   LAC, as the study file states them; the interpolation estimates of a smooth g0: h^2
//   for the nodal interpolant and the mortar projection, h for the mean over a
//   macro-element (a constant per M).
// Goal: the quick tier of `study gap`: on levels 0-3 every method's theorem-norm error
//   against the exact solution converges at its threshold (a method whose rows dropped the
//   gap would hold [u.nu] <= 0 where the exact solution has [u.nu] = g0 > 0: an O(g0) error
//   that does not fall), and each method's discrete gap converges at its interpolation
//   rate; the contact zone's end converges to c.
// Geometry: meshes/two_blocks.geo (regularity-unaligned's meshes), c = (8/15, 1) a node of
//   neither trace.
// Data: scenes/gap.toml (g0 = x^2 / 20, closed on [0, c) by body 1's displacement
//   u_g = w(y) ((y - 1) g0', -g0)), studies/gap.toml with levels 0-3.

mod common;
use contact_rates::contact::Method;
use contact_rates::studies::convergence;
use contact_rates::verify::quantity::Quantity;

/// studies/gap.toml on levels 0-3, without the committed report it is set beside.
fn quick(dir: &std::path::Path) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/studies/gap.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let start = text.find("levels = [").unwrap();
    let end = start + text[start..].find(']').unwrap() + 1;
    let text = format!("{}levels = [0, 1, 2, 3]{}", &text[..start], &text[end..]);
    let text = text.replace("beside = \"regularity-unaligned/beta-1.50\"\n", "");
    let file = dir.join("gap-quick.toml");
    std::fs::write(&file, text).unwrap();
    file.display().to_string()
}

#[test]
fn every_method_converges_across_the_gap_at_its_rate() {
    contact_rates::init();
    let dir = tempfile::tempdir().unwrap();
    let res = convergence::run(&quick(dir.path())).unwrap();
    for m in [Method::Mortar, Method::Nts, Method::Lac] {
        let r = res.rate(m, Quantity::Theorem).unwrap();
        common::assert_rate_passes(r, &[0, 1, 2, 3]);
        // The discrete gap: h^2 for nodal rows, h for lac's constants (less the studies'
        // tolerance 0.05), the successive rates from level 1 on (level 0's body-1 trace is
        // two macro-elements of a graded line: lac's rate from level 0 to 1 is 0.938,
        // pre-asymptotic).
        let best = if m == Method::Lac { 1.0 } else { 2.0 };
        let gaps: Vec<(f64, f64)> = (0..4)
            .map(|l| {
                let e = res
                    .errors
                    .iter()
                    .find(|e| e.method == m && e.level == l && e.quantity == Quantity::DiscreteGap)
                    .unwrap();
                (e.h, e.error)
            })
            .collect();
        for w in gaps[1..].windows(2) {
            let rate = (w[0].1 / w[1].1).ln() / (w[0].0 / w[1].0).ln();
            println!(
                "{m}: discrete gap {:.4e} -> {:.4e}, rate {rate:.3}",
                w[0].1, w[1].1
            );
            assert!(
                rate >= best - 0.05,
                "{m}: the discrete gap's rate {rate} below {best}"
            );
        }
        // The contact zone's end: within one body-1 segment of c at every level (relative
        // to |Gamma_C| = 1, the segment at c is at most h).
        for l in 0..4 {
            let e = res
                .errors
                .iter()
                .find(|e| e.method == m && e.level == l && e.quantity == Quantity::ContactEdge)
                .unwrap();
            println!("{m} level {l}: contact edge {:.4e}, h {:.4}", e.error, e.h);
            assert!(
                e.error <= e.h,
                "{m} level {l}: the contact zone ends {} from c",
                e.error
            );
        }
    }
}
