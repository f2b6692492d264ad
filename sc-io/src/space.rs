//! Where a scan sits in the scanner's world: the index-to-world map each format states (NIfTI
//! sform/qform, NRRD space directions, MetaImage TransformMatrix, DICOM orientation and
//! position), and the patient coordinate conventions viewers expect.
//!
//! A sample `i = (l, m, n)` sits at `origin + D · (i ⊙ spacing)`, where the columns of `D` are
//! the unit directions of the three array axes in the file's own convention. The extractor
//! works in `i ⊙ spacing`; [`World::place`] maps its mesh into world space afterwards, turning
//! normals with the inverse transpose and reversing the winding when the map mirrors (a negative
//! determinant), so that triangles still face out of the filled region.

use sc_runtime::Mesh;

/// A patient coordinate convention: which way the world's +x and +y point (+z is superior in
/// both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Space {
    /// +x right, +y anterior: NIfTI, nibabel, FreeSurfer.
    Ras,
    /// +x left, +y posterior: DICOM, ITK, NRRD's usual space, 3D Slicer's model files.
    Lps,
}

impl Space {
    /// The name written into output files and summaries.
    pub fn name(self) -> &'static str {
        match self {
            Space::Ras => "RAS",
            Space::Lps => "LPS",
        }
    }

    /// The sign of the x and y axes when going from `self` to `other` (RAS and LPS differ in both).
    fn flip_to(self, other: Space) -> f64 {
        if self == other { 1.0 } else { -1.0 }
    }
}

/// The rotation (or general linear part) of a file's index-to-world map, and its convention.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Row-major 3×3 matrix whose columns are the unit world directions of the x, y, z axes.
    pub direction: [[f64; 3]; 3],
    /// The convention the file states its world coordinates in.
    pub space: Space,
}

impl Frame {
    /// Axis-aligned, in `space`.
    pub fn aligned(space: Space) -> Frame {
        Frame {
            direction: IDENTITY,
            space,
        }
    }

    /// The frame whose columns are `columns` (one per array axis, any length: normalised here),
    /// with the lengths returned as the spacing. `None` when a column is zero or not finite, or
    /// the three are linearly dependent: no placement can be built from them.
    pub fn from_columns(columns: [[f64; 3]; 3], space: Space) -> Option<(Frame, [f64; 3])> {
        let lengths = columns.map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt());
        if !lengths.iter().all(|l| l.is_finite() && *l > 0.0) {
            return None;
        }
        let unit: [[f64; 3]; 3] = [0, 1, 2].map(|a| columns[a].map(|v| v / lengths[a]));
        let direction = [0, 1, 2].map(|r| [0, 1, 2].map(|c| unit[c][r]));
        (det(&direction).abs() > 1e-6).then_some((Frame { direction, space }, lengths))
    }

    /// The rotation of a NIfTI qform: quaternion `(b, c, d)` with `a = √(1 − b² − c² − d²)`,
    /// and `qfac` (±1) flipping the third axis.
    pub fn from_quaternion(b: f64, c: f64, d: f64, qfac: f64) -> Option<Frame> {
        let a2 = 1.0 - (b * b + c * c + d * d);
        let a = if a2 > 1e-7 { a2.sqrt() } else { 0.0 };
        let r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - c * c - b * b,
            ],
        ];
        let columns =
            [0, 1, 2].map(|k| [0, 1, 2].map(|row| r[row][k] * if k == 2 { qfac } else { 1.0 }));
        Frame::from_columns(columns, Space::Ras).map(|(frame, _)| frame)
    }

    /// Whether the direction matrix is the identity.
    pub fn is_aligned(&self) -> bool {
        self.direction == IDENTITY
    }
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Which coordinates the mesh is written in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Coordinates {
    /// The scanner's world, in the convention the file uses (RAS for NIfTI, LPS for DICOM,
    /// MetaImage and most NRRD).
    #[default]
    Native,
    /// The scanner's world, right-anterior-superior.
    Ras,
    /// The scanner's world, left-posterior-superior.
    Lps,
    /// Index × spacing + origin, ignoring the file's rotation.
    Index,
}

/// The map from the extractor's `index ⊙ spacing` to the output coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct World {
    /// Row-major linear part.
    pub linear: [[f64; 3]; 3],
    /// Where sample (0, 0, 0) lands.
    pub offset: [f64; 3],
    /// The convention of the result, or `None` for index coordinates.
    pub space: Option<Space>,
}

impl World {
    /// The map for a grid with `frame` (if the file has one) and `origin`, written in `wanted`.
    pub fn new(frame: Option<Frame>, origin: [f64; 3], wanted: Coordinates) -> World {
        let (frame, target) = match (frame, wanted) {
            (_, Coordinates::Index) | (None, _) => {
                return World {
                    linear: IDENTITY,
                    offset: origin,
                    space: None,
                };
            }
            (Some(f), Coordinates::Native) => (f, f.space),
            (Some(f), Coordinates::Ras) => (f, Space::Ras),
            (Some(f), Coordinates::Lps) => (f, Space::Lps),
        };
        let flip = frame.space.flip_to(target);
        let sign = [flip, flip, 1.0];
        World {
            linear: [0, 1, 2].map(|r| frame.direction[r].map(|v| v * sign[r])),
            offset: [0, 1, 2].map(|r| origin[r] * sign[r]),
            space: Some(target),
        }
    }

