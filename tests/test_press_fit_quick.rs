//! Reference: issue 77 (the Lame press fit with its closed form, `analytical::lame`);
//! Theorem 3.1 of Fernandez, Hild and Viano and Drouet and Hild (2017) for the thresholds
//! the study file states (straight and touching there: a claim under test here); the
//! polygonal approximation of a circle (an arc's sagitta over its chord h is h^2 / (8 R)).
//! Goal: the quick tier of `study press-fit` (levels 0-2 split on the arcs): every
//! method's theorem-norm error against the closed form passes its threshold; the boundary's
//! largest sagitta and the slivers' area fall at rate 2, the exact solution's energy on the
//! slivers at rate 1 and below the smallest theorem-norm error; an exact solution without
//! the exact contact geometry (the radial map dropped: body 2 read at body 1's point) is
//! refused before anything is solved (read along the chords' normals with body 2 at body
//! 1's point, its traction has a tangential part and its gap is about -g0).
//! Geometry: meshes/press_fit.geo (a = 0.5, R = 1, g0 = 0.02, b = 1.5).
//! Data: scenes/press-fit.toml (E = 100 and 150, nu = 0.3, plane strain, bore pressure 6.6),
//! studies/press-fit-quick.toml.

mod common;
use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::studies::convergence;
use contact_rates::verify::quantity::Quantity;

#[test]
fn every_method_converges_on_the_press_fit_and_the_boundary_to_its_arcs() {
    contact_rates::init();
    let res = convergence::run("press-fit-quick").unwrap();
    for m in [Method::Mortar, Method::Nts, Method::Lac] {
        common::assert_rate_passes(res.rate(m, Quantity::Theorem).unwrap(), &[0, 1, 2]);
    }
    let g = &res.geometry;
    assert_eq!(g.len(), 3);
    for w in g.windows(2) {
        let rate = |a: f64, b: f64| (a / b).ln() / (w[0].h / w[1].h).ln();
        let (sagitta, area) = (
            rate(w[0].max_sagitta, w[1].max_sagitta),
            rate(w[0].sliver_area, w[1].sliver_area),
        );
        let energy = rate(w[0].sliver_energy.unwrap(), w[1].sliver_energy.unwrap());
        println!(
            "levels {}-{}: sagitta rate {sagitta:.3}, area {area:.3}, sliver energy {energy:.3}",
            w[0].level, w[1].level
        );
        assert!((sagitta - 2.0).abs() < 0.05 && (area - 2.0).abs() < 0.05);
        assert!((energy - 1.0).abs() < 0.05);
    }
    for row in g {
        let smallest = [Method::Mortar, Method::Nts, Method::Lac]
            .iter()
            .map(|&m| res.error(m, row.level, Quantity::Theorem).unwrap())
            .fold(f64::INFINITY, f64::min);
        assert!(row.sliver_energy.unwrap() < smallest, "{row:?}");
    }
}

#[test]
fn an_exact_press_fit_without_its_contact_geometry_is_refused() {
    contact_rates::init();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/press-fit.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let cut = text.find("[exact.contact]").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("press-fit-no-map.toml");
    let text = text[..cut].replace(
        "../meshes/",
        &format!("{}/meshes/", env!("CARGO_MANIFEST_DIR")),
    );
    std::fs::write(&file, text).unwrap();
    let scene = Scene::load(file.to_str().unwrap()).unwrap();
    let err = Case::build(&scene, 0, Method::Mortar, &[])
        .err()
        .expect("refused");
    let message = err.to_string();
    println!("{message}");
    assert!(
        message.contains("is not a solution of the contact problem"),
        "{message}"
    );
}
