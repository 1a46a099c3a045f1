//! Wall-clock time per stage of a render, printed as the paper's Fig. 2 breakdown
//! (ray emission, photon emission, kd-tree build, kd-tree search, other).

use std::fmt;
use std::time::{Duration, Instant};

/// The stages of paper Fig. 2, in its order.
pub const STAGES: [&str; 5] = [
    "ray emission",
    "photon emission",
    "kd-tree build",
    "kd-tree search",
    "other",
];

/// Accumulated time per stage.
#[derive(Default, Debug, Clone)]
pub struct StageTimes {
    times: [Duration; 5],
}

impl StageTimes {
    /// Run `f` and charge its time to `stage` (one of [`STAGES`]).
    pub fn time<T>(&mut self, stage: &str, f: impl FnOnce() -> T) -> T {
        let i = STAGES
            .iter()
            .position(|s| *s == stage)
            .unwrap_or_else(|| panic!("unknown stage {stage}"));
        let t0 = Instant::now();
        let out = f();
        self.times[i] += t0.elapsed();
        out
    }

    pub fn total(&self) -> Duration {
        self.times.iter().sum()
    }
}

impl fmt::Display for StageTimes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let total = self.total().as_secs_f64().max(1e-12);
        writeln!(f, "{:<16} {:>10} {:>7}", "stage", "seconds", "share")?;
        for (name, t) in STAGES.iter().zip(&self.times) {
            let s = t.as_secs_f64();
            writeln!(f, "{name:<16} {s:>10.3} {:>6.1}%", 100.0 * s / total)?;
        }
        write!(f, "{:<16} {:>10.3} {:>6.1}%", "total", total, 100.0)
    }
}
