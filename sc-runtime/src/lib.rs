//! Skeleton Climbing isosurface extraction.
//!
//! The crate has two layers, one folder each:
//! - the **kernel** (`kernel/`): `no_std` and allocation-free, it sweeps a grid layer by layer
//!   with O(nx·ny) caller-provided [`Scratch`] and hands vertices and triangles to a [`Sink`];
//! - the **drivers** (`drivers/`): they run a sweep over a volume in memory ([`extract_into`],
//!   [`extract`], [`Extractor`]), on threads ([`extract_par`], a mesh byte-identical to one
//!   thread's for any thread count), block by block ([`extract_block`], [`BlockMesh`]) or slice by
//!   slice ([`SliceStreamer`]).
//!
//! [`extract`] and [`Extractor`] need the `alloc` feature, [`extract_par`] `std` (the default).
#![no_std]
#![warn(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

extern crate self as sc_runtime;

mod drivers;
mod kernel;

pub use kernel::error::Error;
pub use kernel::params::{Axes, ErrorBound, ErrorUnits, Mode, Params, UnknownName, Volume};
pub use kernel::scalar::Scalar;
pub use kernel::scratch::{Scratch, ScratchLen};
pub use kernel::sink::Sink;
pub use kernel::stats::{Figure, Stats};
pub use kernel::{geometry, tables};

pub use drivers::borrowed::extract_into;
pub use drivers::stream::SliceStreamer;

#[cfg(feature = "alloc")]
mod mesh;
#[cfg(feature = "alloc")]
pub use drivers::blocks::{BlockMesh, block_samples, edge_key, extract_block};
#[cfg(feature = "alloc")]
pub use drivers::reuse::{Extractor, extract};
#[cfg(feature = "alloc")]
pub use mesh::Mesh;

/// Label volumes: every region of a segmentation meshed in one sweep (docs/labels.md). The
/// cube constructions are `no_std`; [`labels::extract_labels`] needs `alloc`.
pub mod labels {
    #[cfg(feature = "alloc")]
    pub use crate::drivers::labels::{
        Atlas, AtlasBlock, AtlasView, Label, LabelParams, block_samples, extract_block,
        extract_labels,
    };
    pub use crate::kernel::labels::*;
}

#[cfg(feature = "std")]
pub mod demo;
#[cfg(feature = "std")]
pub use drivers::threads::extract_par;
