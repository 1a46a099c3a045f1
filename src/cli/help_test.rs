//! Every value of every enum-valued option of every subcommand is offered and
//! explained in that subcommand's `--help`: the values come from the enums
//! (`ValueEnum`, each variant's doc its help), so a value without its own help
//! text (a hand-written list of names) fails.

use clap::CommandFactory;

#[test]
fn every_value_of_every_enum_option_is_in_its_commands_help() {
    let mut cli = super::Cli::command();
    cli.build();
    let mut checked = vec![];
    for sub in cli.get_subcommands() {
        let help = sub.clone().render_long_help().to_string();
        for arg in sub.get_arguments() {
            if !arg.get_action().takes_values() || arg.is_hide_set() {
                continue;
            }
            let values = arg.get_possible_values();
            if values.is_empty() {
                continue;
            }
            let id = format!("{} --{}", sub.get_name(), arg.get_id());
            for v in &values {
                let line = format!("- {}", v.get_name());
                assert!(help.contains(&line), "{id}: `{line}` missing from\n{help}");
                let doc = v.get_help().map(|h| h.to_string()).unwrap_or_default();
                assert!(!doc.is_empty(), "{id} {}: no help text", v.get_name());
                let first = doc.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
                assert!(
                    help.split_whitespace()
                        .collect::<Vec<_>>()
                        .join(" ")
                        .contains(&first),
                    "{id} {}: its help `{doc}` is missing",
                    v.get_name()
                );
            }
            checked.push(id);
        }
    }
    // The options the commands share are among those checked.
    for id in [
        "render --backend",
        "render --controller",
        "render --traversal",
        "gather --traversal",
        "gather --metric",
        "export-verilog --controller",
        "export-verilog --interface",
    ] {
        assert!(
            checked.iter().any(|c| c == id),
            "{id} not checked: {checked:?}"
        );
    }
}

/// The product's command line is a user's: its subcommands take at most 70 option
/// slots between them (each subcommand's `--help` lines, help included); the
/// measurement tools' options live in the lab's binary.
#[test]
fn the_product_takes_at_most_70_option_slots() {
    let mut cli = super::Cli::command();
    cli.build();
    let slots: Vec<(String, usize)> = cli
        .get_subcommands()
        .filter(|s| s.get_name() != "help")
        .map(|s| {
            let n = s
                .get_arguments()
                .filter(|a| !a.is_hide_set() && !a.is_positional())
                .count();
            (s.get_name().to_string(), n)
        })
        .collect();
    let total: usize = slots.iter().map(|(_, n)| n).sum();
    assert!(total <= 70, "{total} option slots: {slots:?}");
    assert!(slots.iter().all(|(_, n)| *n > 3), "{slots:?}");
}

/// `--backend native` runs rust-hdl's simulation; `rtl`, its earlier name, is an
/// accepted alias that the help says is one.
#[test]
fn the_native_backend_keeps_its_earlier_name() {
    use clap::Parser;
    let old = super::Cli::try_parse_from(["photon-fpga", "render", "--backend", "rtl"]);
    let new = super::Cli::try_parse_from(["photon-fpga", "render", "--backend", "native"]);
    assert!(old.is_ok() && new.is_ok());
    let help = super::Cli::command()
        .find_subcommand_mut("render")
        .unwrap()
        .render_long_help()
        .to_string();
    assert!(
        help.contains("- native") && help.contains("`rtl`, its earlier"),
        "{help}"
    );
}
