//! Volumes read a few z-slices at a time, for meshing volumes larger than memory: raw files
//! (with `--dims` or a JSON sidecar), NIfTI-1 (`.nii`, and `.nii.gz` decompressed as it is
//! read) and Zarr arrays (a row of chunks at a time). The header is parsed by the format's own reader, so placement and value maps are the
//! same as a whole read's.

use std::io::{self, Read};
use std::path::{Path, PathBuf};

use super::block::{Block, MAX_TRAILING, Start, block_error, open_block};
use super::format::{Format, ReadOptions};
use super::payload::{self, Encoding, Layout};
use super::placement::check_placement;
use super::{nifti, raw, sidecar, zarr};
use crate::error::{Error, Result};
use crate::progress::{Progress, Silent};
use crate::volume::{Grid, Sample, Samples};

/// A volume whose samples are read slab by slab. `grid` has the placement, the type and the
/// value map; its `samples` stay empty.
pub struct Stream {
    /// Everything about the volume but its samples.
    pub grid: Grid,
    /// The file (a sidecar's data file) or store the samples come from, for error messages.
    path: PathBuf,
    source: Source,
    /// z-slices read so far.
    read: usize,
}

enum Source {
    /// A sample block in a file, decoded as it is read.
    Block {
        reader: Box<dyn Read>,
        encoding: Encoding,
        layout: Layout,
    },
    /// A Zarr array, read by rows of chunks.
    Zarr(Box<zarr::Source>),
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
        Format::Zarr => {
            let (grid, source) = zarr::open(path, options.zarr_level)?;
            check_placement(path, &grid)?;
            let stream = Stream {
                grid,
                path: path.to_path_buf(),
                source: Source::Zarr(Box::new(source)),
                read: 0,
            };
            stream.check_slabs()?;
            return Ok(Some(stream));
        }
        _ => return Ok(None),
    };
    grid.format = format.name();
    check_placement(path, &grid)?;
    Ok(Some(Stream {
        source: Source::Block {
            reader: open_block(&block)?,
            encoding: block.encoding,
            layout: block.layout,
        },
        path: block.path.to_path_buf(),
        grid,
        read: 0,
    }))
}

/// Bytes of samples per slab read from a file: large enough for fast reads, small beside any
/// volume that needs streaming.
const SLAB_BYTES: usize = 16 << 20;

impl Stream {
    /// Refuses a volume whose samples would not fit in this process's memory (see
    /// [`crate::limits`]), naming the file and the size: before a whole read, which would abort
    /// on the allocation. A stream that holds a few slabs at a time may still mesh it.
    pub fn check_whole(&self) -> Result<()> {
        let [nx, ny, nz] = self.grid.dims;
        let what = format!("its {nx} × {ny} × {nz} samples");
        crate::limits::grid(
            [nx, ny, nz].map(|d| d as u64),
            self.grid.samples.dtype().size(),
            &what,
        )
        .map(drop)
        .map_err(|e| Error::file(&self.path, e))
    }

    /// Refuses a stream whose slabs would not fit in memory: a header's slice size is checked
    /// before any slab is allocated. A slab is held twice while it is decoded and copied, beside
    /// the meshing's ring of a few slices.
    fn check_slabs(&self) -> Result<()> {
        let [nx, ny, _] = self.grid.dims;
        let slices = self.slab().saturating_mul(2).saturating_add(4);
        let what = format!(
            "streaming it in slabs of {} slices of {nx} × {ny} samples ({slices} slices held at once)",
            self.slab()
        );
        crate::limits::grid(
            [nx as u64, ny as u64, slices as u64],
            self.grid.samples.dtype().size(),
            &what,
        )
        .map(drop)
        .map_err(|e| Error::file(&self.path, e))
    }

    /// z-slices per read that suit the source: a row of chunks for Zarr, about 16 MiB for files.
    pub(crate) fn slab(&self) -> usize {
        match &self.source {
            Source::Zarr(z) => z.chunk_z().max(1),
            Source::Block { layout, .. } => {
                let [nx, ny, _] = self.grid.dims;
                (SLAB_BYTES / (nx * ny * layout.dtype.size()).max(1)).max(1)
            }
        }
    }

    /// The next `slices` z-slices (fewer at the end), x fastest.
    pub(crate) fn read<T: Sample>(&mut self, slices: usize) -> Result<Vec<T>> {
        let [nx, ny, nz] = self.grid.dims;
        let slices = slices.min(nz - self.read);
        let (z0, z1) = (self.read, self.read + slices);
        let samples = match &mut self.source {
            Source::Zarr(z) => {
                let samples = z.read::<T>(&self.path, z0, z1)?;
                if z1 == nz {
                    self.grid.warnings.extend(z.missing_chunks()?);
                }
                samples
            }
            Source::Block {
                reader,
                encoding,
                layout,
            } => {
                let slab = Layout {
                    count: nx * ny * slices,
                    ..*layout
                };
                let error =
                    |e: io::Error| block_error(&block_at(&self.path, *encoding, *layout), e);
                let samples =
                    payload::read_typed::<T>(&mut *reader, slab, false, &Silent).map_err(error)?;
                if z1 == nz && *encoding != Encoding::Raw {
                    // As a whole read does: read on to make the decoder check the gzip CRC.
                    io::copy(&mut reader.take(MAX_TRAILING), &mut io::sink()).map_err(error)?;
                }
                samples
            }
        };
        self.read = z1;
        Ok(samples)
    }

    /// Every sample, for a whole read.
    pub(crate) fn read_all(mut self, progress: &dyn Progress) -> Result<Grid> {
        self.check_whole()?;
        let dtype = self.grid.samples.dtype();
        progress.phase("reading", self.grid.dims[2] as u64);
        let samples = crate::with_dtype!(dtype, T => {
            let mut all: Vec<T> = Vec::new();
            all.try_reserve_exact(self.grid.dims.iter().product())
                .map_err(|e| Error::file(&self.path, format!("its samples: {e}")))?;
            while self.read < self.grid.dims[2] {
                let slab = self.slab();
                let before = self.read;
                all.extend(self.read::<T>(slab)?);
                progress.inc((self.read - before) as u64);
            }
            T::wrap(all.into())
        });
        self.grid.samples = samples;
        Ok(self.grid)
    }
}

/// A block description for error messages about a streamed block.
fn block_at(path: &Path, encoding: Encoding, layout: Layout) -> Block<'_> {
    Block {
        path,
        start: Start::At(0),
        skip_lines: 0,
        encoding,
        skip_decoded: 0,
        layout,
    }
}
