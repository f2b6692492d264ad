//! The seam between the kernel and the drivers.
//!
//! A driver (one thread, threads, blocks, a stream of slices, a reused extractor) decides which
//! layers of which samples are swept, where the output goes and how pieces join; an engine
//! decides what a layer's samples mean. The drivers are written against [`Engine`] and
//! [`Layers`] only, so a second traversal (the label sweep, adaptive boxes) reuses them by
//! implementing these two traits, if it keeps the contract stated on [`Layers`].

use crate::{Error, Params, Scalar, Scratch, Sink, Stats};

/// Gives a sweep the slices it asks for; `z` is always within what the step needs.
pub(crate) trait Slices<T> {
    fn slice(&self, z: usize) -> &[T];
    /// Slice `z` if it is in memory already, so that it can be fetched into the cache before it
    /// is needed; empty past the grid and for a source that reads slices as the sweep goes.
    fn ahead(&self, _z: usize) -> &[T] {
        &[]
    }
}

/// What samples mean to a traversal, and the sweeps that traverse them.
pub(crate) trait Engine<T: Scalar>: Sync {
    /// A traversal of one z range of a grid, over scratch lent for `'s`.
    type Sweep<'s>: Layers<T>;

    /// A sweep over a grid of `dims`, from layer 0 to the last unless restricted.
    fn sweep<'s>(&self, dims: [usize; 3], params: &Params, scratch: Scratch<'s>)
    -> Self::Sweep<'s>;

    /// One byte per sample of `row`, equal for samples on the same side of every surface: the
    /// survey counts where neighbouring bytes differ to estimate the output and to cut a volume
    /// into chunks of equal work.
    #[cfg(feature = "alloc")]
    fn classify_row(&self, row: &[T], out: &mut [u8]);
}

/// A sweep, layer by layer. The drivers rely on three properties:
/// - layer `k` reads slices `k − 1 ..= k + 2` (those that exist) and nothing else, so a block
///   with a halo of two slices sees all a layer needs;
/// - vertices are numbered in an order fixed by the grid alone, so a sweep started at layer `z0`
///   numbers them as a sweep from layer 0 does, less a constant ([`Layers::ids_used`]);
/// - every triangle is emitted by exactly one cube, through [`Sink::cube_triangle`], so pieces of
///   a grid join without duplicates.
pub(crate) trait Layers<T> {
    /// Makes this a block's sweep: its samples start at `offset` in the whole grid, and it emits
    /// the triangles of the local cubes `own` only.
    #[cfg(feature = "alloc")]
    fn restrict(&mut self, offset: [usize; 3], own: [(usize, usize); 3]);

    /// Prepares layer `z0` and numbers the vertices of plane `z0`; with `emit_plane` false (a
    /// parallel chunk after the first) they are numbered but belong to the previous chunk.
    fn start(
        &mut self,
        z0: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
        emit_plane: bool,
    ) -> Result<(), Error>;

    /// Runs layer `k`.
    fn layer(&mut self, k: usize, src: &impl Slices<T>, sink: &mut impl Sink) -> Result<(), Error>;

    /// The counts so far.
    fn stats(&self) -> Stats;

    /// Vertex ids handed out, including those of a first plane not emitted.
    #[cfg(feature = "std")]
    fn ids_used(&self) -> u32;
}

/// Skeleton Climbing on a scalar grid: samples at or above the iso value are filled.
pub(crate) struct Binary<T: Scalar> {
    pub(super) threshold: T::Threshold,
}

impl<T: Scalar> Binary<T> {
    pub fn new(params: &Params) -> Self {
        Binary {
            threshold: T::threshold(params.iso),
        }
    }
}
