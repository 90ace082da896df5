//! Seconds of the pieces of the solver's set-up and factorization and of the floor,
//! recorded only when the environment variable `CONTACT_RATES_PIECES` is set (a
//! measurement aid: `examples/speed_pieces.rs` prints them). A piece run once per diagonal
//! block is recorded with the block's first equation, so that the blocks factorized side
//! by side on two threads can be told apart.

use std::sync::{Mutex, OnceLock};
use std::time::Instant;

/// (piece, block's first equation or 0, seconds), in the order recorded.
static RECORDS: Mutex<Vec<(&'static str, usize, f64)>> = Mutex::new(Vec::new());

/// Whether pieces are recorded (`CONTACT_RATES_PIECES` set when first asked).
pub fn enabled() -> bool {
    static ENABLED: OnceLock<bool> = OnceLock::new();
    *ENABLED.get_or_init(|| std::env::var_os("CONTACT_RATES_PIECES").is_some())
}

/// Run `f`, recording its seconds as `name` of block `block` when enabled.
pub fn time<T>(name: &'static str, block: usize, f: impl FnOnce() -> T) -> T {
    if !enabled() {
        return f();
    }
    let t = Instant::now();
    let result = f();
    record(name, block, t.elapsed().as_secs_f64());
    result
}

/// Record `seconds` as `name` of block `block` when enabled.
pub fn record(name: &'static str, block: usize, seconds: f64) {
    if enabled() {
        RECORDS
            .lock()
            .expect("pieces lock")
            .push((name, block, seconds));
    }
}

/// The records so far, removed.
pub fn take() -> Vec<(&'static str, usize, f64)> {
    std::mem::take(&mut *RECORDS.lock().expect("pieces lock"))
}
