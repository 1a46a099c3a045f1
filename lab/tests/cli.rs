//! Running the lab binary in the tests: its refusals leave the directory as it was.

use crate::refusals::refused_by;
use assert_cmd::Command;
use std::path::Path;

pub fn bin() -> Command {
    Command::cargo_bin("photon-fpga-lab").unwrap()
}

pub fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// Run `args` and assert the refusal ([`refused_by`]).
pub fn refused(dir: &Path, args: &[String], message: &str) {
    refused_by(bin(), dir, args, message);
}

/// Run `args`, which must succeed; its standard output.
pub fn stdout_of(args: &[String]) -> String {
    let run = bin().args(args).assert().success();
    String::from_utf8_lossy(&run.get_output().stdout).to_string()
}

#[test]
fn memory_core_refuses_bad_input_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    refused(
        dir.path(),
        &strings(&["memory-core", "--fmax-mhz", "0", "--out-dir", d]),
        "--fmax-mhz",
    );
    refused(
        dir.path(),
        &strings(&["memory-core", "--photons", "0", "--out-dir", d]),
        "--photons must be in",
    );
    refused(
        dir.path(),
        &strings(&["memory-core", "--out-dir", &format!("{d}/missing")]),
        "missing",
    );
}
