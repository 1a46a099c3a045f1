//! docs/BANKING.md: the bank model's sweep on one image's read stream, each table
//! with the stream, the model and the command that made it.

use super::mapping::{BankMap, Mapping};
use super::order::QueryOrder;
use super::sim::{imbalance, Issue, Measured};
use super::stream::ImageStream;
use super::sweep::{measure, Point, BARREL_LOOP, INTERCONNECT_CYCLES, SLOTS};
use photon_fpga::host::device::plan::{plan, Device, Limits, ECP5_85K, XC6VSX475T};
use std::fmt::Write;

/// What the report sweeps.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// (D, b) of the mapping × order tables.
    pub compare: Vec<(usize, u32)>,
    /// D values and b values of the conflict curve.
    pub curve_d: Vec<usize>,
    pub curve_b: Vec<u32>,
    /// Replicated levels of the tables, and those the ablation tries.
    pub replicated: u32,
    pub ablate_l: Vec<u32>,
    /// (D, b) of the ablations.
    pub ablate_at: (usize, u32),
    /// Map sizes the device plans are shown for.
    pub plan_sizes: Vec<usize>,
}

impl Sweep {
    /// The full sweep: L = 10 (one 1K-word BlockRAM of replica per datapath).
    pub fn full() -> Self {
        Sweep {
            compare: vec![(16, 6), (16, 7), (8, 5)],
            curve_d: vec![8, 16, 32],
            curve_b: vec![4, 5, 6, 7, 8, 9, 10],
            replicated: 10,
            ablate_l: vec![0, 3, 6, 10],
            ablate_at: (16, 6),
            plan_sizes: vec![1_023, 63_947, 388_826, 1_000_000],
        }
    }

    /// A small sweep for the test of the command.
    pub fn quick() -> Self {
        Sweep {
            compare: vec![(4, 3)],
            curve_d: vec![4],
            curve_b: vec![2, 3],
            replicated: 4,
            ablate_l: vec![0, 4],
            ablate_at: (4, 3),
            plan_sizes: vec![1_023, 388_826],
        }
    }
}

fn point(m: Mapping, o: QueryOrder, d: usize, b: u32, l: u32) -> Point {
    Point {
        mapping: m,
        order: o,
        datapaths: d,
        bank_bits: b,
        replicated: l,
        issue: Issue::Rotate,
        bank_ports: 1,
    }
}

/// reads/cycle/datapath, conflict rate, bank imbalance, joined by `sep`.
fn cells(m: &Measured, sep: &str) -> String {
    format!(
        "{:.3}{sep}{:.1} %{sep}{:.2}",
        m.reads_per_cycle_per_datapath(),
        100.0 * m.conflict_rate(),
        m.bank_imbalance()
    )
}

/// Everything the report says, and the best (mapping, order) of the first table.
pub struct Report {
    pub text: String,
    pub best: (Mapping, QueryOrder),
}

