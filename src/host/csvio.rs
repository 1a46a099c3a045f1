//! CSV photon maps and query lists for `photon-fpga gather`, and its output.
//!
//! Input: `x,y,z` per line; an optional header on line 1; extra columns ignored;
//! blank lines skipped; LF, CRLF or CR-only line endings. Every error names the file,
//! the line (as an editor counts it) and the offending text.

use crate::host::error::{Error, Result};
use crate::host::gather::Gathered;
use crate::host::map::quantize::Point;
use crate::host::output::Output;
use std::path::Path;

/// Largest coordinate magnitude accepted: the squared L2 distance of two points
/// (3 × (2 × 1e150)² ≈ 1.2e301) stays finite in f64, so no backend can meet an
/// infinite or NaN distance.
pub const MAX_COORD: f64 = 1e150;

/// Points read from a CSV file, with the file line of each (for later errors).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointsFile {
    pub points: Vec<Point>,
    /// 1-based file line of `points[i]`.
    pub lines: Vec<usize>,
}

/// The file's bytes with CRLF and lone CR line endings turned into LF, so that the
/// csv reader's line numbers are the file's (it counts neither a lone CR nor, once
/// blank lines are skipped, CRLF as an editor does).
fn unix_line_endings(bytes: Vec<u8>) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'\r' {
            out.push(b'\n');
            if bytes.get(i + 1) == Some(&b'\n') {
                i += 1;
            }
        } else {
            out.push(bytes[i]);
        }
        i += 1;
    }
    out
}

/// Read `x,y,z` points from a CSV file.
pub fn read_points(path: &Path) -> Result<PointsFile> {
    let name = path.display();
    let bytes = std::fs::read(path).map_err(|e| {
        let what = if path.is_dir() {
            "cannot read (a directory)"
        } else {
            "cannot open"
        };
        Error::new(format!("{name}: {what}: {e}"))
    })?;
    let bytes = unix_line_endings(bytes);
    // The csv reader's own line count skips blank lines, and a record's byte offset
    // starts at the blank lines before it: skip those, then count line starts.
    let line_starts: Vec<u64> = std::iter::once(0)
        .chain(
            bytes
                .iter()
                .enumerate()
                .filter(|(_, &b)| b == b'\n')
                .map(|(i, _)| i as u64 + 1),
        )
        .collect();
    let line_of = |pos: Option<&csv::Position>| {
        pos.map_or(0, |p| {
            let mut b = p.byte() as usize;
            while bytes.get(b) == Some(&b'\n') {
                b += 1;
            }
            line_starts.partition_point(|&s| s <= b as u64)
        })
    };
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(&bytes[..]);
    let mut points = Vec::new();
    let mut lines = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let more = rdr.read_record(&mut record).map_err(|e| {
            let line = line_of(e.position());
            Error::new(format!("{name}:{line}: cannot read: {e}"))
        })?;
        if !more {
            break;
        }
        let line = line_of(record.position());
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
        if p.iter().any(|v| v.abs() > MAX_COORD) {
            return Err(Error::new(format!(
                "{name}:{line}: coordinates must lie within ±{MAX_COORD:e} (squared distances \
                 must stay finite), got '{text}'"
            )));
        }
        points.push(p);
        lines.push(line);
    }
    Ok(PointsFile { points, lines })
}

/// Write `query,rank,photon,distance` lines, nearest first (see [`Output`]: a failed
/// run never leaves a half-written file).
pub fn write_neighbours(out: &Output, results: &[Gathered]) -> Result<()> {
    out.write(|w| {
        let mut csv = csv::Writer::from_writer(w);
        csv.write_record(["query", "rank", "photon", "distance"])?;
        for (q, g) in results.iter().enumerate() {
            for (rank, n) in g.neighbours.iter().enumerate() {
                // Display formatting of the distance (shortest exact form).
                csv.write_record([
                    q.to_string(),
                    rank.to_string(),
                    n.photon.to_string(),
                    n.distance.to_string(),
                ])?;
            }
        }
        csv.flush()?;
        Ok(())
    })
}
