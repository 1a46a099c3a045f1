//! Cycle-exact cross-simulation of the exported Verilog against the rust-hdl model.
//!
//! [`record`] runs a [`PhotonSearchCore`](photon_fpga::hw::top::core::PhotonSearchCore) (or,
//! for T > 1 trees, a [`PhotonSearchArray`](photon_fpga::hw::top::array::PhotonSearchArray))
//! through the one [`Driver`] (reset, load each map, stream its queries, accept
//! results; seeded random stalls on every valid/ready stream; the next map is
//! presented as soon as the previous map's queries are all accepted, so the core
//! must hold it back until its searches are done), with a [`Recorder`] observing:
//! it records every input port in every cycle (the *stimulus*) and every handshake
//! and status change (the *responses*). A generated Verilog testbench
//! ([`crate::common::xsim_tb`]) replays the stimulus into the exported `top`
//! without looking at any output and writes the responses it samples in the same
//! format; under Icarus Verilog and Verilator the two response files must be equal
//! byte for byte ([`compare`]), which also means every result leaves at the same
//! cycle. Replaying blindly is what makes a divergence visible: if the Verilog
//! raises a ready one cycle late, its handshake lines move.
//!
//! Both formats are derived from the top's ports ([`ports`]), so they follow the
//! block: no port is named here.
//!
//! # Stimulus file (`stim.hex`)
//!
//! Text, read by `$readmemh`. Lines starting with `//` are comments (the first one
//! lists the columns). Then one line per clock cycle, cycle 0 first, with one
//! zero-padded hexadecimal field per input port except the clock, in port order,
//! separated by one space. Line `c` holds the inputs applied after the falling edge
//! that precedes rising edge `c`; they hold until the next falling edge.
//!
//! # Response file (`resp.txt`)
//!
//! One line per event, in cycle order, `CYCLE` in decimal, values in zero-padded hex
//! of the port's width, sampled just before rising edge `CYCLE` (what that edge acts
//! on). For every stream bundle `B` (ports `B$valid`, `B$ready` and its data
//! members), in port order, a line when a beat moves; then the status outputs (the
//! outputs outside any stream bundle) when they change and at cycle 0:
//!
//! ```text
//! CYCLE B member member ...         a beat of bundle B moved (valid && ready)
//! CYCLE S status status ...         status changed
//! END CYCLES                        the run's cycle count
//! ```

use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::photon_word::TreeImage;
use photon_fpga::hw::error::HwError;
use photon_fpga::hw::export::ports::{self, Port};
use photon_fpga::hw::sim::driver::{Cycle, Driver, HwQuery, HwResult, Job, Observer, RunLimits};
use photon_fpga::hw::sim::native;
use std::fmt::Write as _;
use std::sync::{Arc, Mutex};

/// Idle cycles recorded after the last result.
pub const TAIL_CYCLES: u64 = 4;

/// One map and the queries run on it.
#[derive(Clone, Debug)]
pub struct XsimMap<'a> {
    pub tree: TreeImage<'a>,
    pub queries: Vec<HwQuery>,
}

/// A recorded rust-hdl run.
#[derive(Clone, Debug, Default)]
pub struct XsimRun {
    /// The ports of the recorded top, in port order.
    pub ports: Vec<Port>,
    /// The stimulus file's text.
    pub stimulus: String,
    pub cycles: usize,
    /// The response file's text.
    pub responses: String,
    /// Per map, per query in input order: what the rust-hdl core returned.
    pub results: Vec<Vec<HwResult>>,
}

/// A stream bundle of the top: where its valid, ready and data members are.
#[derive(Clone, Debug)]
pub struct Bundle {
    pub name: String,
    pub valid: usize,
    pub ready: usize,
    pub members: Vec<usize>,
}

/// The stream bundles of `ports` (those with `valid` and `ready` members), in port
/// order, and the status outputs (outputs outside any stream bundle, in port
/// order).
pub fn bundles(ports: &[Port]) -> (Vec<Bundle>, Vec<usize>) {
    let mut bundles: Vec<Bundle> = vec![];
    let mut status = vec![];
    for (i, p) in ports.iter().enumerate() {
        let Some(b) = p.bundle() else {
            if !p.input {
                status.push(i);
            }
            continue;
        };
        let at = match bundles.iter().position(|x| x.name == b) {
            Some(at) => at,
            None => {
                bundles.push(Bundle {
                    name: b.to_string(),
                    valid: usize::MAX,
                    ready: usize::MAX,
                    members: vec![],
                });
                bundles.len() - 1
            }
        };
        match p.member() {
            "valid" => bundles[at].valid = i,
            "ready" => bundles[at].ready = i,
            _ => bundles[at].members.push(i),
        }
    }
    let (streams, others): (Vec<Bundle>, Vec<Bundle>) = bundles
        .into_iter()
        .partition(|b| b.valid != usize::MAX && b.ready != usize::MAX);
    for b in others {
        status.extend(
            [b.valid, b.ready]
                .into_iter()
                .chain(b.members)
                .filter(|&i| i != usize::MAX && !ports[i].input),
        );
    }
    status.sort_unstable();
    (streams, status)
}

/// The stimulus columns: every input but the clock.
pub fn stimulus_columns(ports: &[Port]) -> Vec<usize> {
    (0..ports.len())
        .filter(|&i| ports[i].input && ports[i].name != "clock")
        .collect()
}

