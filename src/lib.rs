//! contact-rates: measured convergence of two discrete non-penetration conditions (the
//! mortar-type K_h^pi and the node-on-segment K_h^I) for quasistatic frictionless contact
//! of two elastic-viscoplastic bodies on non-matching meshes.
//!
//! The modules follow the pipeline: [`mesh`] -> [`scene`] -> [`material`] -> [`fe`] ->
//! [`contact`] -> [`solve`] -> [`case`] / [`metrics`] / [`io`] -> [`verify`] (the shared
//! verification toolkit) -> [`report`] (folders and plots) -> [`studies`] (one folder per
//! study kind and the table of kinds) -> [`results`] (the Results read back from the
//! reports), with [`expr`], [`quadrature`] and [`analytical`] (exact solutions) beside the
//! scene; the binary is a thin CLI over them. Scenes are data ([`scene`]).

pub mod analytical;
pub mod case;
pub mod contact;
pub mod error;
pub mod expr;
pub mod external;
pub mod fe;
pub mod interrupt;
pub mod io;
pub mod material;
pub mod mesh;
pub mod metrics;
pub mod progress;
pub mod quadrature;
pub mod report;
pub mod results;
pub mod scene;
pub mod solve;
pub mod studies;
pub mod verify;

pub use error::{Error, Result};

/// Use faer's sequential mode: a second thread was measured not to speed up the numeric
/// Cholesky at 2e5-2e6 dofs on this class of machine (SPEC section 10).
pub fn init() {
    faer::set_global_parallelism(faer::Par::Seq);
}

/// Run `f` (a program's whole work) on a thread of rayon's global pool, the calling thread
/// waiting. Why: a solve enters the pool some hundred times (every constitutive update,
/// residual and substitution), and from a thread outside the pool each entry hands the
/// work over and sleeps until a worker wakes it; from inside, the parallel loops start at
/// once. Measured (`speed_pieces 4 mortar rates 30`, 2 threads, fastest of 30, three
/// runs each, alternating): newton's time loop 0.0943 / 0.0945 / 0.0954 s -> 0.0856 /
/// 0.0868 / 0.0864 s; the floor 0.064 / 0.059 / 0.064 s -> 0.063 / 0.057 / 0.055 s. (Making
/// the main thread itself one of the pool's threads, `use_current_thread`, gave the same
/// loop but slowed the floor's numeric Cholesky 0.019 -> 0.023 s: its buffers then come
/// from the main thread's heap, as with `MALLOC_ARENA_MAX=1`.) The pool's threads get the
/// main thread's stack, 8 MiB: loading a manufactured scene differentiates its expressions
/// recursively (exmex), 1.5-1.6 MiB in a release build, past the 2 MiB Rust gives a
/// spawned thread in a debug one (tests/test_cli_thread_stack.rs).
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    // An error means the pool exists already (built by an earlier call): keep it.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(8 << 20)
        .build_global();
    rayon::scope(|_| f())
}
