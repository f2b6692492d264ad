//! The built-in volumes as grids, so that the demo and `table1` need no files.

use sc_runtime::demo::{self, DemoVolume};

use crate::cli::Demo;
use sc_io::volume::{Grid, Samples};

/// The built-in volume `which` at `n` samples per axis, and its iso value.
pub fn grid(which: Demo, n: usize) -> (Grid, f64) {
    let DemoVolume {
        data,
        dims,
        iso,
        spacing,
        origin,
    } = match which {
        Demo::Knot => demo::knot(n),
        Demo::Sphere => demo::sphere(n),
        Demo::Torus => demo::torus(n),
        Demo::SphereNoise => demo::sphere_noise(n),
    };
    let mut grid = Grid::new(Samples::F64(data.into()), dims, "built-in");
    grid.spacing = spacing;
    grid.origin = origin;
    (grid, iso)
}

/// The name the user types and the reports show.
pub fn name(which: Demo) -> &'static str {
    match which {
        Demo::Knot => "knot",
        Demo::Sphere => "sphere",
        Demo::Torus => "torus",
        Demo::SphereNoise => "sphere-noise",
    }
}