/// Records stimulus and responses from the top's ports every cycle.
#[derive(Default)]
pub struct Recorder {
    ports: Vec<Port>,
    columns: Vec<usize>,
    bundles: Vec<Bundle>,
    status_ports: Vec<usize>,
    status: Option<Vec<String>>,
    stimulus: String,
    responses: String,
    cycles: usize,
}

impl Observer for Recorder {
    fn sampled(&mut self, c: &Cycle<'_>) -> Result<(), HwError> {
        let block = c.dut.block().ok_or_else(|| {
            HwError::CrossSim("the recorder needs rust-hdl's native simulation".into())
        })?;
        self.sample(block, c.index);
        Ok(())
    }
}

impl Recorder {
    /// Record cycle `cycle` of `block` (any block exported as `top`): its inputs
    /// applied and settled, its rising edge next. A block bench drives its block
    /// itself and calls this once per cycle, then [`Recorder::finish`].
    pub fn sample(&mut self, block: &dyn rust_hdl::prelude::Block, cycle: u64) {
        if self.ports.is_empty() {
            self.ports = ports::ports(block);
            self.columns = stimulus_columns(&self.ports);
            (self.bundles, self.status_ports) = bundles(&self.ports);
            self.stimulus = "// photon-fpga cross-simulation stimulus, columns:".into();
            for &i in &self.columns {
                let p = &self.ports[i];
                let _ = write!(self.stimulus, " {}({})", p.name, p.width);
            }
            self.stimulus.push('\n');
        }
        let v = ports::values(block);
        let fields: Vec<&str> = self.columns.iter().map(|&i| v[i].as_str()).collect();
        self.stimulus.push_str(&fields.join(" "));
        self.stimulus.push('\n');
        for b in &self.bundles {
            if v[b.valid] == "1" && v[b.ready] == "1" {
                let _ = write!(self.responses, "{cycle} {}", b.name);
                for &m in &b.members {
                    let _ = write!(self.responses, " {}", v[m]);
                }
                self.responses.push('\n');
            }
        }
        let st: Vec<String> = self.status_ports.iter().map(|&i| v[i].clone()).collect();
        if self.status.as_ref() != Some(&st) {
            let _ = writeln!(self.responses, "{cycle} S {}", st.join(" "));
            self.status = Some(st);
        }
        self.cycles += 1;
    }

    /// The recording as a run to replay (no search results).
    pub fn finish(self) -> XsimRun {
        let mut responses = self.responses;
        let _ = writeln!(responses, "END {}", self.cycles);
        XsimRun {
            ports: self.ports,
            stimulus: self.stimulus,
            cycles: self.cycles,
            responses,
            results: vec![],
        }
    }
}

/// Shares a [`Recorder`] between the driver and the caller.
struct Shared(Arc<Mutex<Recorder>>);

impl Observer for Shared {
    fn sampled(&mut self, c: &Cycle<'_>) -> Result<(), HwError> {
        self.0.lock().expect("recorder").sampled(c)
    }
}

/// Drive a fresh core for `cfg` through `maps` (each loaded, then queried; random
/// stalls from `stall_seed`), recording stimulus and responses.
pub fn record(
    cfg: &CoreConfig,
    maps: &[XsimMap<'_>],
    stall_seed: Option<u64>,
) -> Result<XsimRun, HwError> {
    if maps.is_empty() {
        return Err(HwError::CrossSim("no map".into()));
    }
    let recorder = Arc::new(Mutex::new(Recorder::default()));
    let dut = native::elaborate(cfg)?;
    let mut driver = Driver::new(dut, stall_seed, vec![Box::new(Shared(recorder.clone()))])?;
    let jobs: Vec<Job<'_>> = maps
        .iter()
        .map(|m| Job {
            load: Some(m.tree),
            queries: &m.queries,
        })
        .collect();
    let limits = RunLimits {
        max_cycles: None,
        tail_cycles: TAIL_CYCLES,
    };
    let results = driver.run(&jobs, limits)?;
    drop(driver);
    let rec = std::mem::take(&mut *recorder.lock().expect("recorder"));
    let mut responses = rec.responses;
    let _ = writeln!(responses, "END {}", rec.cycles);
    Ok(XsimRun {
        ports: rec.ports,
        stimulus: rec.stimulus,
        cycles: rec.cycles,
        responses,
        results: results
            .into_iter()
            .map(|m| m.into_iter().map(|r| r.expect("all received")).collect())
            .collect(),
    })
}

/// The first difference between two response files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// 1-based line number.
    pub line: usize,
    pub expected: Option<String>,
    pub got: Option<String>,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let show = |s: &Option<String>| s.clone().unwrap_or_else(|| "<end of file>".into());
        write!(
            f,
            "responses differ at line {}: rust-hdl `{}`, Verilog `{}`",
            self.line,
            show(&self.expected),
            show(&self.got)
        )
    }
}

/// Byte-for-byte comparison of response files; the first differing line if any.
pub fn compare(expected: &str, got: &str) -> Result<(), Mismatch> {
    if expected == got {
        return Ok(());
    }
    let mut e = expected.lines();
    let mut g = got.lines();
    let mut line = 0;
    loop {
        line += 1;
        let (a, b) = (e.next(), g.next());
        if a != b || (a.is_none() && b.is_none()) {
            return Err(Mismatch {
                line,
                expected: a.map(String::from),
                got: b.map(String::from),
            });
        }
    }
}