    /// Whether the map is `p + offset`, which the extractor applies itself (exactly as before
    /// world coordinates existed, to the bit).
    pub fn is_translation(&self) -> bool {
        self.linear == IDENTITY
    }

    /// Whether the map mirrors, so that the winding must be reversed.
    pub fn mirrors(&self) -> bool {
        det(&self.linear) < 0.0
    }

    /// Maps a mesh made at `index ⊙ spacing` (origin zero) into these coordinates.
    pub fn place(&self, mesh: &mut Mesh) {
        let m = self.linear;
        for p in &mut mesh.positions {
            let q = p.map(f64::from);
            *p = [0, 1, 2].map(|r| (dot(&m[r], &q) + self.offset[r]) as f32);
        }
        let normal_map = inverse_transpose(&m);
        for n in &mut mesh.normals {
            let q = n.map(f64::from);
            let v = [0, 1, 2].map(|r| dot(&normal_map[r], &q));
            let len = dot(&v, &v).sqrt();
            if len > 0.0 {
                *n = v.map(|c| (c / len) as f32);
            }
        }
        if self.mirrors() {
            for t in &mut mesh.triangles {
                t.swap(1, 2);
            }
        }
    }

    /// A description for summaries and file comments.
    pub fn describe(&self) -> String {
        match self.space {
            Some(space) => format!("{} world coordinates (scanner space)", space.name()),
            None => "index × spacing + origin (no rotation)".into(),
        }
    }
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn det(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// `(M⁻¹)ᵀ`, up to a positive factor (normals are normalised afterwards): the cofactor matrix,
/// with the sign of the determinant so that it does not flip them.
fn inverse_transpose(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let cof = [
        [c(1, 2, 1, 2), -c(1, 2, 0, 2), c(1, 2, 0, 1)],
        [-c(0, 2, 1, 2), c(0, 2, 0, 2), -c(0, 2, 0, 1)],
        [c(0, 1, 1, 2), -c(0, 1, 0, 2), c(0, 1, 0, 1)],
    ];
    let s = det(m).signum();
    cof.map(|row| row.map(|v| v * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_of_the_identity_and_a_flip() {
        let f = Frame::from_quaternion(0.0, 0.0, 0.0, 1.0).unwrap();
        assert!(f.is_aligned());
        let flipped = Frame::from_quaternion(0.0, 0.0, 0.0, -1.0).unwrap();
        assert_eq!(flipped.direction[2][2], -1.0);
        // b = c = 0, d = sin(45°): a quarter turn about z takes x to y.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let q = Frame::from_quaternion(0.0, 0.0, s, 1.0).unwrap();
        assert!((q.direction[1][0] - 1.0).abs() < 1e-12 && q.direction[0][0].abs() < 1e-12);
    }

    #[test]
    fn columns_give_spacing_and_refuse_degenerate_frames() {
        let (f, s) = Frame::from_columns(
            [[-2.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 3.0, 0.0]],
            Space::Ras,
        )
        .unwrap();
        assert_eq!(s, [2.0, 2.0, 3.0]);
        assert_eq!(
            f.direction,
            [[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
        );
        assert!(
            Frame::from_columns(
                [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                Space::Ras
            )
            .is_none()
        );
        assert!(
            Frame::from_columns(
                [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                Space::Ras
            )
            .is_none()
        );
    }

    #[test]
    fn placing_maps_points_turns_normals_and_keeps_faces_outward() {
        // A mirror in x: det < 0, so the winding is reversed.
        let frame = Frame::from_columns(
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            Space::Ras,
        )
        .unwrap()
        .0;
        let world = World::new(Some(frame), [10.0, 20.0, 30.0], Coordinates::Native);
        assert!(world.mirrors());
        let mut mesh = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            triangles: vec![[0, 1, 2]],
            ..Mesh::default()
        };
        world.place(&mut mesh);
        assert_eq!(mesh.positions[1], [9.0, 20.0, 30.0]);
        assert_eq!(mesh.triangles, [[0, 2, 1]]);
        // The face normal (b − a) × (c − a) still agrees with the vertex normals.
        let p: Vec<[f64; 3]> = mesh.positions.iter().map(|v| v.map(f64::from)).collect();
        let [a, b, c] = mesh.triangles[0].map(|i| p[i as usize]);
        let (u, v) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let z = u[0] * v[1] - u[1] * v[0];
        assert!(z > 0.0 && mesh.normals[0] == [0.0, 0.0, 1.0]);
        // RAS to LPS negates x and y, a rotation: no reversal.
        let lps = World::new(Some(frame), [10.0, 20.0, 30.0], Coordinates::Lps);
        assert_eq!(lps.mirrors(), world.mirrors());
        assert_eq!(lps.offset, [-10.0, -20.0, 30.0]);
        assert_eq!(
            World::new(Some(frame), [1.0; 3], Coordinates::Index).space,
            None
        );
    }
}
