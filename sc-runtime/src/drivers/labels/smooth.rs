//! Smoothing that keeps the separation (docs/labels.md, "Smoothing"): each vertex slides along
//! its own grid edge to where the Gaussian-smoothed indicators of the edge's two labels cross,
//! and never leaves the edge's inside, so every sample stays on its own side.

use alloc::vec::Vec;

use super::sweep::{Edge, NOT_ON_AN_EDGE, Padded};
use super::{Label, LabelParams};

/// How far inside its edge a vertex stays, as a fraction of the edge: what keeps triangles from
/// thinning to slivers where the smoothed indicators cross near a sample.
const INSIDE: f64 = 1.0 / 32.0;

/// How far, in samples, the Gaussian of width `sigma` reads: three widths either side hold all
/// but 0.3 % of the weight.
pub(super) fn reach(sigma: f64) -> usize {
    libm::ceil(3.0 * sigma) as usize
}

/// Moves the vertices on grid edges (`edges`, per vertex) but those `pinned`. Reads the grid up
/// to [`reach`] samples from each edge's ends.
pub(super) fn place<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    positions: &mut [[f32; 3]],
    edges: &[Edge],
    pinned: &[u32],
) {
    let sigma = params.smoothing;
    let reach = reach(sigma) as isize;
    let weights: Vec<f64> = (-reach..=reach)
        .map(|d| libm::exp(-((d * d) as f64) / (2.0 * sigma * sigma)))
        .collect();
    let mut stays = alloc::vec![false; edges.len()];
    for &v in pinned {
        stays[v as usize] = true;
    }
    let pad = f64::from(u8::from(params.pad));
    for (v, edge) in edges.iter().enumerate() {
        if *edge == NOT_ON_AN_EDGE || stays[v] {
            continue;
        }
        let [x, y, z, axis] = edge.map(|c| c as usize);
        let lower = [x, y, z];
        let mut upper = lower;
        upper[axis] += 1;
        let (a, b) = (grid.at(lower), grid.at(upper));
        // How much more of `a` than of `b` there is around a point, smoothed.
        let balance = |p: [usize; 3]| {
            let mut sum = 0.0;
            for (k, wz) in weights.iter().enumerate() {
                for (j, wy) in weights.iter().enumerate() {
                    for (i, wx) in weights.iter().enumerate() {
                        let d = [i, j, k].map(|o| o as isize - reach);
                        let q: [usize; 3] =
                            core::array::from_fn(|c| p[c].wrapping_add_signed(d[c]));
                        let l = if q.iter().zip(&grid.n).all(|(&c, &n)| c < n) {
                            grid.at(q)
                        } else {
                            grid.background
                        };
                        let w = wx * wy * wz;
                        if l == a {
                            sum += w;
                        } else if l == b {
                            sum -= w;
                        }
                    }
                }
            }
            sum
        };
        let (here, there) = (balance(lower), balance(upper));
        let t = if here > there {
            (here / (here - there)).clamp(INSIDE, 1.0 - INSIDE)
        } else {
            0.5
        };
        let at = lower[axis] as f64 + t;
        positions[v][axis] = (params.origin[axis] + (at - pad) * params.spacing[axis]) as f32;
    }
}
