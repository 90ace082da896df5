// Reference: issue 64 ("lac wherever mortar and nts are: export/grade comparison columns");
// issue 48 (grade).
// Goal: `grade` solves lac beside mortar and nts, and this project's own lac solves of
//   rates-exact's levels 0-2, handed to `grade` as the VTU series an outside code writes
//   (nodal pressure: the macro-element's, a shared node the mean), are graded to grade's own
//   lac errors in every quantity that does not read the pressure, to 1e-10 relative, and
//   their distance to mortar's solution is grade's lac's. The pressure quantities differ: an
//   outside code's nodal pressure is read as linear between the nodes, lac's is constant on
//   each macro-element.
// Geometry: the stacked unit blocks of contact-mms, levels 0-2.
// Data: studies/rates-exact.toml.

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::contact::Method;
use contact_rates::verify::quantity::Quantity;

#[test]
fn this_projects_lac_is_graded_as_grades_own_lac() {
    common::case("contact-mms", 0, Method::Mortar, &[]);
    let g = graded_series::grade_own_solves("rates-exact", Method::Lac, 2);
    let own = |level: usize, q: Quantity| {
        g.errors
            .iter()
            .find(|o| o.method.name() == "lac" && o.level == level && o.quantity == q)
            .map(|o| o.error)
    };
    let (mut worst, mut compared) = (0.0f64, 0);
    for r in g.errors.iter().filter(|r| r.method.name() == "outside") {
        let reads_pressure =
            r.quantity.name().contains("pressure") || r.quantity == Quantity::ContactEdge;
        if reads_pressure || (r.quantity.is_distance() && r.quantity != Quantity::ConeDistance) {
            continue;
        }
        let lac = own(r.level, r.quantity).expect("grade's own lac has the row");
        worst = worst.max((r.error - lac).abs() / lac.abs().max(1e-300));
        compared += 1;
    }
    println!("{compared} errors, largest relative difference to grade's lac {worst:.1e}");
    assert!(compared >= 12, "{compared}");
    assert!(worst <= 1e-10, "{worst}");
}
