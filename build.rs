//! Which Verilog tools the tests can use. A test whose tool is missing is compiled
//! as ignored, so `cargo test` reports it as ignored, never as passed; under
//! `CI=true` every such test runs and fails if its tool is missing.
//!
//! Sets `has_yosys`, `has_verilator`, `has_iverilog`. After installing a tool,
//! `touch build.rs` (or any change to PATH) makes cargo look again.

fn on_path(tool: &str) -> bool {
    std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join(tool).is_file()))
        .unwrap_or(false)
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo:rerun-if-env-changed=PATH");
    let ci = std::env::var("CI").map(|v| v == "true").unwrap_or(false);
    for tool in ["yosys", "verilator", "iverilog"] {
        println!("cargo::rustc-check-cfg=cfg(has_{tool})");
        if ci || on_path(tool) {
            println!("cargo::rustc-cfg=has_{tool}");
        }
    }
}
