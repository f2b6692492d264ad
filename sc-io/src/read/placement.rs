//! The checks every format's placement passes, whether read whole or streamed.

use std::path::Path;

use crate::error::{Error, Result};
use crate::volume::Grid;

/// Refuses what would mesh into garbage: an empty volume, and spacing or origin that are not
/// finite, not positive, or beyond what `f32` vertices can hold (NaN or infinite vertices make
/// invalid glTF; zero spacing collapses the mesh to a plane).
pub(crate) fn check_placement(path: &Path, grid: &Grid) -> Result<()> {
    let [nx, ny, nz] = grid.dims;
    if grid.dims.contains(&0) {
        return Err(Error::file(
            path,
            format!("the volume has no samples: its dims are {nx} × {ny} × {nz}"),
        ));
    }
    let usable = crate::limits::coordinate;
    if !grid.spacing.iter().all(|&s| usable(s) && s > 0.0) {
        return Err(Error::file(
            path,
            format!(
                "the file's sample spacing {:?} is unusable: every spacing must be a positive \
                 finite number (NIfTI pixdim or sform, NRRD spacings or space directions, \
                 MetaImage ElementSpacing, DICOM PixelSpacing or slice positions)",
                grid.spacing
            ),
        ));
    }
    if !grid.origin.iter().all(|&o| usable(o)) {
        return Err(Error::file(
            path,
            format!(
                "the file's origin {:?} is unusable: it must be finite (NIfTI sform or qform \
                 offset, NRRD space origin, MetaImage Offset, DICOM ImagePositionPatient)",
                grid.origin
            ),
        ));
    }
    Ok(())
}
