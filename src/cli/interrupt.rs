//! Ctrl-C (SIGINT) and SIGTERM: a cancellation flag the CLI owns, and the rule that no
//! interrupted run leaves a temp file behind.
//!
//! A signal that arrives while nothing is being written ends the process at once (exit
//! 128 + signal): there is no temp file to remove. One that arrives during a write sets the
//! flag; the writer sees it within one chunk, removes its temp file, keeps the old output and
//! returns [`Interrupted`], which `main` turns into the same exit code. The library never sees
//! a signal, only the flag. A later "Ctrl-C finishes the pass and writes the image" hands the
//! same flag to the renderer and lets [`Phase::Rendering`] wait for it instead of exiting.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use penumbra::image::io::{WriteCancelled, WriteControl};

/// What the process is doing when a signal arrives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Loading, rendering, printing: nothing on disk to clean up, exit at once.
    Rendering,
    /// Writing an output file: let the writer clean up and return.
    Writing,
    /// Rendering in passes: the first signal only sets the flag, so the pass loop drops the
    /// pass in flight and writes the completed samples; a second one exits at once.
    Passes,
}

/// State shared with the signal thread.
#[derive(Debug)]
struct Shared {
    /// Set by the first SIGINT/SIGTERM (shared with the renderer in [`Phase::Passes`]).
    cancelled: Arc<AtomicBool>,
    /// The signal received (0 before any).
    signal: AtomicI32,
    /// Held by the signal thread while it decides, so no write starts in between.
    phase: Mutex<Phase>,
}

/// The run was interrupted by a signal; `main` exits with 128 + `signal`.
#[derive(Debug, thiserror::Error)]
#[error("interrupted by signal {signal}")]
pub struct Interrupted {
    /// The signal number (SIGINT = 2, SIGTERM = 15).
    pub signal: i32,
}

impl Interrupted {
    /// The shell's exit code for a process ended by this signal.
    pub fn exit_code(&self) -> i32 {
        128 + self.signal
    }
}

/// The CLI's handle on SIGINT/SIGTERM; create one per process, at the start of a command.
#[derive(Clone, Debug)]
pub struct Interrupt {
    shared: Arc<Shared>,
}

impl Interrupt {
    /// Take over SIGINT and SIGTERM for the rest of the process.
    pub fn install() -> anyhow::Result<Interrupt> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let shared = Arc::new(Shared {
            cancelled: Arc::new(AtomicBool::new(false)),
            signal: AtomicI32::new(0),
            phase: Mutex::new(Phase::Rendering),
        });
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
        let s = Arc::clone(&shared);
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for sig in signals.forever() {
                    let phase = s.phase.lock().unwrap_or_else(PoisonError::into_inner);
                    let first = s.signal.load(Ordering::SeqCst) == 0;
                    if first {
                        s.signal.store(sig, Ordering::SeqCst);
                    }
                    s.cancelled.store(true, Ordering::SeqCst);
                    if *phase == Phase::Passes && first {
                        eprintln!("interrupted: finishing with the completed samples");
                    } else if *phase != Phase::Writing {
                        // Exit while holding the lock: no write can start any more.
                        eprintln!("interrupted");
                        std::process::exit(128 + sig);
                    }
                }
            })?;
        Ok(Interrupt { shared })
    }

    /// Run `write` (given the write control to pass on) in the writing phase: a signal now
    /// makes it stop and remove its temp file. Returns [`Interrupted`] when a signal came,
    /// whether or not the write had already finished.
    pub fn writing<T>(
        &self,
        chunk_pause: std::time::Duration,
        write: impl FnOnce(&WriteControl) -> anyhow::Result<T>,
    ) -> anyhow::Result<T> {
        self.set_phase(Phase::Writing)?;
        let ctl = WriteControl {
            cancel: Some(self.shared.cancelled.as_ref()),
            chunk_pause,
        };
        let result = write(&ctl);
        match (self.set_phase(Phase::Rendering), result) {
            (Err(interrupted), Err(e)) if e.is::<WriteCancelled>() => {
                Err(interrupted.context(e.to_string()))
            }
            (Err(interrupted), _) => Err(interrupted),
            (Ok(()), result) => result,
        }
    }

    /// Run `f` (given the flag that a signal sets) in the pass phase: the first signal sets
    /// the flag instead of exiting, so `f` can stop at the end of a pass and write what it has
    /// with [`Interrupt::final_write`]. Writes inside `f` are not cancelled by the flag.
    pub fn passes<T>(&self, f: impl FnOnce(&Arc<AtomicBool>) -> T) -> T {
        *self
            .shared
            .phase
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Phase::Passes;
        let r = f(&self.shared.cancelled);
        *self
            .shared
            .phase
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Phase::Rendering;
        r
    }

    /// The signal received so far, if any.
    pub fn signal(&self) -> Option<i32> {
        match self.shared.signal.load(Ordering::SeqCst) {
            0 => None,
            s => Some(s),
        }
    }

    /// Write the last image of a pass-phase render even though a signal came (it is the
    /// image of the completed samples, which the signal asked for): not cancellable; a
    /// further signal during it exits at once, leaving the old output intact (the write
    /// goes to a temp file renamed over it).
    pub fn final_write<T>(
        &self,
        write: impl FnOnce(&WriteControl) -> anyhow::Result<T>,
    ) -> anyhow::Result<T> {
        *self
            .shared
            .phase
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Phase::Passes;
        let r = write(&WriteControl::default());
        *self
            .shared
            .phase
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Phase::Rendering;
        r
    }

    /// Switch phase; fails with [`Interrupted`] if a signal has arrived.
    fn set_phase(&self, to: Phase) -> anyhow::Result<()> {
        let mut phase = self
            .shared
            .phase
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        *phase = to;
        match self.shared.signal.load(Ordering::SeqCst) {
            0 => Ok(()),
            signal => Err(Interrupted { signal }.into()),
        }
    }
}
