//! A quick look at where the surface is before the sweep: sign changes counted on all three axes
//! along every eighth row of every eighth slice (closer slices in a thin volume cut into chunks,
//! see [`slice_step`]), interpolated between the sampled slices. Its reads are scattered over a
//! volume that is mostly not in the caches, so it samples sparsely; every eighth row of every
//! eighth slice is as sparse as it can be while the estimate stays within the mesh's reserve
//! (the test below checks the built-in volumes; `docs/speed-log.md` has the denser and sparser
//! samplings measured).
//!
//! It sizes the mesh's buffers once: buffers grown layer by layer would be copied into fresh
//! memory several times, and first touching a page is costly. The parallel extraction also cuts
//! its chunks by it, so that each has about equal work.

use alloc::vec::Vec;

use crate::Scalar;
use crate::kernel::prefetch;
use crate::kernel::{Engine, Slices};

/// Slices between the sampled ones, at most.
const SLICE_STEP: usize = 8;
/// Rows between the sampled ones.
const ROW_STEP: usize = 8;

/// Slices between the sampled ones, for a volume of `nz` slices to be cut into `chunks` runs of
/// about equal estimated work: every eighth, or closer where that would leave a chunk fewer
/// than two sampled slices: a thin volume sampled every eighth slice can miss its densest
/// layers, and its chunks then take unequal times.
pub(crate) fn slice_step(nz: usize, chunks: usize) -> usize {
    (nz / (2 * chunks)).clamp(1, SLICE_STEP)
}

/// Estimated Steps 1–3 vertices (sign changes on grid edges) per slice, from the samples.
pub(crate) struct Survey {
    /// Slices between the sampled ones.
    step: usize,
    /// Per sampled slice `step · i`, the sign changes of its sampled rows' edges on all three
    /// axes (x along the row, y to the next row, z to the next slice).
    sampled: Vec<usize>,
}

impl Survey {
    /// Surveys every sampled slice on this thread.
    pub fn new<T: Scalar>(src: &impl Slices<T>, dims: [usize; 3], engine: &impl Engine<T>) -> Self {
        let mut signs = Vec::new();
        let step = slice_step(dims[2], 1);
        Survey {
            step,
            sampled: (0..dims[2])
                .step_by(step)
                .map(|z| sampled_slice(src, dims, engine, z, &mut signs))
                .collect(),
        }
    }

    /// A survey from the counts of [`sampled_slice`] for `z = 0, step, 2 · step, …`.
    #[cfg(feature = "std")]
    pub fn from_sampled(step: usize, sampled: Vec<usize>) -> Self {
        Survey { step, sampled }
    }

    /// Estimated vertices whose edges start in slice `z`: interpolated between the sampled
    /// slices around it, scaled by the rows that were skipped. Interpolated rather than held
    /// constant up to the next sample, so that chunks cut by it have equal work.
    pub fn at(&self, z: usize) -> usize {
        let (i, f) = (z / self.step, z % self.step);
        let lo = self.sampled[i];
        let hi = self.sampled.get(i + 1).copied().unwrap_or(lo);
        ROW_STEP * (lo * (self.step - f) + hi * f) / self.step
    }

    /// Estimated vertices of layers `z0..z1`.
    pub fn between(&self, z0: usize, z1: usize) -> usize {
        (z0..z1).map(|z| self.at(z)).sum()
    }
}

/// The sign changes of slice `z`'s sampled rows' edges, on all three axes; `signs` is reused
/// scratch.
pub(crate) fn sampled_slice<T: Scalar>(
    src: &impl Slices<T>,
    [nx, ny, nz]: [usize; 3],
    engine: &impl Engine<T>,
    z: usize,
    signs: &mut Vec<u8>,
) -> usize {
    // Three rows of signs: (y, z), (y + 1, z) and (y, z + 1). Classified first, so that the
    // counting loops vectorise.
    signs.resize(3 * nx, 0);
    let (row, rest) = signs.split_at_mut(nx);
    let (next, up) = rest.split_at_mut(nx);
    let here = src.slice(z);
    let above = (z + 1 < nz).then(|| src.slice(z + 1));
    // Signs are 0 or 1: their xor summed is the count of changes, in a loop that vectorises.
    let differ =
        |a: &[u8], b: &[u8]| a.iter().zip(b).map(|(a, b)| u32::from(a ^ b)).sum::<u32>() as usize;
    let mut n = 0;
    for y in (0..ny).step_by(ROW_STEP) {
        // The rows two steps on, asked for now: each row is a short run of lines of its own,
        // and read only when needed, each would wait on memory.
        let ahead = y + 2 * ROW_STEP;
        if let Some(rows) = here.get(ahead * nx..) {
            prefetch::all(&rows[..rows.len().min(2 * nx)]);
        }
        if let Some(rows) = above.and_then(|above| above.get(ahead * nx..)) {
            prefetch::all(&rows[..rows.len().min(nx)]);
        }
        engine.classify_row(&here[y * nx..][..nx], row);
        n += differ(&row[1..], &row[..nx - 1]);
        if y + 1 < ny {
            engine.classify_row(&here[(y + 1) * nx..][..nx], next);
            n += differ(row, next);
        }
        if let Some(above) = above {
            engine.classify_row(&above[y * nx..][..nx], up);
            n += differ(row, up);
        }
    }
    n
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use super::Survey;
    use crate::drivers::InMemory;
    use crate::kernel::Binary;
    use crate::{Params, Volume, demo, extract};

    /// The survey's estimate of Steps 1–3's vertices, against their count, on the built-in
    /// volumes: within what the mesh's reserve (half as much again) covers with room to spare.
    #[test]
    fn the_estimate_is_close_to_the_vertex_count() {
        for (name, v) in [
            ("knot", demo::knot(128)),
            ("sphere", demo::sphere(128)),
            ("torus", demo::torus(128)),
            ("noise", demo::sphere_noise(128)),
        ] {
            let src = InMemory {
                data: &v.data,
                nxy: v.dims[0] * v.dims[1],
            };
            let survey = Survey::new(&src, v.dims, &Binary::<f64>::new(&Params::new(v.iso)));
            let estimate = survey.between(0, v.dims[2]) as f64;
            let mesh =
                extract(&Volume::new(&v.data, v.dims).unwrap(), &Params::new(v.iso)).unwrap();
            let ratio = estimate / mesh.stats.v13 as f64;
            assert!(
                (0.85..=1.15).contains(&ratio),
                "{name}: estimate / count {ratio:.3}"
            );
        }
    }
}
