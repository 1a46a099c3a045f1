//! The on-disk cache of built Verilator models, shared by every process of a user.
//!
//! A model takes seconds to a minute to build and depends only on its inputs, so it
//! is built once per key and kept in the user's cache directory (not under the
//! working directory, which a render should leave as it found it):
//! `$PHOTON_FPGA_CACHE_DIR`, else `$XDG_CACHE_HOME/photon-fpga`, else
//! `~/.cache/photon-fpga`. The key is the SHA-256 of everything that changes the
//! built library: the Verilog, the harness, the tool's version and its arguments.
//!
//! Why this shape: a cache that several processes fill at once must never show a
//! half-built entry, and a failed or interrupted build must leave nothing behind.
//! So an entry is built in a temporary directory beside it and renamed into place
//! (a rename within one file system is atomic), under an exclusive lock per key so
//! that concurrent first builds of one model build it once and all succeed. An
//! entry records the SHA-256 of its library; one whose library is missing or does
//! not match (a damaged or truncated file) is removed and built again.

use crate::hw::error::HwError;
use sha2::{Digest, Sha256};
use std::fs::{self, File};
use std::path::{Path, PathBuf};

/// Environment variable that overrides the cache directory.
pub const CACHE_ENV: &str = "PHOTON_FPGA_CACHE_DIR";

/// The file inside an entry that says it is complete: the library's SHA-256.
const COMPLETE: &str = "complete";

fn cerr(msg: impl Into<String>) -> HwError {
    HwError::Simulation(msg.into())
}

/// The directory that holds the cached models.
pub fn cache_root() -> PathBuf {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(d) = env(CACHE_ENV) {
        return d;
    }
    let base = env("XDG_CACHE_HOME")
        .or_else(|| env("HOME").map(|h| h.join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("photon-fpga")
}

/// The key of a model made from `parts` (each hashed with its length, so that no
/// two different lists of parts share a key).
pub fn key(parts: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update((p.len() as u64).to_le_bytes());
        h.update(p);
    }
    format!("{:x}", h.finalize())
}

fn file_sha256(path: &Path) -> Option<String> {
    let bytes = fs::read(path).ok()?;
    Some(format!("{:x}", Sha256::digest(&bytes)))
}

/// Whether `entry` is complete and its `artifact` is the one it recorded.
fn intact(entry: &Path, artifact: &str) -> bool {
    match fs::read_to_string(entry.join(COMPLETE)) {
        Ok(recorded) => file_sha256(&entry.join(artifact)).is_some_and(|s| s == recorded.trim()),
        Err(_) => false,
    }
}

/// The cached entry `key` of `root` holding `artifact` (a path relative to the
/// entry), built by `build` into an empty directory if it is missing or damaged.
/// `build` must leave `artifact` in the directory it is given.
pub fn get_or_build(
    root: &Path,
    key: &str,
    artifact: &str,
    build: impl FnOnce(&Path) -> Result<(), HwError>,
) -> Result<PathBuf, HwError> {
    let entry = root.join(key);
    if intact(&entry, artifact) {
        return Ok(entry);
    }
    let io = |what: &str, p: &Path, e: std::io::Error| {
        cerr(format!("model cache: cannot {what} {}: {e}", p.display()))
    };
    fs::create_dir_all(root).map_err(|e| io("create", root, e))?;
    let lock_path = root.join(format!("{key}.lock"));
    let lock = File::create(&lock_path).map_err(|e| io("create", &lock_path, e))?;
    lock.lock().map_err(|e| io("lock", &lock_path, e))?;
    // Another process may have built it while this one waited for the lock.
    if intact(&entry, artifact) {
        return Ok(entry);
    }
    if entry.exists() {
        fs::remove_dir_all(&entry).map_err(|e| io("remove the damaged entry", &entry, e))?;
    }
    // Removed on every early return (a failed build leaves nothing).
    let tmp = tempfile::Builder::new()
        .prefix(&format!(".{key}."))
        .tempdir_in(root)
        .map_err(|e| io("make a build directory in", root, e))?;
    build(tmp.path())?;
    let sha = file_sha256(&tmp.path().join(artifact)).ok_or_else(|| {
        cerr(format!(
            "model cache: the build left no {artifact} in {}",
            tmp.path().display()
        ))
    })?;
    fs::write(tmp.path().join(COMPLETE), &sha)
        .map_err(|e| io("write", &tmp.path().join(COMPLETE), e))?;
    let built = tmp.keep();
    if let Err(e) = fs::rename(&built, &entry) {
        let _ = fs::remove_dir_all(&built);
        return Err(io("move the built model to", &entry, e));
    }
    Ok(entry)
}

/// Remove the entry `key` of `root` (a library that would not load): the next
/// [`get_or_build`] builds it again.
pub fn evict(root: &Path, key: &str) -> Result<(), HwError> {
    let entry = root.join(key);
    match fs::remove_dir_all(&entry) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(cerr(format!(
            "model cache: cannot remove {}: {e}",
            entry.display()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_once_rebuilds_a_damaged_entry_and_leaves_nothing_on_failure() {
        let root = tempfile::tempdir().unwrap();
        let k = key(&[b"verilog", b"harness"]);
        assert_ne!(k, key(&[b"veriloghar", b"ness"]), "parts are delimited");
        let builds = std::cell::Cell::new(0);
        let build = |d: &Path| {
            builds.set(builds.get() + 1);
            fs::write(d.join("lib.so"), b"model").map_err(|e| cerr(e.to_string()))
        };
        let e = get_or_build(root.path(), &k, "lib.so", build).unwrap();
        assert_eq!(fs::read(e.join("lib.so")).unwrap(), b"model");
        get_or_build(root.path(), &k, "lib.so", build).unwrap();
        assert_eq!(builds.get(), 1, "a complete entry is reused");
        // A truncated library no longer matches its record: built again.
        fs::write(e.join("lib.so"), b"mod").unwrap();
        get_or_build(root.path(), &k, "lib.so", build).unwrap();
        assert_eq!(builds.get(), 2);
        assert_eq!(fs::read(e.join("lib.so")).unwrap(), b"model");
        // A failed build: no entry, no build directory.
        let k2 = key(&[b"other"]);
        let r = get_or_build(root.path(), &k2, "lib.so", |d: &Path| {
            fs::write(d.join("top.v"), b"x").unwrap();
            Err(cerr("no verilator"))
        });
        assert!(r.is_err());
        let dirs: Vec<String> = fs::read_dir(root.path())
            .unwrap()
            .map(|e| e.unwrap())
            .filter(|e| e.path().is_dir())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(dirs, vec![k.clone()], "only the good entry is left");
        // A build that forgets its artifact is an error, not an entry.
        let k3 = key(&[b"third"]);
        assert!(get_or_build(root.path(), &k3, "lib.so", |_: &Path| Ok(())).is_err());
        assert!(!root.path().join(&k3).exists());
    }

    #[test]
    fn concurrent_first_builds_all_succeed_and_build_once() {
        let root = tempfile::tempdir().unwrap();
        let k = key(&[b"shared"]);
        let builds = std::sync::atomic::AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    get_or_build(root.path(), &k, "lib.so", |d: &Path| {
                        builds.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                        std::thread::sleep(std::time::Duration::from_millis(50));
                        fs::write(d.join("lib.so"), b"model").map_err(|e| cerr(e.to_string()))
                    })
                    .unwrap();
                });
            }
        });
        assert_eq!(builds.load(std::sync::atomic::Ordering::SeqCst), 1);
    }
}
