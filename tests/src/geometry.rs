//! Geometric mesh checks: generalised winding number, distance to the mesh, enclosed volume,
//! normal agreement.
//!
//! The winding number is the test of *separation*: a closed, consistently outward-wound surface
//! has winding number 1 at every point of the filled solid and 0 outside, so evaluating it at every
//! grid point checks that the surface separates filled samples from empty ones exactly as SPEC §1
//! classifies them — something no count or topology check can see.

use std::f64::consts::PI;

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: P) -> f64 {
    dot(a, a).sqrt()
}

fn corners(positions: &[[f32; 3]], t: [u32; 3]) -> [P; 3] {
    t.map(|i| positions[i as usize].map(f64::from))
}

/// Solid angle of triangle `abc` seen from `p` (Van Oosterom–Strackee), signed positive when
/// the triangle's normal `(b − a) × (c − a)` points away from `p`.
pub fn solid_angle(p: P, tri: [P; 3]) -> f64 {
    let [a, b, c] = tri.map(|q| sub(q, p));
    let (la, lb, lc) = (norm(a), norm(b), norm(c));
    let num = dot(a, cross(b, c));
    let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    2.0 * num.atan2(den)
}

/// The generalised winding number of the mesh at `p`: Σ solid angles / 4π.
pub fn winding_number(p: P, positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|&t| solid_angle(p, corners(positions, t)))
        .sum::<f64>()
        / (4.0 * PI)
}

/// Distance from `p` to triangle `abc` (closest-point by Voronoi regions, Ericson §5.1.5).
pub fn point_triangle_distance(p: P, [a, b, c]: [P; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let at = |s: f64, u: P, v: f64, w: P| {
        [
            s * u[0] + v * w[0],
            s * u[1] + v * w[1],
            s * u[2] + v * w[2],
        ]
    };
    let closest = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else {
            let vc = d1 * d4 - d3 * d2;
            if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
                let v = d1 / (d1 - d3);
                let o = at(1.0, a, v, ab);
                [o[0], o[1], o[2]]
            } else {
                let cp = sub(p, c);
                let (d5, d6) = (dot(ab, cp), dot(ac, cp));
                if d6 >= 0.0 && d5 <= d6 {
                    c
                } else {
                    let vb = d5 * d2 - d1 * d6;
                    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
                        let w = d2 / (d2 - d6);
                        at(1.0, a, w, ac)
                    } else {
                        let va = d3 * d6 - d5 * d4;
                        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
                            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
                            at(1.0, b, w, sub(c, b))
                        } else {
                            let denom = 1.0 / (va + vb + vc);
                            let (v, w) = (vb * denom, vc * denom);
                            let o = at(1.0, a, v, ab);
                            at(1.0, o, w, ac)
                        }
                    }
                }
            }
        }
    };
    norm(sub(p, closest))
}

/// Winding number at `p` and the distance from `p` to the mesh, in one pass.
pub fn winding_and_distance(p: P, positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> (f64, f64) {
    let mut w = 0.0;
    let mut d = f64::INFINITY;
    for &t in triangles {
        let c = corners(positions, t);
        w += solid_angle(p, c);
        d = d.min(point_triangle_distance(p, c));
    }
    (w / (4.0 * PI), d)
}

/// Enclosed volume by the divergence theorem: positive for an outward-wound closed surface.
pub fn signed_volume(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(positions, t);
            dot(a, cross(b, c)) / 6.0
        })
        .sum()
}

/// Fraction of triangles whose face normal `(b − a) × (c − a)` has a positive dot product with
/// the sum of their three vertex normals.
pub fn normal_agreement(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> f64 {
    assert_eq!(positions.len(), normals.len(), "one normal per vertex");
    let agree = triangles
        .iter()
        .filter(|&&t| {
            let [a, b, c] = corners(positions, t);
            let face = cross(sub(b, a), sub(c, a));
            let n = t.iter().fold([0.0; 3], |s, &i| {
                let v = normals[i as usize].map(f64::from);
                [s[0] + v[0], s[1] + v[1], s[2] + v[2]]
            });
            dot(face, n) > 0.0
        })
        .count();
    agree as f64 / triangles.len().max(1) as f64
}

/// Twice the area of a triangle.
pub fn double_area(positions: &[[f32; 3]], t: [u32; 3]) -> f64 {
    let [a, b, c] = corners(positions, t);
    norm(cross(sub(b, a), sub(c, a)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TET: [[f32; 3]; 4] = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    const TRIS: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

    #[test]
    fn winding_number_is_one_inside_zero_outside() {
        let w = winding_number([0.1, 0.1, 0.1], &TET, &TRIS);
        assert!((w - 1.0).abs() < 1e-12, "{w}");
        let w = winding_number([1.0, 1.0, 1.0], &TET, &TRIS);
        assert!(w.abs() < 1e-12, "{w}");
        let flipped: Vec<[u32; 3]> = TRIS.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let w = winding_number([0.1, 0.1, 0.1], &TET, &flipped);
        assert!((w + 1.0).abs() < 1e-12, "{w}");
        assert!((signed_volume(&TET, &TRIS) - 1.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn distance_to_a_triangle() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!((point_triangle_distance([0.2, 0.2, 0.5], t) - 0.5).abs() < 1e-12);
        assert!((point_triangle_distance([-1.0, 0.0, 0.0], t) - 1.0).abs() < 1e-12);
        assert!((point_triangle_distance([1.0, 1.0, 0.0], t) - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((point_triangle_distance([0.5, -2.0, 0.0], t) - 2.0).abs() < 1e-12);
    }
}
