//! The registry of methods: every discrete non-penetration condition this project solves,
//! with what the rest of the code needs to know of it. A new method is a file of rows
//! (see [`super::mortar`]) and a line in [`REGISTRY`].

use super::{Piece, PieceRow};

/// Which discrete cone. Written as its [`Method::name`] in files; read from it with an
/// error that lists the names.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase", try_from = "String")]
pub enum Method {
    /// K_h^pi, the global mortar-type condition.
    Mortar,
    /// K_h^I, the local node-on-segment condition.
    Nts,
    /// LAC, the local average contact condition of Drouet and Hild (2017): non-penetration
    /// on average over each macro-element of body 1's trace.
    Lac,
}

/// The discrete space of a pressure: a method's, and a pressure profile's (what its best
/// approximation of a pressure is taken in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PressureSpace {
    /// Continuous, linear between consecutive points (the nodal rows' pressure at the
    /// body-1 trace nodes, the multiplier over the node's lumped weight; a code's nodal
    /// pressure).
    Linear,
    /// Constant between the two points of each consecutive pair (LAC's pressure on its
    /// macro-elements, the multiplier over |M|, written at each macro-element's two ends).
    ConstantOnPairs,
}

/// What the code knows of one method.
pub struct MethodInfo {
    /// The method.
    pub method: Method,
    /// Name on the command line and in files.
    pub name: &'static str,
    /// Its pressure space.
    pub pressure: PressureSpace,
    /// Whether it is the reference the distance D between cones is measured against.
    pub reference: bool,
    /// Its symbol in the paper (K_h^pi, K_h^I) when it is one of the paper's two cones:
    /// the paper's solver and Theorem 3.1's rates are stated for those.
    pub paper_symbol: Option<&'static str>,
    /// Its rows on one piece (the methods that integrate build the piece's mortar
    /// segments, [`Piece::mortar_segments`]; the pointwise ones do not).
    pub rows: fn(&Piece) -> Vec<PieceRow>,
}

/// Every method, in the order the reports list them (the enum's order).
pub const REGISTRY: [MethodInfo; 3] = [
    MethodInfo {
        method: Method::Mortar,
        name: "mortar",
        paper_symbol: Some("K_h^pi"),
        pressure: PressureSpace::Linear,
        reference: true,
        rows: super::mortar::rows,
    },
    MethodInfo {
        method: Method::Nts,
        name: "nts",
        paper_symbol: Some("K_h^I"),
        pressure: PressureSpace::Linear,
        reference: false,
        rows: super::nts::rows,
    },
    MethodInfo {
        method: Method::Lac,
        name: "lac",
        paper_symbol: None,
        pressure: PressureSpace::ConstantOnPairs,
        reference: false,
        rows: super::lac::rows,
    },
];

impl Method {
    /// Every method, in the order the reports list them.
    pub const ALL: [Method; 3] = [REGISTRY[0].method, REGISTRY[1].method, REGISTRY[2].method];

    /// The registry's line for this method.
    pub fn info(self) -> &'static MethodInfo {
        &REGISTRY[self as usize]
    }

    /// Name used on the command line and in files.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The method the distance D between cones is measured against (mortar).
    pub fn reference() -> Method {
        REGISTRY.iter().find(|m| m.reference).unwrap().method
    }

    /// Whether this is the reference the distance D between cones is measured against.
    pub fn is_reference(self) -> bool {
        self.info().reference
    }

    /// The methods of `methods` other than the reference, in their order: the ones a
    /// report compares with the reference.
    pub fn compared(methods: &[Method]) -> impl Iterator<Item = Method> + '_ {
        methods.iter().copied().filter(|m| !m.is_reference())
    }

    /// Whether it is one of the paper's two cones (K_h^pi, K_h^I).
    pub fn in_paper(self) -> bool {
        self.info().paper_symbol.is_some()
    }

    /// The space its pressure lies in.
    pub fn pressure_space(self) -> PressureSpace {
        self.info().pressure
    }

    /// Whether the pressure is constant on each row's support rather than linear between
    /// body-1 nodes.
    pub fn piecewise_constant_pressure(self) -> bool {
        self.pressure_space() == PressureSpace::ConstantOnPairs
    }

    /// Parse a name of the registry.
    pub fn parse(s: &str) -> Option<Self> {
        REGISTRY.iter().find(|m| m.name == s).map(|m| m.method)
    }

    /// The names, quoted and joined for an error message: "mortar", "nts" or "lac".
    pub fn names_for_error() -> String {
        let names: Vec<String> = REGISTRY.iter().map(|m| format!("\"{}\"", m.name)).collect();
        match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => names.join(""),
        }
    }
}

impl TryFrom<String> for Method {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        Method::parse(&s)
            .ok_or_else(|| format!("unknown method '{s}'; use {}", Method::names_for_error()))
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

// The registry lists the methods in the enum's order, so that `info` is an index.
const _: () = {
    let mut i = 0;
    while i < REGISTRY.len() {
        assert!(REGISTRY[i].method as usize == i);
        i += 1;
    }
};
