//! Geometric embedding (SPEC §4): a triangulation is valid only if its triangles never cross,
//! wherever the data puts the vertices along their edges.
//!
//! Vertices are placed at `t = k / 1024`, the SPEC §1 clamp grid, so coordinates are exact in `f64`
//! and the predicates in [`crate::intersect`] decide every placement exactly.

use crate::cube::{corner_offset, edge_corners};
use crate::intersect::{Point, is_degenerate, triangles_conflict};
use crate::rng::SplitMix;

/// Random placements tried per triangulation.
pub const RANDOM_PLACEMENTS: usize = 64;
/// Extra placements with every `t` at 1/1024, 1/2 or 1023/1024, where slivers are thinnest.
pub const EXTREME_PLACEMENTS: usize = 32;

/// Checks `triangles` at the seeded placements; the error names the first failure.
pub fn check(triangles: &[[u8; 3]], seed: u64) -> Result<(), String> {
    let mut rng = SplitMix(seed);
    for trial in 0..RANDOM_PLACEMENTS + EXTREME_PLACEMENTS {
        let ks: [u32; 12] = core::array::from_fn(|_| {
            if trial < RANDOM_PLACEMENTS {
                1 + (rng.below(1023) as u32)
            } else {
                [1, 512, 1023][rng.below(3)]
            }
        });
        let place = |t: &[u8; 3]| t.map(|e| vertex(e, ks[usize::from(e)]));
        for (i, a) in triangles.iter().enumerate() {
            let pa = place(a);
            if is_degenerate(&pa) {
                return Err(format!("triangle {a:?} has zero area at t = {ks:?}/1024"));
            }
            for b in &triangles[i + 1..] {
                if triangles_conflict(&pa, &place(b)) {
                    return Err(format!(
                        "triangles {a:?} and {b:?} intersect at t = {ks:?}/1024"
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The point at `k / 1024` along edge `e` from its lower corner.
fn vertex(e: u8, k: u32) -> Point {
    let [a, b] = edge_corners(e).map(corner_offset);
    let t = f64::from(k) / 1024.0;
    [0, 1, 2].map(|i| f64::from(a[i]) + t * (f64::from(b[i]) - f64::from(a[i])))
}

/// A seed per table entry, so every run validates the same placements.
pub fn entry_seed(class: u8, case: u8) -> u64 {
    0x5EED_0000 ^ (u64::from(class) << 8 | u64::from(case))
}
