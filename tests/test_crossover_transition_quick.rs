// Reference: issue 63 (nts past its crossover where the interface separates); Theorem 3.1
//   (K_h^I: h^(1/2), K_h^pi: h^(3/4), both bounds); the triangle inequality
//   D - e_mortar <= e_nts <= D + e_mortar, D the distance between the cones' solutions.
// Goal: the quick tier of `study crossover-transition`, as crossover-quick is to crossover:
//   on crossover-transition-quick (contact on [0, 0.5871), separation beyond, u ~ r^1.25 at
//   the transition) over its levels 0-2, nts's distance to mortar is at least twice
//   mortar's theorem-norm error at every level, mortar's rate is above 0.85 and nts's is
//   below 0.75 and at least 0.45. A K_h^I replaced by K_h^pi has D = 0 and mortar's rate and
//   fails; so does an nts that stops converging.
// Geometry: meshes/two_blocks_point.geo, the upper contact line graded 5 on each side of c,
//   the slave sqrt(10) coarser than the master (h_upper = 0.12 at level 0).
// Data: E = 100 (slave) and 150, nu = 0.3, one step; errors against the exact solution.

use contact_rates::contact::Method;
use contact_rates::studies::convergence;
use contact_rates::verify::quantity::Quantity;

#[test]
fn nts_distance_dominates_from_level_0_and_its_rate_is_nts_s() {
    contact_rates::init();
    let path =
        contact_rates::verify::study_file::builtin_dir().join("crossover-transition-quick.toml");
    let res = convergence::run(&path.display().to_string()).unwrap();
    for level in [0, 1, 2] {
        let em = res.error(Method::Mortar, level, Quantity::Theorem).unwrap();
        let d = res
            .error(Method::Nts, level, Quantity::ConeDistance)
            .unwrap();
        println!(
            "level {level}: e_mortar {em:.4e}, D {d:.4e}, D / e_mortar {:.2}",
            d / em
        );
        assert!(d >= 2.0 * em, "level {level}: D / e_mortar = {}", d / em);
    }
    let rate = |m: Method| {
        let r = res.rate(m, Quantity::Theorem).unwrap();
        println!(
            "{m}: theorem rate {:.3} ({})",
            r.rate(),
            r.assessment.verdict.name()
        );
        r.rate()
    };
    let (mortar, nts) = (rate(Method::Mortar), rate(Method::Nts));
    assert!(mortar > 0.85, "mortar's rate {mortar}");
    assert!(
        nts < 0.75,
        "nts's rate {nts}: its h^(1/2) distance to mortar does not show"
    );
    assert!(
        nts >= 0.45,
        "nts's rate {nts} is below Theorem 3.1's h^(1/2)"
    );
    // The interface separates at every level: the exact contact set is 0.5871 of Gamma_C;
    // the coarse slave trace (4 segments at level 0) holds contact on 0.90 of it there.
    for l in &res.levels {
        assert!(
            l.contact_fraction > 0.5 && l.contact_fraction < 0.95,
            "{:?}: contact fraction {}",
            l.level,
            l.contact_fraction
        );
    }
}
