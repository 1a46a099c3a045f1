//! What an exact gather did — the certified share, the float fallbacks and the
//! photon reads on either side — and the run summary's line that reports it.

/// What an exact gather did, summed over its gathers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ExactStats {
    /// The m of the last gather, and whether it was chosen on a sample.
    pub m: usize,
    pub chosen: bool,
    pub queries: u64,
    /// Queries the core answered and the certificate proved.
    pub certified: u64,
    /// Queries sent to the core but answered by the float search: not certified,
    /// or with candidates tied at rank k.
    pub uncertified: u64,
    pub ties: u64,
    /// Queries outside the photon box (the core cannot take them): float search.
    pub outside: u64,
    /// Photons the core read, and the host's float search.
    pub core_reads: u64,
    pub host_reads: u64,
}

impl ExactStats {
    /// The run summary's line.
    pub fn summary(&self) -> String {
        let q = self.queries.max(1) as f64;
        let core = self.queries - self.outside;
        format!(
            "exact: m = {} ({}), k' = k + m; certified {} of {} core queries ({:.2} %); \
             float fallbacks {} ({} uncertified, {} ties) and {} outside the photon box; \
             photon reads per query: core {:.1} + host {:.1} = {:.1}",
            self.m,
            if self.chosen {
                "chosen on a sample"
            } else {
                "--refine"
            },
            self.certified,
            core,
            100.0 * self.certified as f64 / core.max(1) as f64,
            self.uncertified + self.ties,
            self.uncertified,
            self.ties,
            self.outside,
            self.core_reads as f64 / q,
            self.host_reads as f64 / q,
            (self.core_reads + self.host_reads) as f64 / q,
        )
    }
}
