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
//!
//! The public modules, a front end's whole view of the crate:
//!
//! - [`read`]: a volume file in, as a [`volume::Grid`] ([`read::stream`] for slab-by-slab
//!   reading); [`volume`]: the grid and its typed samples; [`space`]: where it sits in the
//!   scanner's world.
//! - [`surface`]: the extraction of a grid (whole, streamed, or as [`shard`]s).
//! - [`write`](mod@write): a mesh out, in the format its file name asks for, through an
//!   [`atomic`] file, whole or not at all; [`mesh_in`]: a mesh read back, for comparisons.
//! - [`report`]: the counts of an extraction as JSON; [`distance`]: how far apart two meshes
//!   are; [`separation`]: which samples a mesh leaves on the wrong side; [`progress`]: how
//!   long-running work tells how far it got.
//!
//! The formats' parsers and writers behind these are private: a format is chosen by its file
//! name, never named by a caller.

pub mod atomic;
mod buffer;
pub mod distance;
mod error;
mod input;
pub mod labels;
pub mod limits;
pub mod mesh_in;
pub mod progress;
pub mod read;
pub mod report;
pub mod separation;
pub mod shard;
mod slabs;
pub mod space;
#[cfg(feature = "surface")]
pub mod surface;
pub mod volume;
pub mod write;

pub use error::{Error, Result};
pub(crate) use volume::with_dtype;
