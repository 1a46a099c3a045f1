//! Output files that a failed run never leaves behind, checked before any work.
//!
//! * [`Output::check`] runs first: the path is not one of the run's inputs, not a
//!   directory, and its directory takes a new file (tried with a temporary file).
//! * A regular (or new) file is written to a uniquely named temporary file beside it
//!   and renamed into place only when complete, so a reader never sees half a file
//!   and no user's `X.tmp` is ever touched.
//! * Anything that is not a regular file — a device, a FIFO, a symlink (e.g.
//!   `/dev/stdout`, which may lead to the file a shell redirected into) — is never
//!   replaced by a rename: it is opened and written in place (a symlink's regular
//!   target truncated first), once the run's work is done.
//! * [`Output::stage`] is for producers that write by path (the simulator's VCD): a
//!   temporary file to write, renamed by [`Staged::commit`] once the whole run has
//!   succeeded and deleted if it is dropped.
//! * An interrupted run (Ctrl-C, SIGTERM) runs no destructor, so every temporary
//!   file is also remembered, and [`remove_on_interrupt`] installs the handler that
//!   deletes those still there before the process exits.

use crate::host::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A checked output path.
#[derive(Debug)]
pub struct Output {
    /// What the user named (for messages).
    shown: PathBuf,
    /// Where the bytes go.
    target: PathBuf,
    /// Not a regular file (device, FIFO, symlink): written in place.
    in_place: bool,
    /// In place into a regular file (a symlink's target): truncate it first.
    truncate: bool,
}

/// An output being written by path; see [`Output::stage`].
#[derive(Debug)]
pub struct Staged {
    temp: Option<tempfile::TempPath>,
    target: PathBuf,
    shown: PathBuf,
}

/// Every temporary file this process made. One renamed into place or deleted is
/// no longer there, so the interrupt handler's removal of the list touches only
/// those a run was still writing.
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Install (once per process) the Ctrl-C / SIGTERM handler that deletes the
/// temporary files of the outputs being written, then exits with status 130.
pub fn remove_on_interrupt() -> Result<()> {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    let mut result = Ok(());
    INSTALLED.call_once(|| {
        result = ctrlc::set_handler(|| {
            let list = TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner());
            for p in list.iter() {
                let _ = std::fs::remove_file(p);
            }
            eprintln!("interrupted; no output written");
            std::process::exit(130);
        })
        .map_err(|e| Error::new(format!("cannot install the interrupt handler: {e}")));
    });
    result
}

/// A temporary file in `dir` with the permissions a new file gets (0o666 less the
/// umask), not the owner-only ones of a plain temporary file: it becomes the output.
fn temp_in(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    b.prefix(".photon-fpga-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let file = b.tempfile_in(dir)?;
    TEMPORARIES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(file.path().to_path_buf());
    Ok(file)
}

fn err(path: &Path, what: impl std::fmt::Display) -> Error {
    Error::new(format!("{}: {what}", path.display()))
}

impl Output {
    /// Check `path` as an output of a run that reads `inputs`.
    pub fn check(path: &Path, inputs: &[&Path]) -> Result<Output> {
        for input in inputs {
            if same_file::is_same_file(path, input).unwrap_or(false) {
                return Err(err(
                    path,
                    format!(
                        "is also an input ({}); refusing to overwrite it",
                        input.display()
                    ),
                ));
            }
        }
        let link = std::fs::symlink_metadata(path)
            .map(|m| m.file_type().is_symlink())
            .unwrap_or(false);
        let (in_place, truncate) = match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => return Err(err(path, "is a directory")),
            Ok(m) => (link || !m.is_file(), m.is_file()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && !link => (false, false),
            Err(e) => return Err(err(path, format!("cannot be used as output: {e}"))),
        };
        let out = Output {
            shown: path.to_path_buf(),
            target: path.to_path_buf(),
            in_place,
            truncate,
        };
        if !out.in_place {
            // The directory must take a new file: try it now, before any work.
            temp_in(out.dir())
                .map_err(|e| err(path, format!("cannot write in its directory: {e}")))?;
        }
        Ok(out)
    }

    /// The path as the user gave it.
    pub fn path(&self) -> &Path {
        &self.shown
    }

    fn dir(&self) -> &Path {
        match self.target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        }
    }

    /// Write the whole output with `body`: atomically for a file, in place for a
    /// device or FIFO.
    pub fn write(&self, body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
        let e = |x: std::io::Error| err(&self.shown, format!("cannot write: {x}"));
        if self.in_place {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(self.truncate)
                .open(&self.target)
                .map_err(e)?;
            let mut w = std::io::BufWriter::new(f);
            body(&mut w).map_err(e)?;
            return w.flush().map_err(e);
        }
        let tmp = temp_in(self.dir()).map_err(e)?;
        let mut w = std::io::BufWriter::new(tmp);
        body(&mut w).map_err(e)?;
        let tmp = w.into_inner().map_err(|x| e(x.into_error()))?;
        tmp.persist(&self.target).map_err(|x| e(x.error))?;
        Ok(())
    }

    /// A path for a producer to write to: a temporary file beside the output (or the
    /// device itself), made the output by [`Staged::commit`].
    pub fn stage(&self) -> Result<Staged> {
        if self.in_place {
            return Ok(Staged {
                temp: None,
                target: self.target.clone(),
                shown: self.shown.clone(),
            });
        }
        let tmp =
            temp_in(self.dir()).map_err(|e| err(&self.shown, format!("cannot write: {e}")))?;
        Ok(Staged {
            temp: Some(tmp.into_temp_path()),
            target: self.target.clone(),
            shown: self.shown.clone(),
        })
    }
}

impl Staged {
    /// Where the producer writes.
    pub fn path(&self) -> &Path {
        self.temp.as_deref().unwrap_or(&self.target)
    }

    /// The run succeeded: make the staged file the output.
    pub fn commit(self) -> Result<()> {
        if let Some(t) = self.temp {
            t.persist(&self.target)
                .map_err(|e| err(&self.shown, format!("cannot write: {}", e.error)))?;
        }
        Ok(())
    }
}
