//! The drivers: how a sweep is run over a volume, and where its output goes.
//!
//! Each driver is written against the kernel's [`Engine`](crate::kernel::Engine) seam, not
//! against one sweep, and the public entry points pick Skeleton Climbing's binary engine:
//! - [`borrowed`]: one sweep into a caller's sink and scratch, no allocation (`extract_into`);
//! - [`reuse`]: one thread into an owned mesh, buffers kept between calls (`Extractor`, `extract`);
//! - [`threads`]: z chunks on threads, stitched into the one-thread mesh (`extract_par`);
//! - [`blocks`]: a block of the grid with its halo, merged exactly with the others
//!   (`extract_block`, `BlockMesh`);
//! - [`stream`]: slices pushed one at a time through a ring of four (`SliceStreamer`).

use crate::kernel::Slices;
use crate::{Error, Mode, Params, Scalar, Volume};

pub(crate) mod borrowed;
pub(crate) mod stream;

#[cfg(feature = "alloc")]
pub(crate) mod adaptive;
#[cfg(feature = "alloc")]
pub(crate) mod blocks;
#[cfg(feature = "alloc")]
pub(crate) mod labels;
#[cfg(feature = "alloc")]
pub(crate) mod reuse;
#[cfg(feature = "alloc")]
pub(crate) mod survey;

#[cfg(feature = "std")]
pub(crate) mod spare;
#[cfg(feature = "std")]
pub(crate) mod threads;

/// An in-memory volume seen slice by slice.
pub(crate) struct InMemory<'a, T> {
    pub data: &'a [T],
    pub nxy: usize,
}

impl<'a, T: Scalar> InMemory<'a, T> {
    pub fn new(volume: &Volume<'a, T>) -> Self {
        let [nx, ny, _] = volume.dims();
        InMemory {
            data: volume.data(),
            nxy: nx * ny,
        }
    }
}

impl<T> Slices<T> for InMemory<'_, T> {
    #[inline]
    fn slice(&self, z: usize) -> &[T] {
        &self.data[z * self.nxy..(z + 1) * self.nxy]
    }

    #[inline]
    fn ahead(&self, z: usize) -> &[T] {
        self.data
            .get(z * self.nxy..(z + 1) * self.nxy)
            .unwrap_or(&[])
    }
}

/// Refuses adaptive mode, with `entry`'s reason, in an entry point that does not run it, and
/// adaptive mode's option in every other mode.
pub(crate) fn not_adaptive(params: &Params, entry: &'static str) -> Result<(), Error> {
    if params.mode == Mode::Adaptive {
        return Err(Error::NotAdaptive { what: entry });
    }
    if params.max_box.is_some() {
        return Err(Error::NotAdaptive {
            what: "max_box needs adaptive mode",
        });
    }
    if params.allow_wrong_side {
        return Err(Error::NotAdaptive {
            what: "allow_wrong_side needs adaptive mode",
        });
    }
    Ok(())
}

/// Whether the grid has any cube: dims below 2 on an axis give an empty mesh.
pub(crate) fn has_cubes(dims: [usize; 3]) -> bool {
    dims.iter().all(|&d| d >= 2)
}

/// Renumbers `triangles` onto the vertices they use, of `count`, keeping those vertices' order;
/// returns each kept vertex's old index, for the per-vertex columns to follow.
#[cfg(feature = "alloc")]
pub(crate) fn keep_used(count: usize, triangles: &mut [[u32; 3]]) -> alloc::vec::Vec<usize> {
    let mut new_id = alloc::vec![u32::MAX; count];
    for t in triangles.iter() {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut kept = alloc::vec::Vec::new();
    for (v, id) in new_id.iter_mut().enumerate() {
        if *id == 0 {
            *id = kept.len() as u32;
            kept.push(v);
        }
    }
    for t in triangles {
        *t = t.map(|v| new_id[v as usize]);
    }
    kept
}
