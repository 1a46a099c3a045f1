//! CSV photon maps and query lists for `photon-fpga gather`, and its output.
//!
//! Input: `x,y,z` per line; an optional header on line 1; extra columns ignored.
//! Every error names the file, the line and the offending text.

use super::error::{Error, Result};
use super::gather::Gathered;
use super::quantize::Point;
use std::io::Write;
use std::path::Path;

/// Read `x,y,z` points from a CSV file.
pub fn read_points(path: &Path) -> Result<Vec<Point>> {
    let name = path.display();
    let file =
        std::fs::File::open(path).map_err(|e| Error::new(format!("{name}: cannot open: {e}")))?;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(std::io::BufReader::new(file));
    let mut points = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let more = rdr.read_record(&mut record).map_err(|e| {
            let line = e.position().map(|p| p.line()).unwrap_or(0);
            Error::new(format!("{name}:{line}: cannot read: {e}"))
        })?;
        if !more {
            break;
        }
        let line = record.position().map(|p| p.line()).unwrap_or(0);
        let text = record.iter().collect::<Vec<_>>().join(",");
        if record.len() == 1 && record[0].is_empty() {
            continue; // a blank line
        }
        let parsed: Vec<Option<f64>> = (0..3)
            .map(|i| record.get(i).and_then(|f| f.parse::<f64>().ok()))
            .collect();
        if parsed.iter().any(|v| v.is_none()) {
            // Line 1 may be a header: no field of it is a number.
            let header = line == 1 && record.iter().all(|f| f.parse::<f64>().is_err());
            if header {
                continue;
            }
            return Err(Error::new(format!(
                "{name}:{line}: expected three numbers x,y,z, got '{text}'"
            )));
        }
        let p = [0, 1, 2].map(|i| parsed[i].unwrap());
        if p.iter().any(|v| !v.is_finite()) {
            return Err(Error::new(format!(
                "{name}:{line}: coordinates must be finite, got '{text}'"
            )));
        }
        points.push(p);
    }
    Ok(points)
}

/// Write `query,rank,photon,distance` lines, nearest first, to `path` atomically:
/// a temporary file in the same directory renamed into place, so a failed run never
/// leaves a half-written output.
pub fn write_neighbours(path: &Path, results: &[Gathered]) -> Result<()> {
    write_atomically(path, |w| {
        writeln!(w, "query,rank,photon,distance")?;
        for (q, g) in results.iter().enumerate() {
            for (rank, n) in g.neighbours.iter().enumerate() {
                writeln!(w, "{q},{rank},{},{}", n.photon, n.distance)?;
            }
        }
        Ok(())
    })
}

/// Create `path` via a temporary sibling and a rename.
pub fn write_atomically(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let err = |e: std::io::Error| Error::new(format!("{}: cannot write: {e}", path.display()));
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::NamedTempFile::new_in(dir).map_err(err)?;
    let mut w = std::io::BufWriter::new(tmp);
    body(&mut w).map_err(err)?;
    let tmp = w.into_inner().map_err(|e| err(e.into_error()))?;
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}
