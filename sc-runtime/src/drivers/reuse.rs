//! Repeated extractions into the same buffers.

use crate::drivers::borrowed::sweep_into;
#[cfg(feature = "std")]
use crate::drivers::spare::SPARES;
use crate::drivers::survey::Survey;
use crate::drivers::{InMemory, has_cubes};
use crate::kernel::{Binary, Engine};
use crate::mesh::{OwnedScratch, Presized};
use crate::{Error, Mesh, Mode, Params, Scalar, Stats, Volume};

/// Extracts on one thread into buffers it keeps from one call to the next: for an iso slider, a
/// time series, or any loop that meshes volumes of one size again and again.
///
/// [`extract`] allocates a fresh mesh on every call, and the mesh is then first touched page by
/// page. An `Extractor` keeps the mesh's vectors and its scratch, so once they are large enough
/// an extraction allocates nothing. The mesh is the one [`extract`] gives.
///
/// ```
/// use sc_runtime::{Extractor, Params, Volume, demo, extract};
///
/// let knot = demo::knot(48);
/// let volume = Volume::new(&knot.data, knot.dims).unwrap();
/// let mut extractor = Extractor::new();
/// for iso in [0.7, 0.8, 0.9] {
///     let mesh = extractor.extract(&volume, &Params::new(iso)).unwrap();
///     assert_eq!(*mesh, extract(&volume, &Params::new(iso)).unwrap());
/// }
/// ```
#[derive(Default)]
pub struct Extractor {
    mesh: Mesh,
    scratch: OwnedScratch,
}

impl Extractor {
    /// An extractor with no buffers yet: the first extraction allocates them.
    pub fn new() -> Self {
        Self::default()
    }

    /// Extracts the surface, replacing the previous call's mesh. After an error the kept mesh
    /// is unspecified until the next successful call.
    pub fn extract<T: Scalar>(
        &mut self,
        volume: &Volume<'_, T>,
        params: &Params,
    ) -> Result<&Mesh, Error> {
        if params.mode == Mode::Adaptive {
            self.mesh = super::adaptive::extract(volume, params, &super::adaptive::InOrder)?;
            return Ok(&self.mesh);
        }
        super::not_adaptive(params, "")?;
        self.sweep(&Binary::new(params), volume, params)
    }

    /// [`Extractor::extract`] with any engine.
    pub(crate) fn sweep<T: Scalar>(
        &mut self,
        engine: &impl Engine<T>,
        volume: &Volume<'_, T>,
        params: &Params,
    ) -> Result<&Mesh, Error> {
        let dims = volume.dims();
        self.scratch.fit(dims)?;
        let mesh = &mut self.mesh;
        mesh.positions.clear();
        mesh.normals.clear();
        mesh.values.clear();
        mesh.triangles.clear();
        mesh.stats = Stats::default();
        if has_cubes(dims) {
            let survey = Survey::new(&InMemory::new(volume), dims, engine);
            mesh.reserve_for(survey.between(0, dims[2]), params);
        }
        mesh.stats = sweep_into(
            engine,
            volume,
            params,
            self.scratch.lend(),
            &mut Presized::new(mesh),
        )?;
        Ok(&self.mesh)
    }

    /// The last extraction's mesh, kept: the buffers go with it.
    pub fn into_mesh(self) -> Mesh {
        self.mesh
    }
}

/// Extracts the surface on one thread. To extract again and again, an [`Extractor`] keeps the
/// mesh's buffers between calls; with the `std` feature, this keeps the scratch (see
/// [`extract_par`](crate::extract_par)).
///
/// ```
/// use sc_runtime::{Params, Volume, demo, extract};
///
/// let knot = demo::knot(64);
/// let params = Params { spacing: knot.spacing, origin: knot.origin, ..Params::new(knot.iso) };
/// let mesh = extract(&Volume::new(&knot.data, knot.dims).unwrap(), &params).unwrap();
/// assert_eq!(mesh.stats.t13, 13_968); // the paper's Table 1, Steps 1–3
/// ```
pub fn extract<T: Scalar>(volume: &Volume<'_, T>, params: &Params) -> Result<Mesh, Error> {
    if params.mode == Mode::Adaptive {
        return super::adaptive::extract(volume, params, &super::adaptive::InOrder);
    }
    super::not_adaptive(params, "")?;
    sweep(&Binary::new(params), volume, params)
}

/// [`extract`] with any engine.
pub(crate) fn sweep<T: Scalar>(
    engine: &impl Engine<T>,
    volume: &Volume<'_, T>,
    params: &Params,
) -> Result<Mesh, Error> {
    let mut extractor = Extractor::new();
    #[cfg(feature = "std")]
    {
        extractor.scratch = SPARES.take(volume.dims())?;
    }
    let done = extractor.sweep(engine, volume, params).map(drop);
    #[cfg(feature = "std")]
    SPARES.give(core::mem::take(&mut extractor.scratch));
    done.map(|()| extractor.into_mesh())
}

#[cfg(test)]
mod tests {
    use super::Extractor;
    use crate::{Mode, Params, Volume, demo, extract};

    /// Meshes of every mode, with and without normals, in turn, on two volumes of different
    /// sizes: each equals `extract`'s; and extracting the same volume again reuses the buffers
    /// (same addresses, nothing reallocated).
    #[test]
    fn every_mesh_equals_extract_and_a_repeat_reuses_the_buffers() {
        let (knot, sphere) = (demo::knot(40), demo::sphere_noise(24));
        let mut extractor = Extractor::new();
        for v in [&knot, &sphere, &knot] {
            let volume = Volume::new(&v.data, v.dims).unwrap();
            for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
                for normals in [false, true] {
                    let params = Params {
                        mode,
                        normals,
                        ..Params::new(v.iso)
                    };
                    let want = extract(&volume, &params).unwrap();
                    let first = extractor.extract(&volume, &params).unwrap();
                    assert_eq!(*first, want, "{mode:?}, normals {normals}");
                    let at = (first.positions.as_ptr(), first.triangles.as_ptr());
                    let again = extractor.extract(&volume, &params).unwrap();
                    assert_eq!(*again, want);
                    assert_eq!((again.positions.as_ptr(), again.triangles.as_ptr()), at);
                }
            }
        }
        assert!(!extractor.into_mesh().triangles.is_empty());
    }
}
