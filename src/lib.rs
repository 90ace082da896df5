//! contact-rates: measured convergence of two discrete non-penetration conditions (the
//! mortar-type K_h^pi and the node-on-segment K_h^I) for quasistatic frictionless contact
//! of two elastic-viscoplastic bodies on non-matching meshes.
//!
//! The modules follow the pipeline: [`mesh`] -> [`scene`] -> [`material`] -> [`fe`] ->
//! [`contact`] -> [`solve`] -> [`case`] / [`metrics`] / [`io`] -> [`study`] -> [`report`],
//! with [`expr`], [`quadrature`] and [`analytical`] (exact solutions) beside the scene;
//! the binary is a thin CLI over them. Scenes are data ([`scene`]).

pub mod analytical;
pub mod case;
pub mod contact;
pub mod error;
pub mod expr;
pub mod fe;
pub mod io;
pub mod material;
pub mod mesh;
pub mod metrics;
pub mod progress;
pub mod quadrature;
pub mod report;
pub mod scene;
pub mod solve;
pub mod study;

pub use error::{Error, Result};

/// Use faer's sequential mode: a second thread was measured not to speed up the numeric
/// Cholesky at 2e5-2e6 dofs on this class of machine (SPEC section 10).
pub fn init() {
    faer::set_global_parallelism(faer::Par::Seq);
}
