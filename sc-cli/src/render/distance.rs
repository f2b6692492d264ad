//! Distance from each triangle of a mesh (its centroid) to a reference mesh, exact per triangle.

use sc_io::distance::Nearest;
use sc_io::mesh_in::TriangleMesh;

/// Per triangle of `mesh`, the distance from its centroid to the nearest point of `reference`.
pub fn per_triangle(mesh: &TriangleMesh, reference: &TriangleMesh) -> Vec<f64> {
    let nearest = Nearest::new(&reference.positions, &reference.triangles, [1.0; 3]);
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
            nearest.distance(std::array::from_fn(|d| (a[d] + b[d] + c[d]) / 3.0))
        })
        .collect()
}
