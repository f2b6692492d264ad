//! Volumes read a few z-slices at a time, for meshing volumes larger than memory: raw files
//! (with `--dims` or a JSON sidecar) and NIfTI-1 (`.nii`, and `.nii.gz` decompressed as it is
//! read). The header is parsed by the format's own reader, so placement and value maps are the
//! same as a whole read's.

use std::io::{self, Read};
use std::path::{Path, PathBuf};

use super::payload::{self, Encoding, Layout};
use super::{Block, Format, ReadOptions, block_error, nifti, open_block, raw, sidecar};
use crate::error::{Error, Result};
use crate::progress::Silent;
use crate::volume::{Grid, Sample, Samples};

/// A volume whose samples are read slab by slab. `grid` has the placement, the type and the
/// value map; its `samples` stay empty.
pub struct Stream {
    /// Everything about the volume but its samples.
    pub grid: Grid,
    path: PathBuf,
    reader: Box<dyn Read>,
    encoding: Encoding,
    layout: Layout,
    /// z-slices read so far; the data file (a sidecar's) for error messages is `path`.
    read: usize,
}

/// Opens `path` for reading slab by slab, or `Ok(None)` if its format cannot stream (only whole
/// reads: NRRD, MetaImage, NumPy, DICOM, and NIfTI with a negative `scl_slope`, whose samples
/// are converted to floating point as a whole).
pub fn open(path: &Path, options: &ReadOptions) -> Result<Option<Stream>> {
    if !path.exists() {
        return Err(Error::file(path, "no such file or directory"));
    }
    let format = Format::detect(path, options)?;
    let side;
    let (mut grid, block) = match format {
        Format::Raw(layout) => (
            Grid::new(Samples::empty(layout.dtype), layout.dims, ""),
            raw::block(path, &layout)?,
        ),
        Format::Sidecar => {
            let json = sidecar::find(path)
                .ok_or_else(|| Error::file(path, "no JSON sidecar beside it"))?;
            side = sidecar::Sidecar::read(&json)?;
            let mut grid = Grid::new(Samples::empty(side.layout.dtype), side.layout.dims, "");
            grid.spacing = side.spacing.unwrap_or(grid.spacing);
            grid.origin = side.origin.unwrap_or(grid.origin);
            (grid, raw::block(&side.data, &side.layout)?)
        }
        Format::Nifti => {
            let (mut grid, block, rescale) = nifti::open(path)?;
            match rescale {
                Some((slope, _)) if slope < 0.0 => return Ok(None),
                Some((slope, inter)) => grid.rescale(slope, inter),
                None => {}
            }
            (grid, block)
        }
        _ => return Ok(None),
    };
    grid.format = format.name();
    super::check_placement(path, &grid)?;
    Ok(Some(Stream {
        reader: open_block(&block)?,
        path: block.path.to_path_buf(),
        encoding: block.encoding,
        layout: block.layout,
        grid,
        read: 0,
    }))
}

impl Stream {
    /// The next `slices` z-slices (fewer at the end), x fastest.
    pub fn read<T: Sample>(&mut self, slices: usize) -> Result<Vec<T>> {
        let [nx, ny, nz] = self.grid.dims;
        let slices = slices.min(nz - self.read);
        let layout = Layout {
            count: nx * ny * slices,
            ..self.layout
        };
        let samples = payload::read_typed::<T>(&mut self.reader, layout, false, &Silent)
            .map_err(|e| self.error(e))?;
        self.read += slices;
        if self.read == nz && self.encoding != Encoding::Raw {
            // As a whole read does: read on to make the decoder check the gzip CRC.
            io::copy(
                &mut (&mut self.reader).take(super::MAX_TRAILING),
                &mut io::sink(),
            )
            .map_err(|e| self.error(e))?;
        }
        Ok(samples)
    }

    fn error(&self, e: io::Error) -> Error {
        let block = Block {
            path: &self.path,
            start: super::Start::At(0),
            skip_lines: 0,
            encoding: self.encoding,
            skip_decoded: 0,
            layout: self.layout,
        };
        block_error(&block, e)
    }
}
