//! Meshes a scan the way a program of your own would: read the volume with sc-io, extract the
//! surface `f = iso`, write the mesh atomically (the file appears whole or not at all), and
//! print the number of triangles.
//!
//! ```sh
//! cargo run --release -p sc-io --example mesh_scan -- tests/data/itk-t1-mri.nii.gz brain.ply 100
//! ```
//!
//! The input is any volume sc-io reads (NIfTI, NRRD, MetaImage, NumPy, a DICOM directory, Zarr,
//! raw samples with a JSON sidecar); the mesh format follows the output's extension (`.ply`,
//! `.obj`, `.stl`, `.glb`). Without an iso value, the surface is taken midway between the
//! smallest and largest sample: a start, not a choice (`skelclimb info` suggests better ones).

use std::path::Path;
use std::process::ExitCode;

use sc_io::atomic::AtomicFile;
use sc_io::progress::Silent;
use sc_io::read::{self, ReadOptions};
use sc_io::surface::{self, Request};
use sc_io::write::{MeshFormat, WriteOptions};

const USAGE: &str = "usage: mesh_scan INPUT OUTPUT [ISO]
  INPUT   a volume: .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, .npy, .npz, a DICOM or Zarr folder
  OUTPUT  the mesh: .ply, .obj, .stl or .glb
  ISO     the surface value, in the volume's units (default: midway through its values)";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (input, output, iso) = match args.as_slice() {
        [flag] if flag == "-h" || flag == "--help" => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        [input, output] => (input, output, None),
        [input, output, iso] => match iso.parse::<f64>() {
            Ok(iso) if iso.is_finite() => (input, output, Some(iso)),
            _ => return usage(&format!("ISO must be a number, not {iso:?}")),
        },
        _ => return usage("give an input volume and an output mesh"),
    };
    match mesh_scan(Path::new(input), Path::new(output), iso) {
        Ok(triangles) => {
            println!("{output}: {triangles} triangles");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("mesh_scan: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn usage(problem: &str) -> ExitCode {
    eprintln!("mesh_scan: {problem}\n{USAGE}");
    ExitCode::from(2)
}

/// Reads `input`, meshes it at `iso` and writes the mesh to `output`; the triangle count.
fn mesh_scan(input: &Path, output: &Path, iso: Option<f64>) -> sc_io::Result<usize> {
    // Both checked before the read, which can be long: an output name without a mesh format,
    // and an output that cannot be created.
    let format = MeshFormat::from_path(output).map_err(sc_io::Error::Usage)?;
    let file = AtomicFile::create(output)?;
    let grid = read::read(input, &ReadOptions::default(), &Silent)?;
    let iso = match iso {
        Some(iso) => iso,
        None => {
            let range = grid.range();
            if range.finite == 0 {
                return Err(sc_io::Error::file(
                    input,
                    "no finite sample to take an iso value from",
                ));
            }
            (range.min + range.max) / 2.0
        }
    };
    let request = Request::new(iso);
    let mesh = surface::extract(&grid, &request, &Silent)?;
    // Records the coordinate system (RAS, LPS) in the formats that have room for it.
    let options = WriteOptions {
        space: surface::world(&grid, &request).space,
        ..WriteOptions::default()
    };
    file.write_with(|out| format.write(&mesh, &options, out))?;
    Ok(mesh.triangles.len())
}
