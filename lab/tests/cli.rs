//! Running the lab binary in the tests: its refusals leave the directory as it was.

use assert_cmd::Command;
use std::path::Path;

pub fn bin() -> Command {
    Command::cargo_bin("photon-fpga-lab").unwrap()
}

pub fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// The names in `dir`, hidden files included.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Run `args` and assert the failure: status 2, the message, no panic, and `dir`
/// exactly as it was (no output, no temporary file).
pub fn refused(dir: &Path, args: &[String], message: &str) {
    let before = listing(dir);
    let assert = bin().args(args).assert().code(2);
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(
        stderr.contains(message),
        "stderr {stderr:?} lacks {message:?}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(listing(dir), before, "a failed run left files behind");
}

/// Run `args`, which must succeed; its standard output.
pub fn stdout_of(args: &[String]) -> String {
    let run = bin().args(args).assert().success();
    String::from_utf8_lossy(&run.get_output().stdout).to_string()
}
