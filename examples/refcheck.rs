use contact_rates::{case::Case, contact::Method, scene::Scene, solve::{self, Settings}, study::error::{Comparison, norms}};
fn main() {
    contact_rates::init();
    let scene = Scene::load("rates").unwrap();
    let p = vec![("h_upper".to_string(), 0.3), ("h_lower".to_string(), 0.3 / 1.4142), ("matching".to_string(), 1.0)];
    let r: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let cases: Vec<Case> = (r - 3..=r).map(|l| Case::build(&scene, l, Method::Mortar, &p).unwrap()).collect();
    let sols: Vec<_> = cases.iter().map(|c| solve::solve(&c.problem, &Settings::default(), 4, true).unwrap()).collect();
    let last = cases.len() - 1;
    for i in 0..last {
        let cmp = Comparison::new(&cases[i].problem.model, &cases[last].problem.model);
        let mut out = String::new();
        for (s, t) in sols[i].states.iter().zip(&sols[last].states).skip(1) {
            let d = cmp.difference(&cases[i].problem.model, s, &cases[last].problem.model, t);
            let n = norms(&cases[last].problem.model, t);
            out += &format!(" [u {:.3e} semi {:.3e} s {:.3e}]", (d.l2_u / n.l2_u).sqrt(), (d.semi_u / n.semi_u).sqrt(), (d.stress / n.stress).sqrt());
        }
        let a1: f64 = cases[i].problem.model.elements.iter().map(|e| e.area).sum();
        let a2: f64 = cases[last].problem.model.elements.iter().map(|e| e.area).sum();
        println!("level {} vs {}: area {:.15} {a1:.15} {a2:.15} {out}", i + r - 3, r, cmp.area());
    }
}
