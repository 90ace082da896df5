//! Reference: gmsh's MSH 4.1 ASCII format.
//! Goal: the reader takes what gmsh 4.8 writes (physical names, entities, node blocks,
//! element blocks) and turns every malformed file into an error naming the section.

use contact_rates::mesh::msh::parse_msh;
use std::path::Path;

const GOOD: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 7 "edge with spaces"
2 3 "body"
$EndPhysicalNames
$Entities
0 1 1 0
1 0 0 0 1 0 0 1 7 0
1 0 0 0 1 1 0 1 3 0
$EndEntities
$Nodes
2 4 1 4
1 1 0 2
1
2
0 0 0
1 0 0
2 1 0 2
3
4
1 1 0
0 1 0
$EndNodes
$Elements
2 3 1 3
1 1 1 1
1 1 2
2 1 2 2
2 1 2 3
3 1 3 4
$EndElements
"#;

#[test]
fn reads_a_small_mesh_with_physical_names() {
    let m = parse_msh(GOOD, Path::new("good.msh")).unwrap();
    assert_eq!(m.nodes.len(), 4);
    assert_eq!(m.triangles.len(), 2);
    assert_eq!(m.lines.len(), 1);
    assert_eq!(m.physical_tag(1, "edge with spaces"), Some(7));
    assert_eq!(m.physical_tag(2, "body"), Some(3));
    assert_eq!(m.nodes[2], [1.0, 1.0]);
}

#[test]
fn malformed_files_are_errors_naming_the_section() {
    let cases = [
        (GOOD.replace("4.1 0 8", "2.2 0 8"), "$MeshFormat"),
        (GOOD.replace("4.1 0 8", "4.1 1 8"), "binary"),
        (GOOD.replace("1 1 0\n0 1 0", "1 1 0\n0 nan 0"), "$Nodes"),
        (GOOD.replace("3 1 3 4", "3 1 3 9"), "unknown node 9"),
        (GOOD.replace("2 1 2 2", "2 1 9 2"), "element type 9"),
        (GOOD.replace("$EndPhysicalNames", ""), "$PhysicalNames"),
        (
            GOOD[..GOOD.find("$Elements").unwrap()].to_string(),
            "$Elements",
        ),
        (GOOD.replace("2 4 1 4", "2 5 1 5"), "announces 5 nodes"),
        (String::new(), "empty or truncated"),
        ("garbage".to_string(), "unexpected token"),
    ];
    for (text, needle) in cases {
        let e = parse_msh(&text, Path::new("bad.msh"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bad.msh") && e.contains(needle),
            "'{needle}' not in: {e}"
        );
    }
}

#[test]
fn truncations_never_panic() {
    for cut in 0..GOOD.len() {
        let _ = parse_msh(&GOOD[..cut], Path::new("cut.msh"));
    }
}
