//! docs/MEMORY.md, part two: the chosen cache timed by the cycle model (`sim`)
//! against slots per datapath, on each memory, at k = 32 and k = 500; the closed
//! form beside it (Little's law: S ≥ L + m × Lm slots keep a datapath reading every
//! cycle, and D × m × block bytes per read must fit the memory's bytes per cycle);
//! then the choice, and why.

use super::memories::MEMORIES;
use super::report::{chosen_replay, Choice, Sweep};
use super::sim::{Machine, MemoryTiming};
use super::sweep::{replays, timed, Stream, LOOP};
use std::fmt::Write;

/// The main stream at k = 32 with each memory's latency doubled and quadrupled
/// (the latencies are partly assumed): reads/cycle/datapath against S.
fn latency_table(t: &mut String, main: &Stream, choice: &Choice) {
    let slots = [16usize, 32, 64];
    let scales = [1u64, 2, 4];
    let _ = writeln!(
        t,
        "\nLatency sensitivity ({}, reads/cycle/datapath; the latency is partly assumed):\n",
        main.label
    );
    let _ = write!(t, "| memory | latency |");
    for s in slots {
        let _ = write!(t, " S = {s} |");
    }
    let _ = writeln!(t, "\n|---|---:|{}", "---:|".repeat(slots.len()));
    for (mi, m) in MEMORIES.iter().enumerate() {
        let r = chosen_replay(m, mi, main, choice);
        let pts: Vec<_> = scales
            .iter()
            .flat_map(|&x| slots.iter().map(move |&s| (x, s)))
            .map(|(x, s)| {
                let mach = Machine {
                    datapaths: m.datapaths,
                    slots: s,
                    loop_cycles: LOOP,
                    layout: r.layout,
                    cache: r.cache,
                    sharing: r.sharing,
                    memory: MemoryTiming {
                        latency: m.latency * x,
                        bytes_per_cycle: m.bytes_per_cycle(),
                    },
                };
                (mach, choice.order)
            })
            .collect();
        let res = timed(main, &pts);
        for (xi, x) in scales.iter().enumerate() {
            let _ = write!(t, "| {} | {} cycles |", m.device.name, m.latency * x);
            for si in 0..slots.len() {
                let rpc = res[xi * slots.len() + si].reads_per_cycle_per_datapath(m.datapaths);
                let _ = write!(t, " {rpc:.3} |");
            }
            let _ = writeln!(t);
        }
    }
}

/// Append the timing tables and the choice to `t`; set `choice.slots`.
pub fn section(t: &mut String, streams: &[Stream], sweep: &Sweep, choice: &mut Choice) {
    let main = &streams[0];
    // The timed streams: the main map's, at every k measured.
    let timed_streams: Vec<&Stream> = streams
        .iter()
        .filter(|s| s.emitted == main.emitted)
        .collect();
    let _ = writeln!(
        t,
        "## Throughput: the cycle model ({} order, the chosen cache)\n\n\
         A slot loop of L = {LOOP} cycles (the barrel's 11 + 3 interconnect registers, \
         as `banking`); a miss parks its slot until its burst has arrived (a second \
         miss on a burst in flight waits for it), the other slots go on; the memory \
         serves bursts in order at its sustained bytes per cycle, each arriving its \
         latency after its transfer. Columns: reads per cycle per datapath (1.0 is the \
         most), hit rate (misses waiting on a burst in flight count as misses), the \
         data bus's busy share, most bursts in flight, queries/s = reads/cycle × D × \
         clock / reads per query. Closed form: m = misses per read from the trace \
         model, S ≥ L + m × Lm slots needed, and the memory's bound on reads/cycle \
         per datapath, W / (D × m × block bytes).\n",
        choice.order.name()
    );
    let _ = writeln!(t, "| memory | stream | S | reads/cycle/datapath | hit rate | bus busy | bursts in flight | queries/s (modelled) |");
    let _ = writeln!(t, "|---|---|---:|---:|---:|---:|---:|---:|");
    let mut closed = String::new();
    let mut slots_chosen = vec![];
    for (mi, m) in MEMORIES.iter().enumerate() {
        let mut need = 0usize;
        let mut best_s = sweep.slots[0];
        for s in &timed_streams {
            let r = chosen_replay(m, mi, s, choice);
            let c = replays(s, &[(r, choice.order)])[0];
            let mpr = c.misses_per_read();
            let s_need = (LOOP as f64 + mpr * m.latency as f64).ceil() as usize;
            let bw = m.bytes_per_cycle()
                / (m.datapaths as f64 * mpr * f64::from(r.layout.block_bytes()));
            let _ = writeln!(
                closed,
                "| {} | {} | {:.4} | {} | {:.2} |",
                m.device.name, s.label, mpr, s_need, bw
            );
            let pts: Vec<_> = sweep
                .slots
                .iter()
                .map(|&sl| {
                    (
                        Machine {
                            datapaths: m.datapaths,
                            slots: sl,
                            loop_cycles: LOOP,
                            layout: r.layout,
                            cache: r.cache,
                            sharing: r.sharing,
                            memory: MemoryTiming {
                                latency: m.latency,
                                bytes_per_cycle: m.bytes_per_cycle(),
                            },
                        },
                        choice.order,
                    )
                })
                .collect();
            let res = timed(s, &pts);
            let rpcs: Vec<f64> = res
                .iter()
                .map(|x| x.reads_per_cycle_per_datapath(m.datapaths))
                .collect();
            let top = rpcs.iter().copied().fold(0.0, f64::max);
            let first = rpcs.iter().position(|&x| x >= 0.95 * top).unwrap_or(0);
            best_s = best_s.max(sweep.slots[first]);
            need = need.max(s_need);
            for ((sl, x), rpc) in sweep.slots.iter().zip(&res).zip(&rpcs) {
                let hit = x.hits as f64 / (x.hits + x.misses + x.merged).max(1) as f64;
                let qps = rpc * m.datapaths as f64 * m.clock_mhz * 1e6 / s.reads_per_query();
                let _ = writeln!(
                    t,
                    "| {} | {} | {sl} | {rpc:.3} | {:.1} % | {:.1} % | {} | {:.2} M |",
                    m.device.name,
                    s.label,
                    100.0 * hit,
                    100.0 * x.bus_utilisation(),
                    x.max_in_flight,
                    qps / 1e6
                );
            }
        }
        let _ = need;
        slots_chosen.push(best_s);
    }
    latency_table(t, main, choice);
    let _ = writeln!(
        t,
        "\nClosed form (modelled, from the trace model's misses per read):\n\n\
         | memory | stream | misses/read m | slots needed L + m × Lm | memory bound on reads/cycle/datapath |\n\
         |---|---|---:|---:|---:|\n{closed}"
    );
    let _ = writeln!(
        t,
        "Chosen S per memory: the fewest slots of the sweep within 5 % of the best \
         reads/cycle on every timed stream: {}.\n",
        MEMORIES
            .iter()
            .zip(&slots_chosen)
            .map(|(m, s)| format!("{} S = {s}", m.device.name))
            .collect::<Vec<_>>()
            .join(", ")
    );
    choice.slots = slots_chosen;
    why(t, choice);
}

