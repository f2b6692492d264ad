use crate::kernel::sweep::Sweep;
use crate::kernel::{Binary, Engine, Layers, Slices};
use crate::{Error, Params, Scalar, Scratch, Sink, Stats};

/// Meshes a volume fed one z-slice at a time, holding only four slices: a volume larger than
/// memory can be meshed while it is read. The mesh is the same as [`crate::extract_into`]'s.
///
/// ```
/// use sc_runtime::{Mesh, Params, Scratch, SliceStreamer};
///
/// let dims = [8, 8, 8];
/// let len = Scratch::len(dims).unwrap();
/// let (mut bytes, mut words) = (vec![0u8; len.bytes], vec![0u32; len.words]);
/// let mut ring = vec![0f32; SliceStreamer::<f32, Mesh>::ring_len(dims)];
/// let scratch = Scratch::new(&mut bytes, &mut words, dims).unwrap();
/// let mut s = SliceStreamer::new(dims, &Params::new(0.5), scratch, &mut ring, Mesh::default()).unwrap();
/// for z in 0..8 {
///     let slice: Vec<f32> = (0..64).map(|i| if (2..6).contains(&z) && i == 27 { 1.0 } else { 0.0 }).collect();
///     s.push(&slice).unwrap();
/// }
/// let (mesh, stats) = s.finish().unwrap();
/// assert_eq!(mesh.triangles.len() as u64, stats.triangles);
/// ```
pub struct SliceStreamer<'s, T: Scalar, S: Sink> {
    dims: [usize; 3],
    sweep: Sweep<'s, T>,
    ring: Ring<'s, T>,
    received: usize,
    sink: S,
}

struct Ring<'s, T> {
    buf: &'s mut [T],
    nxy: usize,
}

impl<T> Slices<T> for Ring<'_, T> {
    fn slice(&self, z: usize) -> &[T] {
        &self.buf[(z % 4) * self.nxy..][..self.nxy]
    }
}

impl<'s, T: Scalar, S: Sink> SliceStreamer<'s, T, S> {
    /// Samples of the four-slice ring buffer the streamer needs.
    pub fn ring_len(dims: [usize; 3]) -> usize {
        4 * dims[0] * dims[1]
    }

    /// A streamer over `dims`, with lent scratch and a ring of at least [`Self::ring_len`] samples.
    pub fn new(
        dims: [usize; 3],
        params: &Params,
        scratch: Scratch<'s>,
        ring: &'s mut [T],
        sink: S,
    ) -> Result<Self, Error> {
        super::not_adaptive(
            params,
            "SliceStreamer does not run adaptive mode: the balancing of its boxes reads up to 4 × max_box + 2 slices past a slab, where the stream holds four (use extract or extract_block)",
        )?;
        Scratch::len(dims)?;
        if ring.len() < Self::ring_len(dims) {
            return Err(Error::ScratchTooSmall);
        }
        let nxy = dims[0] * dims[1];
        Ok(SliceStreamer {
            dims,
            sweep: Binary::new(params).sweep(dims, params, scratch),
            ring: Ring { buf: ring, nxy },
            received: 0,
            sink,
        })
    }

    /// Takes the next z-slice (`nx · ny` samples, x fastest) and finishes every layer it completes.
    pub fn push(&mut self, slice: &[T]) -> Result<(), Error> {
        let nxy = self.ring.nxy;
        if self.received >= self.dims[2] {
            return Err(Error::TooManySlices { nz: self.dims[2] });
        }
        if slice.len() != nxy {
            return Err(Error::SliceLength {
                expected: nxy,
                actual: slice.len(),
            });
        }
        let z = self.received;
        self.ring.buf[(z % 4) * nxy..][..nxy].copy_from_slice(slice);
        self.received += 1;
        if !crate::drivers::has_cubes(self.dims) {
            return Ok(());
        }
        match z {
            0 => {}
            1 => self.sweep.start(0, &self.ring, &mut self.sink, true)?,
            _ => self.sweep.layer(z - 2, &self.ring, &mut self.sink)?,
        }
        Ok(())
    }

    /// Finishes the last layer after all `nz` slices arrived; returns the sink and the counts.
    pub fn finish(mut self) -> Result<(S, Stats), Error> {
        if self.received != self.dims[2] {
            return Err(Error::DataLength {
                expected: self.dims[2] * self.ring.nxy,
                actual: self.received * self.ring.nxy,
            });
        }
        if crate::drivers::has_cubes(self.dims) {
            self.sweep
                .layer(self.dims[2] - 2, &self.ring, &mut self.sink)?;
        }
        Ok((self.sink, self.sweep.stats()))
    }
}
