//! BankMap against the bank model's own mapping (`host::banking::mapping`, the
//! software the mapping was chosen with): for random and boundary addresses of
//! several (L, b, address width) shapes and both mappings (XOR-fold, modulo), the
//! replica flag, the bank and the row must be the model's; and the (bank, row) pairs of all addresses below the
//! replica's end are distinct.

use crate::common::{rng, settle};
use photon_fpga::hw::config::bank_config::BankMapping;
use photon_fpga::hw::store::bank_map::BankMap;
use photon_fpga_lab::banking::mapping::{BankMap as Model, Mapping};
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::HashSet;

#[test]
fn bank_and_row_are_the_models_xor_fold_and_modulo() {
    let shapes = [
        (0, 0, 8, 1),
        (4, 3, 10, 2),
        (9, 5, 17, 3),
        (10, 7, 19, 4),
        (10, 10, 20, 5),
    ];
    let maps = [
        (BankMapping::Xor, Mapping::XorFold),
        (BankMapping::Modulo, Mapping::Modulo),
    ];
    for ((l, b, h, seed), (mapping, model_mapping)) in shapes
        .into_iter()
        .flat_map(|s| maps.into_iter().map(move |m| (s, m)))
    {
        let mut uut = BankMap::new(l, b, h, mapping);
        uut.connect_all();
        check_all(&uut).expect("BankMap checks");
        let model = Model {
            mapping: model_mapping,
            bank_bits: b,
            replicated: l,
        };
        let mut r = rng(seed);
        let top = (1u32 << h) - 1;
        let mut addrs: Vec<u32> = (0..3000).map(|_| r.gen_range(1..=top)).collect();
        addrs.extend([
            1,
            top,
            (1 << l).max(1),
            (1u32 << l).saturating_sub(1).max(1),
        ]);
        let mut cells = HashSet::new();
        for a in addrs {
            uut.address.next = (a as u64).into();
            settle(&mut uut);
            let want = model.bank(a);
            assert_eq!(uut.replicated.val(), want.is_none(), "L {l} b {b}: {a}");
            if let Some(bank) = want {
                assert_eq!(uut.bank.val().to_u64(), bank as u64, "L {l} b {b}: {a}");
                assert_eq!(uut.row.val().to_u64(), (a >> b) as u64, "L {l} b {b}: {a}");
                cells.insert((a, bank, a >> b));
            }
        }
        let pairs: HashSet<(u32, u32)> = cells.iter().map(|&(_, bank, row)| (bank, row)).collect();
        assert_eq!(
            pairs.len(),
            cells.len(),
            "L {l} b {b}: two addresses share a cell"
        );
    }
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints() {
    use photon_fpga::hw::export::verilog::export_block;
    let e = export_block(BankMap::new(10, 7, 19, BankMapping::Xor)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
    crate::common::lint_top(dir.path());
}
