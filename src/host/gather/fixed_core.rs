//! [`FixedCore`]: a core given whole by a core description file (`--core FILE`),
//! and the checks that a gather and its map fit it.

use crate::host::error::{Error, Result};
use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::TreeImage;
use crate::hw::config::traversal::Traversal;
use std::path::{Path, PathBuf};

/// A fixed core read from a core description file
/// ([`core_file`](crate::hw::config::core_file)): one core, one Verilator model, for every
/// map that fits it.
#[derive(Clone, Debug, PartialEq)]
pub struct FixedCore {
    pub config: CoreConfig,
    /// The file it was read from, named in every refusal.
    pub file: PathBuf,
}

impl FixedCore {
    /// The core described by the file at `path`.
    pub fn read(path: &Path) -> Result<Self> {
        Ok(FixedCore {
            config: crate::hw::config::core_file::read(path)?,
            file: path.to_path_buf(),
        })
    }

    /// Most photons the core holds: 2^H − 1.
    pub fn max_photons(&self) -> usize {
        self.config.tree_words() - 1
    }

    /// "the 1023 photons the core of FILE holds (address_bits = 10)".
    pub fn photon_limit(&self) -> String {
        format!(
            "the {} photons the core of {} holds (address_bits = {})",
            self.max_photons(),
            self.file.display(),
            self.config.address_bits
        )
    }

    /// This core, if `tree` fits it (layout and photon count), else why not.
    pub fn check_map(&self, tree: TreeImage<'_>) -> Result<CoreConfig> {
        self.config
            .check_map(tree)
            .map_err(|e| Error::new(format!("{}: {e}", self.file.display())))?;
        Ok(self.config)
    }

    /// Why a gather of `k` in `metric` with `traversal` cannot run on this core.
    pub fn check_gather(&self, k: usize, metric: Metric, traversal: Traversal) -> Result<()> {
        let c = &self.config;
        let f = self.file.display();
        if k > c.k {
            return Err(Error::new(format!(
                "--k {k} exceeds the found list of the core of {f} (k = {}: at most {} \
                 photons per query)",
                c.k, c.k
            )));
        }
        if metric != c.metric {
            return Err(Error::new(format!(
                "the gather's metric {metric} differs from the core of {f} (metric = {})",
                c.metric
            )));
        }
        if traversal != c.traversal {
            return Err(Error::new(format!(
                "the gather's traversal {traversal} differs from the core of {f} \
                 (traversal = {})",
                c.traversal
            )));
        }
        Ok(())
    }
}
