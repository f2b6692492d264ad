//! Volume files in, mesh files out: the readers, writers and sample types that the `skelclimb`
//! command and the Python package share, so that both read a scan the same way and write the
//! same bytes.
//!
//! ```no_run
//! # #[cfg(feature = "surface")] {
//! use sc_io::{atomic::AtomicFile, progress::Silent, read, surface};
//! use sc_io::write::{MeshFormat, WriteOptions};
//!
//! let grid = read::read("scan.nii.gz".as_ref(), &read::ReadOptions::default(), &Silent)?;
//! let request = surface::Request::new(300.0);
//! let mesh = surface::extract(&grid, &request, &Silent)?;
//! AtomicFile::create("bone.ply".as_ref())?
//!     .write_with(|out| MeshFormat::Ply.write(&mesh, &WriteOptions::default(), out))?;
//! # }
//! # Ok::<(), sc_io::Error>(())
//! ```
//!
//! The `surface` module needs the `surface` feature (on by default). It compiles the sweep for
//! every sample type, most of this crate's build time, so a front end that calls `sc-runtime`
//! itself (the Python package) or only reads (the fuzzer) turns default features off.
//! The `zarr` feature (on by default) reads Zarr arrays and OME-Zarr images through `zarrs` and
//! the C libraries of its codecs; without it a Zarr store is refused with a message that says
//! so, and the build is shorter (the fuzzer has no Zarr target and leaves it off).

pub mod atomic;
pub mod buffer;
pub mod error;
pub mod mesh_in;
pub mod progress;
pub mod read;
pub mod report;
pub mod shard;
pub mod space;
#[cfg(feature = "surface")]
pub mod surface;
pub mod volume;
pub mod write;

pub use error::{Error, Result};
