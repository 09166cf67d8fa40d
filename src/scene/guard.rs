//! Third-party parsers (`tobj`, `gltf`) run on untrusted files: a panic inside one must become
//! an error naming the file, and its text (a crate's source path, an index, a backtrace) must
//! not reach the user's terminal. The panic hook is process-wide, so it is wrapped once to stay
//! silent on the threads that are inside [`catch`] and to behave as before everywhere else.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

thread_local! {
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

static WRAP_HOOK: Once = Once::new();

/// A panic caught by [`catch`] (its message is deliberately dropped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crashed;

/// Run `f`; `Err(Crashed)` if it panicked, with nothing printed for the panic.
pub fn catch<T>(f: impl FnOnce() -> T) -> Result<T, Crashed> {
    WRAP_HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    r.map_err(|_| Crashed)
}