fn why(t: &mut String, c: &Choice) {
    let cache = super::cache::CacheConfig {
        lines: 1,
        ways: c.ways,
        policy: c.policy,
    }
    .name();
    let _ = writeln!(t, "## The choice, and why\n");
    let _ = writeln!(
        t,
        "What the hardware step of issue 52 builds, from the tables above (each rule \
         stated with its table; every number modelled):\n"
    );
    for (mi, m) in MEMORIES.iter().enumerate() {
        let _ = writeln!(
            t,
            "* **{}**: the top T = {} levels on chip{}; below them blocks of s = {} \
             levels (a subtree of {} nodes, {} bytes, one line); a {cache} cache, {}, in \
             the BlockRAM the device has left; S = {} slots per datapath.",
            m.name,
            c.on_chip[mi],
            if c.on_chip[mi] == m.replica_levels {
                " (the replica beside each datapath, no banked store)"
            } else {
                " (the replica and a banked store below it)"
            },
            c.block_levels[mi],
            (1u32 << c.block_levels[mi]) - 1,
            ((1u32 << c.block_levels[mi]) * 4).div_ceil(m.burst_bytes) * m.burst_bytes,
            c.sharing.name(),
            c.slots[mi]
        );
    }
    let _ = writeln!(
        t,
        "* **Query order: {}.** The host sends the queries in this order and returns \
         the results in the caller's (issue 52, item 5).\n",
        c.order.name()
    );
    let _ = writeln!(
        t,
        "Why: a block of s levels is one line and whole bursts, so a descent pays one \
         memory latency per s levels; s is the one with the fewest DRAM bytes per \
         query, which the memory's bound (the closed form's last column) rewards. \
         {} {} {}",
        if c.ways == Some(1) {
            "A direct-mapped cache is within half a point of every associativity at the \
             device's budget (a coherent stream's working set is small beside it), and \
             needs no replacement state at all."
        } else {
            "More ways and LRU's per-hit update buy less than half a point of hit rate."
        },
        match c.sharing {
            super::trace::Sharing::Shared => {
                "One cache shared by every datapath, because splitting it per datapath \
                 pair loses more than 1 % of hit rate (each pair's queries reach every \
                 part of the tree, so each pair's cache holds the same blocks again); in \
                 hardware it is banked by block id like the on-chip store, its crossbar \
                 registered (issue 52, item 6)."
            }
            super::trace::Sharing::PerPair => {
                "One cache per datapath pair keeps each cache port private (no crossbar, \
                 whose arbitration sets the banked core's clock, synth/REPORT.md)."
            }
        },
        if c.slots.iter().all(|&x| x <= crate::banking::sweep::SLOTS) {
            "The slots: the barrel's 16 already cover L + m × Lm at these hit rates, so \
             a miss's wait is hidden by the other slots; the latency table shows how \
             many a slower memory would need."
        } else {
            "The slots: more than the barrel's 16, as the cycle model needs to hide the \
             latency (the closed form's L + m × Lm, with the bursts' queueing on top)."
        }
    );
}
