use crate::{Error, Mesh, Params, Scalar, Volume};

/// Extracts the surface on `threads` threads (0 = all cores). The mesh is byte-identical to
/// [`crate::extract`]'s. `progress` is called with the number of z layers just finished.
pub fn extract_par<T: Scalar>(
    volume: &Volume<'_, T>,
    params: &Params,
    threads: usize,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Mesh, Error> {
    let _ = (volume, params, threads, progress);
    todo!("runtime in progress")
}
