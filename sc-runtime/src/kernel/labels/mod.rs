//! Label volumes, cube by cube (docs/labels.md): which construction a cube of labelled corners
//! takes, and the triangles of those that are not a binary table's.
//!
//! A cube reads its eight labels only, through keys that order them (the background first), so
//! both cubes sharing a face split it the same way and every construction here is a pure
//! function of the cube's labelling; the sweep that numbers vertices and merges grey edges is a
//! driver (`drivers::labels`).

mod cube;
mod face;

/// The widest smoothing a label extraction takes, in voxels: wider, a vertex's place would
/// average labels several regions away.
pub const MAX_SMOOTHING: f64 = 4.0;

pub use cube::{Junction, Kind, Local, MAX_TRIANGLES, classify, few_labels, junction};
pub use face::{FACES, corner_edge, edge_corners};
