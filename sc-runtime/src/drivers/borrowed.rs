use super::{InMemory, has_cubes};
use crate::kernel::{Binary, Engine, Layers};
use crate::{Error, Params, Scalar, Scratch, Sink, Stats, Volume};

/// Extracts the surface without allocating: the caller lends [`Scratch`] and receives the mesh
/// through `sink`. This is the whole algorithm; the other entry points wrap it.
///
/// ```
/// use sc_runtime::{Params, Scratch, Sink, Volume, extract_into};
///
/// struct Count(usize, usize);
/// impl Sink for Count {
///     fn vertex(&mut self, _: [f32; 3], _: Option<[f32; 3]>) { self.0 += 1 }
///     fn triangle(&mut self, _: [u32; 3]) { self.1 += 1 }
/// }
/// // One filled sample in a 3×3×3 grid: an octahedron around it, flattened by Step 4.
/// let mut data = [0u8; 27];
/// data[13] = 1;
/// let len = Scratch::len([3, 3, 3]).unwrap();
/// let (mut bytes, mut words) = ([0u8; 256], [0u32; 128]);
/// assert!(len.bytes <= 256 && len.words <= 128);
/// let scratch = Scratch::new(&mut bytes, &mut words, [3, 3, 3]).unwrap();
/// let mut sink = Count(0, 0);
/// let stats = extract_into(&Volume::new(&data, [3, 3, 3]).unwrap(), &Params::new(1.0), scratch, &mut sink).unwrap();
/// assert_eq!((stats.t13, sink.1 as u64), (8, stats.triangles));
/// ```
pub fn extract_into<T: Scalar>(
    volume: &Volume<'_, T>,
    params: &Params,
    scratch: Scratch<'_>,
    sink: &mut impl Sink,
) -> Result<Stats, Error> {
    super::not_adaptive(
        params,
        "extract_into does not run adaptive mode: its boxes read the whole Steps 1–3 mesh (use extract)",
    )?;
    sweep_into(&Binary::new(params), volume, params, scratch, sink)
}

/// [`extract_into`] with any engine.
pub(crate) fn sweep_into<T: Scalar>(
    engine: &impl Engine<T>,
    volume: &Volume<'_, T>,
    params: &Params,
    scratch: Scratch<'_>,
    sink: &mut impl Sink,
) -> Result<Stats, Error> {
    sweep_at(engine, volume, [0; 3], params, scratch, sink)
}

/// [`sweep_into`] on samples lying at global index `at` of a larger grid: every cube is meshed,
/// but the sink is told global indices and positions, and Step 4's parity classes follow them.
pub(crate) fn sweep_at<T: Scalar>(
    engine: &impl Engine<T>,
    volume: &Volume<'_, T>,
    at: [usize; 3],
    params: &Params,
    scratch: Scratch<'_>,
    sink: &mut impl Sink,
) -> Result<Stats, Error> {
    let dims = volume.dims();
    if !has_cubes(dims) {
        return Ok(Stats::default());
    }
    let src = InMemory::new(volume);
    let mut sweep = engine.sweep(dims, params, scratch);
    // Blocks (which allocate) are the only samples not at the grid's origin.
    #[cfg(feature = "alloc")]
    if at != [0; 3] {
        sweep.restrict(at, dims.map(|n| (0, n - 1)));
    }
    #[cfg(not(feature = "alloc"))]
    let _ = at;
    sweep.start(0, &src, sink, true)?;
    for k in 0..dims[2] - 1 {
        sweep.layer(k, &src, sink)?;
    }
    Ok(sweep.stats())
}
