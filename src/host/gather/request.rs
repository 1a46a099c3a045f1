//! `GatherRequest`: one gather as the host runs it. The CLI validates its options
//! once and hands the host this whole request (the parameters, who answers,
//! `--exact` and where the waveform goes), so the host never asks an option
//! object again.

use super::{make_backend, BackendKind, GatherBackend, GatherParams};
use crate::host::error::{Error, Result};
use crate::host::exact::ExactBackend;
use crate::host::map::quantize::Point;
use crate::host::output::{Output, Staged};
use crate::hw::sim::native::SimOptions;
use std::path::{Path, PathBuf};

/// A validated gather.
#[derive(Debug)]
pub struct GatherRequest {
    /// k, radius, grid, metric, traversal, capacity and the core.
    pub params: GatherParams,
    /// Who answers the gathers.
    pub backend: BackendKind,
    /// `--exact`: the float search's answers from k + m grid candidates a query,
    /// with m if given (`--refine`); `None`: the backend's own answers.
    pub exact: Option<Option<usize>>,
    /// Photons a query gathers as the memory sees them: k, or with `--exact` the
    /// most candidates the core may return.
    pub gathered_k: usize,
    /// Where the simulation's waveform goes (`--vcd` or env PHOTON_FPGA_VCD), and
    /// once staged, the temporary file the simulator writes.
    vcd_path: Option<PathBuf>,
    vcd: Option<Staged>,
}

impl GatherRequest {
    /// A request for `backend` with `params`; `vcd` records the simulation's
    /// waveform (refused unless the backend simulates a core).
    pub fn new(
        params: GatherParams,
        backend: BackendKind,
        exact: Option<Option<usize>>,
        gathered_k: usize,
        vcd: Option<PathBuf>,
    ) -> Result<Self> {
        if vcd.is_some() && !backend.simulates() {
            return Err(Error::new("--vcd needs --backend native or verilator"));
        }
        Ok(GatherRequest {
            params,
            backend,
            exact,
            gathered_k,
            vcd_path: vcd,
            vcd: None,
        })
    }

    /// Whether the request records a waveform.
    pub fn records_waveform(&self) -> bool {
        self.vcd_path.is_some()
    }

    /// Check the waveform's path against the run's `inputs` and stage it: the
    /// simulator writes a temporary file that becomes the VCD only when the whole
    /// run succeeds ([`GatherRequest::finish`]).
    pub fn stage_waveform(&mut self, inputs: &[&Path]) -> Result<()> {
        if let Some(p) = &self.vcd_path {
            self.vcd = Some(Output::check(p, inputs)?.stage()?);
        }
        Ok(())
    }

    /// The backend over `photons` with the request's parameters, recording the
    /// staged waveform (`--exact` wraps the quantized search).
    pub fn backend(&self, photons: &[Point]) -> Result<Box<dyn GatherBackend>> {
        let sim = SimOptions {
            vcd: self.vcd.as_ref().map(|v| v.path().to_path_buf()),
            ..SimOptions::default()
        };
        self.make(photons, &self.params, &sim)
    }

    /// Another backend of the same kind over `photons` with `params` (a two-pass
    /// render's caustic and irradiance maps); it records no waveform.
    pub fn other_backend(
        &self,
        photons: &[Point],
        params: &GatherParams,
    ) -> Result<Box<dyn GatherBackend>> {
        self.make(photons, params, &SimOptions::default())
    }

    fn make(
        &self,
        photons: &[Point],
        params: &GatherParams,
        sim: &SimOptions,
    ) -> Result<Box<dyn GatherBackend>> {
        match self.exact {
            Some(refine) => Ok(Box::new(ExactBackend::new(
                self.backend,
                photons,
                params,
                refine,
                sim,
            )?)),
            None => make_backend(self.backend, photons, params, sim),
        }
    }

    /// The run succeeded: the staged waveform becomes the VCD.
    pub fn finish(self) -> Result<()> {
        match self.vcd {
            Some(v) => v.commit(),
            None => Ok(()),
        }
    }
}
