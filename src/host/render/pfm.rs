//! Linear radiance as a Portable Float Map (`render --out NAME.pfm`): what an
//! error measurement against another renderer's reference needs, where the PNG has
//! been exposed, clamped and gamma-encoded to 8 bits.
//!
//! The format: the header `PF\n<width> <height>\n-1.0\n` (colour; the negative
//! scale means little-endian), then f32 RGB triples, rows from the bottom of the
//! image up.

use crate::host::error::Result;
use crate::host::output::Output;
use glam::Vec3;

/// Whether `path` names a PFM file (by its extension, any case).
pub fn is_pfm(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pfm"))
}

/// The PFM bytes of a `width` × `height` image of linear radiance, row by row from
/// the top (`EyePass::linear`).
pub fn encode_pfm(width: u32, height: u32, linear: &[Vec3]) -> Vec<u8> {
    assert_eq!(
        linear.len(),
        (width * height) as usize,
        "one value per pixel"
    );
    let mut out = format!("PF\n{width} {height}\n-1.0\n").into_bytes();
    for row in (0..height as usize).rev() {
        for c in &linear[row * width as usize..(row + 1) * width as usize] {
            for v in c.to_array() {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    out
}

/// Write [`encode_pfm`]'s bytes to `out` (atomically for a file; see [`Output`]).
pub fn save_pfm(width: u32, height: u32, linear: &[Vec3], out: &Output) -> Result<()> {
    let bytes = encode_pfm(width, height, linear);
    out.write(|w| w.write_all(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pfm_is_bottom_up_little_endian_rgb() {
        let img = [
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(4.0, 5.0, 6.0),
            Vec3::new(7.0, 8.0, 9.0),
            Vec3::new(10.0, 11.0, 12.0),
        ];
        let bytes = encode_pfm(2, 2, &img);
        let header = b"PF\n2 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        // The bottom row (7..12) first.
        assert_eq!(
            floats,
            [7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        );
        assert!(is_pfm(std::path::Path::new("a/B.PFM")));
        assert!(!is_pfm(std::path::Path::new("a.png")));
    }
}
