// Reference: Theorem 3.1 of the paper (rates 3/4 for K_h^pi and 1/2 for K_h^I when u is in
//   H^2 and f in L2, which the regularity family satisfies for beta > 1); the best
//   approximation of r^beta by P1 on uniform meshes, whose H1 error falls no faster than
//   h^beta (the solution's own regularity bounds every P1 discretization's rate).
// Goal: the quick tier of `study regularity`: at beta = 1.25 both cones meet Theorem 3.1's
//   thresholds (3/4 and 1/2 less the studies' tolerance 0.05); at beta = 0.6, where the
//   theorem claims nothing, both converge, and neither beats the best rate min(1, beta) by
//   more than that tolerance.
// Geometry: the regularity scenes (stacked unit blocks, the transition point a node of both
//   meshes), uniform refinement.
// Data: beta = 1.25 on levels 0-3, beta = 0.6 on levels 1-4 (level 0 is pre-asymptotic
//   there); one load step; errors against the exact solution.

use contact_rates::contact::Method;
use contact_rates::studies::convergence;
use contact_rates::studies::regularity::{best_rate, study_path};
use contact_rates::verify::quantity::Quantity;

/// The study file of `beta` with its levels replaced by `levels`, in a temporary folder.
fn quick(beta: f64, levels: &str, dir: &std::path::Path) -> String {
    let text = std::fs::read_to_string(study_path(beta)).unwrap();
    let start = text.find("levels = [").unwrap();
    let end = start + text[start..].find(']').unwrap() + 1;
    let text = format!("{}levels = [{levels}]{}", &text[..start], &text[end..]);
    let path = dir.join(format!("quick-{beta}.toml"));
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn theorem_rate(res: &convergence::StudyResult, m: Method) -> f64 {
    let r = res.rate(m, Quantity::Theorem).unwrap();
    println!(
        "{}: theorem rate {:.3} ± {:.3} over {:?} ({})",
        m,
        r.rate(),
        r.stderr(),
        r.assessment.used,
        r.assessment.verdict.name()
    );
    r.rate()
}

#[test]
fn theorem_rates_where_it_applies_and_no_rate_beyond_the_regularity() {
    contact_rates::init();
    let dir = tempfile::tempdir().unwrap();
    let res = convergence::run(&quick(1.25, "0, 1, 2, 3", dir.path())).unwrap();
    assert!(theorem_rate(&res, Method::Mortar) >= 0.75 - 0.05);
    assert!(theorem_rate(&res, Method::Nts) >= 0.5 - 0.05);
    assert!(res.failures().is_empty(), "{:?}", res.failures());
    let beta = 0.6;
    let res = convergence::run(&quick(beta, "1, 2, 3, 4", dir.path())).unwrap();
    let best = best_rate(Quantity::Theorem, beta).unwrap();
    for m in [Method::Mortar, Method::Nts] {
        let rate = theorem_rate(&res, m);
        assert!(
            rate > 0.0 && rate <= best + 0.05,
            "{m}: {rate} against the best {best}"
        );
    }
}
