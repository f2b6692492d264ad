//! The kernel: Skeleton Climbing's Steps 1–4 over a grid, layer by layer (SPEC §1–5).
//!
//! `no_std` and allocation-free: a sweep works in O(nx·ny) scratch the caller lends
//! ([`Scratch`](crate::Scratch)) and hands vertices and triangles to a [`Sink`](crate::Sink).
//! What it needs of the drivers, and what they may rely on, is in [`engine`].

// Allocation-free itself, but only the allocating driver runs it (`drivers/adaptive`).
#[cfg(feature = "alloc")]
pub(crate) mod adaptive;
pub(crate) mod engine;
pub(crate) mod error;
pub mod geometry;
pub mod labels;
pub(crate) mod params;
pub(crate) mod prefetch;
pub(crate) mod scalar;
pub(crate) mod scratch;
pub(crate) mod sink;
pub(crate) mod stats;
pub(crate) mod sweep;
pub mod tables;
pub(crate) mod vertex;

pub(crate) use engine::{Binary, Engine, Layers, Slices};
