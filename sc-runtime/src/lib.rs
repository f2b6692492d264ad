//! Skeleton Climbing isosurface extraction.
//!
//! The core (the layer sweep) is `no_std` and allocation-free: it walks a grid layer by layer with
//! O(nx·ny) caller-provided scratch and hands vertices and triangles to a [`Sink`]. With the
//! `alloc` feature, [`extract`] builds an indexed [`Mesh`] and [`SliceStreamer`] meshes a volume
//! fed one z-slice at a time; with `std` (default), [`extract_par`] splits the z range over threads
//! and produces a byte-identical mesh for any thread count.
#![no_std]
#![warn(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

extern crate self as sc_runtime;

mod error;
pub mod geometry;
mod params;
mod scalar;
pub mod tables;

pub use error::Error;
pub use params::{Axes, ErrorBound, ErrorUnits, Mode, Params, UnknownName, Volume};
pub use scalar::Scalar;
mod stats;
pub use stats::{Figure, Stats};

#[cfg(feature = "alloc")]
mod mesh;
#[cfg(feature = "alloc")]
pub use mesh::Mesh;
#[cfg(feature = "alloc")]
mod extractor;
#[cfg(feature = "alloc")]
pub use extractor::{Extractor, extract};
#[cfg(feature = "alloc")]
mod block;
#[cfg(feature = "alloc")]
mod survey;
#[cfg(feature = "alloc")]
pub use block::{BlockMesh, block_samples, edge_key, extract_block};

mod extract;
mod prefetch;
mod stream;
pub use extract::extract_into;
pub use stream::SliceStreamer;

#[cfg(feature = "std")]
pub mod demo;
#[cfg(feature = "std")]
mod parallel;
#[cfg(feature = "std")]
pub use parallel::extract_par;
#[cfg(feature = "std")]
mod claims;
#[cfg(feature = "std")]
mod region;
#[cfg(feature = "std")]
mod spare;

mod scratch;
mod sink;
mod sweep;
mod vertex;
pub use scratch::{Scratch, ScratchLen};
pub use sink::Sink;
