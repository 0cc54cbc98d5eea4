//! Lines for the user on standard output that never panic: once stdout is closed (`sppm check
//! … | head`), further lines are dropped silently instead of panicking as `println!` does.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// Write one line to standard output; a closed or failing stdout ends the printing, not the
/// program (the run's files are its results, not its stdout).
pub fn line(args: std::fmt::Arguments) {
    if CLOSED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if writeln!(out, "{args}").and_then(|()| out.flush()).is_err() {
        CLOSED.store(true, Ordering::Relaxed);
    }
}

/// `say!("…", args)`: [`line`] with `format!` syntax.
#[macro_export]
macro_rules! say {
    ($($t:tt)*) => {
        $crate::console::line(format_args!($($t)*))
    };
}
