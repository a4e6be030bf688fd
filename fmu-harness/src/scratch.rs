//! The master's temporary files: the folders FMUs are extracted to
//! (`<temp dir>/fmu-harness-<pid>-<n>-<nanos>-<stem>`) and a CSV being written. Each is
//! registered while it exists and removed when its owner drops it, on an error as on success;
//! [`remove_on_signals`] removes whatever is still registered when SIGINT, SIGTERM or SIGHUP
//! arrives, then lets the signal end the process as it would have (issue 35).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// What exists now and must not outlive the process.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    // A poisoned list is still a list of paths.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

fn remove(path: &Path) {
    let _ = if path.is_dir() {
        std::fs::remove_dir_all(path)
    } else {
        std::fs::remove_file(path)
    };
}

/// A folder or file removed (and unregistered) on drop.
#[derive(Debug)]
pub struct Scratch(PathBuf);

impl Scratch {
    /// A fresh folder under the system temp dir, unique within and across processes, created
    /// and registered under one lock (a signal cannot come between the two).
    pub fn directory(stem: &str) -> std::io::Result<Scratch> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let base = std::env::temp_dir();
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let mut list = live();
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let dir = base.join(format!(
                "fmu-harness-{}-{n}-{nanos}-{stem}",
                std::process::id()
            ));
            match std::fs::create_dir(&dir) {
                Ok(()) => {
                    list.push(dir.clone());
                    return Ok(Scratch(dir));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// A new file at `path` (refused if something is there), registered.
    pub fn file(path: &Path) -> std::io::Result<(Scratch, std::fs::File)> {
        let mut list = live();
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)?;
        list.push(path.to_path_buf());
        Ok((Scratch(path.to_path_buf()), file))
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    /// Renames the file to `to` and stops looking after it (it is no longer temporary).
    pub fn persist(self, to: &Path) -> std::io::Result<()> {
        let mut list = live();
        std::fs::rename(&self.0, to)?;
        list.retain(|p| *p != self.0);
        drop(list);
        std::mem::forget(self);
        Ok(())
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let mut list = live();
        remove(&self.0);
        list.retain(|p| *p != self.0);
    }
}

/// The registered paths now (for tests and messages).
pub fn registered() -> Vec<PathBuf> {
    live().clone()
}

/// Removes every registered path; what the signal thread runs before the process ends.
pub fn remove_all() {
    let mut list = live();
    for p in list.drain(..) {
        remove(&p);
    }
}

/// Starts a thread that, on SIGINT, SIGTERM or SIGHUP, removes every registered path and then
/// ends the process by the signal's default action (its exit status says which signal). The
/// command line calls it once; a library user of the crate decides for itself.
#[cfg(unix)]
pub fn remove_on_signals() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("fmu-harness-signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                remove_all();
                // Back to the default action, raised again: the process ends by the signal.
                let _ = signal_hook::low_level::emulate_default_handler(signal);
                std::process::exit(128 + signal);
            }
        })?;
    Ok(())
}

#[cfg(not(unix))]
pub fn remove_on_signals() -> std::io::Result<()> {
    Ok(())
}
