//! What a run can be asked for, checked before any work or allocation: a request
//! that cannot be served is refused with a clear error (exit 2), never met with an
//! allocator abort or a run that eats memory until it is killed.

use crate::host::error::{Error, Result};

/// Photons emitted by one render at most (`--photons`); the trace also stops as
/// soon as more photons are stored than the map's capacity.
pub const MAX_EMITTED: usize = 1 << 32;

/// Memory the gathered neighbours of one run may take (queries × k of them), about a
/// third of the 24 GiB machines this project targets.
pub const MEMORY_BUDGET: u64 = 8 << 30;

/// Bytes one gathered neighbour takes, with its share of the per-query bookkeeping
/// (query point, result vector) spread over k = 1.
const NEIGHBOUR_BYTES: u64 = 16;
const QUERY_BYTES: u64 = 96;

/// Refuse a run whose `queries` gathers of up to `k` neighbours each (at most
/// `photons` exist) would not fit [`MEMORY_BUDGET`]. `what` names the options
/// that set the query count.
pub fn check_gather_memory(queries: u64, k: usize, photons: u64, what: &str) -> Result<()> {
    let k = (k as u64).min(photons);
    let bytes = k
        .checked_mul(NEIGHBOUR_BYTES)
        .and_then(|b| b.checked_add(QUERY_BYTES))
        .and_then(|b| b.checked_mul(queries));
    match bytes {
        Some(b) if b <= MEMORY_BUDGET => Ok(()),
        _ => Err(Error::new(format!(
            "{queries} queries ({what}) × up to {k} photons each would need about {} of memory \
             for the gathered photons; the limit is {} GiB: ask for fewer",
            bytes.map_or("more than 2^64 bytes".to_string(), |b| format!(
                "{:.1} GiB",
                b as f64 / (1u64 << 30) as f64
            )),
            MEMORY_BUDGET >> 30
        ))),
    }
}

/// Bytes one stored photon takes through a render: the photon, its world position,
/// its packed word, permutation entry and the kd-tree build's working copy.
const PHOTON_BYTES: u64 = 128;

/// The largest photon capacity within [`MEMORY_BUDGET`]: the limit of the backends
/// that search in the host's memory (float, sw).
pub const MEMORY_CAPACITY: usize = (MEMORY_BUDGET / PHOTON_BYTES) as usize;

/// Refuse a photon capacity whose map would not fit [`MEMORY_BUDGET`] (a render
/// stores up to `--capacity` photons).
pub fn check_photon_memory(capacity: usize) -> Result<()> {
    let bytes = (capacity as u64).saturating_mul(PHOTON_BYTES);
    if bytes <= MEMORY_BUDGET {
        Ok(())
    } else {
        Err(Error::new(format!(
            "--capacity {capacity} photons could need about {:.1} GiB; the limit is {} GiB",
            bytes as f64 / (1u64 << 30) as f64,
            MEMORY_BUDGET >> 30
        )))
    }
}

/// A float option that must be finite and positive (e.g. `--exposure`).
pub fn check_positive(flag: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::new(format!(
            "{flag} must be a finite number > 0, got {v}"
        )))
    }
}

/// A float option that must be finite and not negative (e.g. `--radius`).
pub fn check_non_negative(flag: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::new(format!(
            "{flag} must be a finite number >= 0, got {v}"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_memory_budget_counts_queries_times_k() {
        // The direct render: 256 x 256 x 4 queries, k = 32.
        assert!(check_gather_memory(262_144, 32, 1 << 20, "--size, --spp").is_ok());
        // k beyond the photon count costs nothing more.
        assert!(check_gather_memory(1000, usize::MAX, 500, "q").is_ok());
        let e = check_gather_memory(1 << 34, 32, 1 << 20, "--size 16384x16384, --spp 64")
            .unwrap_err()
            .to_string();
        assert!(e.contains("--spp 64") && e.contains("GiB"), "{e}");
        assert!(check_gather_memory(u64::MAX, usize::MAX, u64::MAX, "x").is_err());
    }

    #[test]
    fn photon_capacity_within_the_budget() {
        assert!(check_photon_memory((1 << 20) - 1).is_ok());
        let e = check_photon_memory(1 << 40).unwrap_err().to_string();
        assert!(e.contains("--capacity"), "{e}");
    }

    #[test]
    fn positive_floats() {
        assert!(check_positive("--exposure", 1.5).is_ok());
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = check_positive("--exposure", v).unwrap_err().to_string();
            assert!(e.contains("--exposure"), "{e}");
        }
    }
}
