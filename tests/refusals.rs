//! A refused run, for the product's and the lab's command-line tests: exit status
//! 2, the message on stderr, no panic, and the directory exactly as it was (no
//! output, no temporary file).
#![allow(dead_code)]

use assert_cmd::Command;
use std::path::Path;

/// The names in `dir`, hidden files included.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Run `cmd` with `args` and assert the refusal: status 2, `message`, no panic,
/// and `dir` as it was.
pub fn refused_by(mut cmd: Command, dir: &Path, args: &[String], message: &str) {
    let before = listing(dir);
    let assert = cmd.args(args).assert().code(2);
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(
        stderr.contains(message),
        "stderr {stderr:?} lacks {message:?}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(listing(dir), before, "a failed run left files behind");
}
