//! `photon-fpga gather`: the k nearest photons of every query of a CSV photon map.

use crate::cli::gather_opts::GatherOpts;
use crate::cli::set_threads;
use crate::host::csvio;
use crate::host::error::{Error, Result};
use crate::host::limits::{self};
use crate::host::output::Output;
use crate::hw::config::core_spec::DEFAULT_K;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct GatherArgs {
    /// The photon map: `x,y,z` per line (optional header, extra columns ignored).
    /// (`--photons`, its earlier name, is still accepted; render's --photons is a
    /// count.)
    #[arg(long = "map", value_name = "P.csv", alias = "photons")]
    pub photons: PathBuf,
    /// Query positions, same format.
    #[arg(long)]
    pub queries: PathBuf,
    #[command(flatten)]
    pub opts: GatherOpts,
    /// Output CSV: `query,rank,photon,distance`, nearest first.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn gather(args: &GatherArgs) -> Result<()> {
    set_threads(args.opts.threads)?;
    let mut request = args.opts.request(DEFAULT_K)?;
    // The core file is an input too: no output may replace it.
    let mut inputs = vec![args.photons.as_path(), args.queries.as_path()];
    inputs.extend(args.opts.core_file.file.as_deref());
    let out = Output::check(&args.out, &inputs)?;
    request.stage_waveform(&inputs)?;
    let photons = csvio::read_points(&args.photons)?;
    let queries = csvio::read_points(&args.queries)?;
    if photons.points.is_empty() {
        return Err(Error::new(format!(
            "{}: the photon set is empty",
            args.photons.display()
        )));
    }
    limits::check_gather_memory(
        queries.points.len() as u64,
        request.gathered_k,
        photons.points.len() as u64,
        &format!("the lines of {}", args.queries.display()),
    )?;
    // The grid covers the photons alone: a query never changes another's answer.
    let backend = request.backend(&photons.points)?;
    for (q, line) in queries.points.iter().zip(&queries.lines) {
        backend
            .check_query(*q)
            .map_err(|e| Error::new(format!("{}:{line}: {e}", args.queries.display())))?;
    }
    let results = backend.gather(&queries.points)?;
    csvio::write_neighbours(&out, &results)?;
    if request.exact.is_some() {
        if let Some(info) = backend.describe() {
            println!("{info}");
        }
    }
    request.finish()
}
