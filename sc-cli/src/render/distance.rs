//! Distance from each triangle of a mesh (its centroid) to a reference mesh, exact per triangle,
//! with the reference's triangles binned in a uniform grid so each query looks nearby first.

use std::collections::HashMap;

use sc_io::mesh_in::TriangleMesh;
use sc_runtime::geometry::point_triangle_distance_squared;

type P = [f64; 3];

/// Per triangle of `mesh`, the distance from its centroid to the nearest point of `reference`.
pub fn per_triangle(mesh: &TriangleMesh, reference: &TriangleMesh) -> Vec<f64> {
    let tris: Vec<[P; 3]> = reference
        .triangles
        .iter()
        .map(|t| t.map(|i| reference.positions[i as usize].map(f64::from)))
        .collect();
    // Cells about two edge lengths wide.
    let edge = tris.iter().map(|t| dist2(t[0], t[1]).sqrt()).sum::<f64>() / tris.len() as f64;
    let cell = (2.0 * edge).max(1e-9);
    let key = |p: P| p.map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (n, t) in tris.iter().enumerate() {
        let (lo, hi) = (0..3).fold(([i64::MAX; 3], [i64::MIN; 3]), |(lo, hi), k| {
            let c = key(t[k]);
            (
                std::array::from_fn(|d| lo[d].min(c[d])),
                std::array::from_fn(|d| hi[d].max(c[d])),
            )
        });
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    grid.entry([x, y, z]).or_default().push(n);
                }
            }
        }
    }
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
            let p: P = std::array::from_fn(|d| (a[d] + b[d] + c[d]) / 3.0);
            let k = key(p);
            let mut best = f64::INFINITY;
            // Shell by shell: once the best distance is within the shell's reach, stop.
            for r in 0i64.. {
                for x in -r..=r {
                    for y in -r..=r {
                        for z in -r..=r {
                            if x.abs().max(y.abs()).max(z.abs()) != r {
                                continue;
                            }
                            for &n in grid
                                .get(&[k[0] + x, k[1] + y, k[2] + z])
                                .into_iter()
                                .flatten()
                            {
                                best = best.min(point_triangle(p, tris[n]));
                            }
                        }
                    }
                }
                if best <= r as f64 * cell || r > 64 {
                    break;
                }
            }
            if best.is_finite() {
                best
            } else {
                tris.iter()
                    .map(|&t| point_triangle(p, t))
                    .fold(f64::INFINITY, f64::min)
            }
        })
        .collect()
}

fn dist2(a: P, b: P) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

fn point_triangle(p: P, t: [P; 3]) -> f64 {
    point_triangle_distance_squared(p, t).sqrt()
}
