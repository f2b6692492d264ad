//! NIfTI-1 single files (`.nii`, `.nii.gz`). The `nifti` crate parses and validates the header;
//! the samples go through [`read_block`] so that they land in their typed vector with one copy
//! (the crate's volume types would hold a byte buffer and convert it again).

use std::io::BufReader;
use std::path::Path;

use nifti::{Endianness, NiftiHeader, NiftiType};

use super::block::{Block, Start, read_block};
use super::payload::{Encoding, Layout};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::space::{Frame, Space};
use crate::volume::{Dtype, Endian, Grid, Samples};

/// Reads a NIfTI-1 volume. The placement comes from the sform when its code is set, else from
/// the qform, as the NIfTI standard orders them (spacing from pixdim with the qform);
/// scl_slope/scl_inter map stored values to real ones.
pub fn read(path: &Path, progress: &dyn Progress) -> Result<Grid> {
    let (mut grid, block, rescale) = open(path)?;
    grid.samples = read_block(&block, progress)?;
    if let Some((slope, inter)) = rescale {
        grid.rescale(slope, inter);
    }
    Ok(grid)
}

/// The header: the grid without its samples, the sample block, and the value map to apply once
/// the samples are read (`scl_slope`, `scl_inter`), if any.
#[allow(clippy::type_complexity)]
pub fn open(path: &Path) -> Result<(Grid, Block<'_>, Option<(f64, f64)>)> {
    let gz = path.to_string_lossy().to_ascii_lowercase().ends_with(".gz");
    let encoding = if gz { Encoding::Gzip } else { Encoding::Raw };
    let file = crate::input::open(path)?;
    let header = NiftiHeader::from_reader(super::payload::decode(BufReader::new(file), encoding))
        .map_err(|e| match e {
        // The crate's own text for I/O errors is debug output; say it in words.
        nifti::NiftiError::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => Error::file(
            path,
            "not a readable NIfTI-1 header: the file ends inside it",
        ),
        nifti::NiftiError::Io(io) => Error::io(path, io),
        other => Error::file(path, format!("not a readable NIfTI-1 header: {other}")),
    })?;
    let bad = |message: String| Error::file(path, format!("NIfTI header: {message}"));
    // The crate takes a wrong sizeof_hdr as a byte-order hint, not as corruption.
    if header.sizeof_hdr != 348 {
        return Err(Error::file(
            path,
            "not a readable NIfTI-1 header: sizeof_hdr is not 348",
        ));
    }
    if &header.magic != b"n+1\0" {
        return Err(bad(
            "this is a header of an .hdr/.img pair; only single .nii files are read".into(),
        ));
    }
    let dims = dims(&header).map_err(bad)?;
    let dtype = dtype(&header).map_err(bad)?;
    if !(header.vox_offset >= 348.0 && header.vox_offset.fract() == 0.0) {
        return Err(bad(format!("vox_offset {} is invalid", header.vox_offset)));
    }
    let vox_offset = header.vox_offset as u64;
    let layout = Layout {
        dtype,
        endian: match header.endianness {
            Endianness::Big => Endian::Big,
            Endianness::Little => Endian::Little,
        },
        count: dims.iter().product(),
    };
    let (start, skip_decoded) = if gz {
        (Start::At(0), vox_offset)
    } else {
        (Start::At(vox_offset), 0)
    };
    let block = Block {
        path,
        start,
        skip_lines: 0,
        encoding,
        skip_decoded,
        layout,
    };
    let mut grid = Grid::new(Samples::empty(dtype), dims, "NIfTI-1");

    // Spacing that is not a positive finite number is refused after reading (`check_placement`),
    // naming pixdim, rather than replaced by a guess.
    grid.spacing = [1, 2, 3].map(|i| f64::from(header.pixdim[i]).abs());
    let slope = f64::from(header.scl_slope);
    let rescale = (slope != 0.0 && slope.is_finite()).then(|| (slope, f64::from(header.scl_inter)));
    if header.sform_code > 0 {
        let rows = [header.srow_x, header.srow_y, header.srow_z].map(|r| r.map(f64::from));
        let columns = [0, 1, 2].map(|a| [rows[0][a], rows[1][a], rows[2][a]]);
        let (frame, spacing) = Frame::from_columns(columns, Space::Ras).ok_or_else(|| {
            bad(format!(
                "sform (code {}) is not a valid placement: its rows are {:?}",
                header.sform_code, rows
            ))
        })?;
        grid.frame = Some(frame);
        grid.spacing = spacing;
        grid.origin = [rows[0][3], rows[1][3], rows[2][3]];
        grid.notes.push(format!(
            "placed by the sform (code {}): RAS world coordinates",
            header.sform_code
        ));
    } else if header.qform_code > 0 {
        let qfac = if header.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let [b, c, d] = [header.quatern_b, header.quatern_c, header.quatern_d].map(f64::from);
        let frame = Frame::from_quaternion(b, c, d, qfac).ok_or_else(|| {
            bad(format!(
                "qform quaternion b, c, d = {b}, {c}, {d} is not a rotation"
            ))
        })?;
        grid.frame = Some(frame);
        grid.origin = [header.quatern_x, header.quatern_y, header.quatern_z].map(f64::from);
        grid.notes.push(format!(
            "placed by the qform (code {}, qfac {qfac}): RAS world coordinates",
            header.qform_code
        ));
    }
    Ok((grid, block, rescale))
}

/// The first three dimensions; any further ones (time, components) must be 1.
fn dims(header: &NiftiHeader) -> Result<[usize; 3], String> {
    let dim = header.dim().map_err(|e| format!("bad dimensions: {e}"))?;
    if dim.iter().skip(3).any(|&d| d != 1) {
        return Err(format!(
            "dimensions {dim:?}: only single 3-D volumes can be meshed"
        ));
    }
    let at = |i: usize| dim.get(i).map_or(1, |&d| usize::from(d));
    Ok([at(0), at(1), at(2)])
}

fn dtype(header: &NiftiHeader) -> Result<Dtype, String> {
    let t = header
        .data_type()
        .map_err(|_| format!("unknown datatype code {}", header.datatype))?;
    let (kind, bytes) = match t {
        NiftiType::Uint8 => ('u', 1),
        NiftiType::Int8 => ('i', 1),
        NiftiType::Uint16 => ('u', 2),
        NiftiType::Int16 => ('i', 2),
        NiftiType::Uint32 => ('u', 4),
        NiftiType::Int32 => ('i', 4),
        NiftiType::Float32 => ('f', 4),
        NiftiType::Float64 => ('f', 8),
        _ => ('?', 0),
    };
    Dtype::from_kind(kind, bytes)
        .ok_or_else(|| format!("datatype {t:?} (code {}) is not supported: scalar 8- to 32-bit integers and floats are", header.datatype))
}
