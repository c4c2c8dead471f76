//! The scans `benches/dump_insert_case.py` writes (the simulated URG-04LX
//! scans the 50 µs insert is judged on), for the examples that time
//! the insert (`insert_case`, `spell_probe`), and the median they report.

use std::error::Error;

use ndt_core::Pose2;

/// Scans in the map before the timed inserts (as `speed.py`).
pub const PREFILL: usize = 100;

/// The median of `v` (the upper one of an even count; NaN when empty),
/// sorting `v`.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// One scan: scan-frame points and the pose they were seen from.
pub type Scan = (Vec<[f64; 2]>, Pose2);

/// The scans of `bytes`: per scan its point count (i64), the points' x and y
/// and the pose's x, y and θ (f64), all little-endian.
pub fn scans(bytes: &[u8]) -> Result<Vec<Scan>, Box<dyn Error>> {
    let mut words = bytes
        .chunks_exact(8)
        .map(|w| <[u8; 8]>::try_from(w).unwrap_or([0; 8]));
    let mut out = Vec::new();
    while let Some(count) = words.next() {
        let n = usize::try_from(i64::from_le_bytes(count))?;
        let mut values = words.by_ref().take(2 * n + 3).map(f64::from_le_bytes);
        let points: Vec<[f64; 2]> = (0..n)
            .map_while(|_| Some([values.next()?, values.next()?]))
            .collect();
        match (values.next(), values.next(), values.next()) {
            (Some(x), Some(y), Some(theta)) if points.len() == n => {
                out.push((points, Pose2::new(x, y, theta)));
            }
            _ => return Err("the file ends inside a scan".into()),
        }
    }
    Ok(out)
}