/// Run `sweep` on `stream` and render the report. `how`: the stream's
/// description and the command that regenerates the report.
pub fn report(stream: &ImageStream, sweep: &Sweep, how: &str) -> Report {
    let mut t = String::new();
    let n = stream.tree.len();
    let q = stream.queries.len();
    let reads = stream.total_reads();
    let loop_cycles = BARREL_LOOP + INTERCONNECT_CYCLES;
    let _ = writeln!(
        t,
        "# Banked photon store: bank conflicts, measured in software\n"
    );
    let _ = writeln!(t, "<!-- generated; edit src/host/banking, not this -->\n");
    let _ = writeln!(t, "{how}\n");
    let _ = writeln!(
        t,
        "Stream: {n} photons, {q} queries, {reads} reads ({:.1} per query), from the \
         software search (`knn::search_with`, the cell traversal), which the barrel \
         datapath matches read for read. Model (`src/host/banking/sim.rs`): each \
         datapath has {SLOTS} slots, one read in flight per slot, at most one read \
         issued per cycle; a granted read's slot can issue again {loop_cycles} cycles \
         later (the barrel's {BARREL_LOOP}-cycle slot loop + {INTERCONNECT_CYCLES} \
         interconnect registers); the top L levels are read from the datapath's own \
         copy; a bank serves one read per cycle, round robin; a refused slot goes to \
         the back of its datapath's ready queue (unless stated). Columns: reads per \
         cycle per datapath over the whole run (every read counted, replicated ones \
         too; 1.0 is the most a datapath issues), refused bank requests / offered \
         bank requests, busiest bank's reads / mean bank's reads.\n",
        reads as f64 / q.max(1) as f64
    );
    // The ideal: no bank ever refuses (every level replicated).
    let ideal_pts: Vec<Point> = sweep
        .curve_d
        .iter()
        .map(|&d| point(Mapping::Modulo, QueryOrder::Raster, d, 0, 32))
        .collect();
    let ideal = measure(stream, &ideal_pts);
    let _ = writeln!(
        t,
        "Without banks (every node in every datapath's own copy: the slots and the slot \
         loop alone): {}.\n",
        sweep
            .curve_d
            .iter()
            .zip(&ideal)
            .map(|(d, m)| format!("D = {d}: {:.3}", m.reads_per_cycle_per_datapath()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let l = sweep.replicated;
    // The first table chooses: the mapping with the best mean over the orders
    // (the host may send any), then that mapping's best order.
    let mut best = (Mapping::XorFold, QueryOrder::Raster);
    let mut best_mean = f64::MIN;
    for (ti, &(d, b)) in sweep.compare.iter().enumerate() {
        let pts: Vec<Point> = Mapping::ALL
            .iter()
            .flat_map(|&m| QueryOrder::ALL.iter().map(move |&o| point(m, o, d, b, l)))
            .collect();
        let res = measure(stream, &pts);
        let _ = writeln!(
            t,
            "## Mapping × query order, D = {d}, B = {}, L = {l}\n",
            1 << b
        );
        let _ = write!(t, "| mapping |");
        for o in QueryOrder::ALL {
            let _ = write!(t, " {} |", o.name());
        }
        let _ = writeln!(t, " mean |");
        let _ = writeln!(t, "|---|{}---:|", "---|".repeat(QueryOrder::ALL.len()));
        for (mi, m) in Mapping::ALL.iter().enumerate() {
            let _ = write!(t, "| {} |", m.name());
            let row = &res[mi * QueryOrder::ALL.len()..(mi + 1) * QueryOrder::ALL.len()];
            for r in row {
                let _ = write!(t, " {} |", cells(r, " / "));
            }
            let rpc = |r: &Measured| r.reads_per_cycle_per_datapath();
            let mean = row.iter().map(rpc).sum::<f64>() / row.len() as f64;
            let _ = writeln!(t, " {mean:.3} |");
            if ti == 0 && mean > best_mean {
                best_mean = mean;
                let top = (0..row.len())
                    .max_by(|&a, &b| rpc(&row[a]).total_cmp(&rpc(&row[b])))
                    .unwrap_or(0);
                best = (*m, QueryOrder::ALL[top]);
            }
        }
        let _ = writeln!(
            t,
            "\nEach cell: reads/cycle/datapath / conflict rate / bank imbalance.\n"
        );
    }
    let (bm, bo) = best;
    let _ = writeln!(
        t,
        "Chosen from the first table: {}, the best mean over the orders, and its best \
         order, {}. The tables below use both.\n",
        bm.name(),
        bo.name()
    );
    // The conflict curve.
    let pts: Vec<Point> = sweep
        .curve_d
        .iter()
        .flat_map(|&d| sweep.curve_b.iter().map(move |&b| point(bm, bo, d, b, l)))
        .collect();
    let res = measure(stream, &pts);
    let _ = writeln!(
        t,
        "## Bank-conflict curve: {}, {} order, L = {l}\n",
        bm.name(),
        bo.name()
    );
    let _ = write!(t, "| D \\ B |");
    for b in &sweep.curve_b {
        let _ = write!(t, " {} |", 1u32 << b);
    }
    let _ = writeln!(t, "\n|---|{}", "---:|".repeat(sweep.curve_b.len()));
    for (di, d) in sweep.curve_d.iter().enumerate() {
        let _ = write!(t, "| {d} |");
        for bi in 0..sweep.curve_b.len() {
            let r = &res[di * sweep.curve_b.len() + bi];
            let _ = write!(
                t,
                " {:.3} ({:.1} %) |",
                r.reads_per_cycle_per_datapath(),
                100.0 * r.conflict_rate()
            );
        }
        let _ = writeln!(t);
    }
    let _ = writeln!(
        t,
        "\nEach cell: reads/cycle/datapath (conflict rate). The whole core reads D × \
         that per cycle.\n"
    );
    // Ablations.
    let (d, b) = sweep.ablate_at;
    let mut pts: Vec<(String, Point)> = sweep
        .ablate_l
        .iter()
        .map(|&al| (format!("L = {al}"), point(bm, bo, d, b, al)))
        .collect();
    let base = point(bm, bo, d, b, l);
    pts.push((
        format!("L = {l}, a refused datapath stalls (in order)"),
        Point {
            issue: Issue::InOrder,
            ..base
        },
    ));
    pts.push((
        format!("L = {l}, two read ports per bank"),
        Point {
            bank_ports: 2,
            ..base
        },
    ));
    let res = measure(stream, &pts.iter().map(|p| p.1).collect::<Vec<_>>());
    let _ = writeln!(
        t,
        "## Ablations: {}, {} order, D = {d}, B = {}\n",
        bm.name(),
        bo.name(),
        1 << b
    );
    let _ = writeln!(
        t,
        "| variant | reads/cycle/datapath | conflict rate | bank imbalance |"
    );
    let _ = writeln!(t, "|---|---:|---:|---:|");
    for ((name, _), r) in pts.iter().zip(&res) {
        let _ = writeln!(t, "| {name} | {} |", cells(r, " | "));
    }
    // Storage balance.
    let _ = writeln!(
        t,
        "\n## Storage: nodes per bank, busiest / mean (B = {}, L = {l})\n",
        1 << b
    );
    let _ = writeln!(t, "| mapping | storage imbalance |\n|---|---:|");
    for m in Mapping::ALL {
        let occ = BankMap {
            mapping: m,
            bank_bits: b,
            replicated: l,
        }
        .occupancy(n);
        let _ = writeln!(t, "| {} | {:.3} |", m.name(), imbalance(&occ));
    }
    plans(&mut t, &sweep.plan_sizes, stream.tree.layout.word_bits());
    Report {
        text: t,
        best: (bm, bo),
    }
}

fn plans(t: &mut String, sizes: &[usize], word_bits: u32) {
    let lim = Limits::default();
    let _ = writeln!(
        t,
        "\n## B, L, D by device (`device::plan`, {word_bits}-bit photon words, at least \
         {} datapaths, B ≥ {} × D, D ≤ {}, datapaths and crossbar ≤ {:.0} % of the logic)\n",
        lim.min_datapaths,
        lim.banks_per_datapath,
        lim.max_datapaths,
        100.0 * lim.logic_share
    );
    let _ = writeln!(
        t,
        "| device | photons | B | BlockRAMs per bank | L | D | bank ports | BlockRAMs (banks + \
         datapaths) | logic (datapaths + crossbar, by synth/device_costs.toml) |"
    );
    let _ = writeln!(t, "|---|---:|---:|---:|---:|---:|---|---|---|");
    let devs: [&Device; 2] = [&ECP5_85K, &XC6VSX475T];
    for dev in devs {
        for &n in sizes {
            match plan(n, word_bits, dev.datapath_brams, dev, &lim) {
                Ok(p) => {
                    let _ = writeln!(
                        t,
                        "| {} | {n} | {} | {} | {} | {} | {} | {} + {} of {} | {} + {} of {} |",
                        dev.name,
                        p.banks(),
                        p.brams_per_bank,
                        p.replicated_levels,
                        p.datapaths,
                        if p.bank_bits == 0 {
                            "–"
                        } else {
                            p.ports.name()
                        },
                        p.bank_brams,
                        p.datapath_brams,
                        dev.brams,
                        p.datapath_luts,
                        p.crossbar_luts,
                        dev.luts
                    );
                }
                Err(e) => {
                    let _ = writeln!(t, "| {} | {n} | refused: {e} | | | | | | |", dev.name);
                }
            }
        }
    }
}
