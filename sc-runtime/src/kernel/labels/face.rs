//! The face rule (docs/labels.md, rule 2): how a cube face with labelled corners is split.

/// Each face's corners in cyclic order, face `2 · axis + side` (the face at `axis = side`).
/// Corner `c` sits at `(c & 1, c >> 1 & 1, c >> 2 & 1)`.
pub const FACES: [[u8; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 5, 7, 6],
];

/// The cube edge (SPEC §1 numbering) between corners `a` and `b`, which differ in one bit.
pub const fn corner_edge(a: u8, b: u8) -> u8 {
    let low = if a < b { a } else { b };
    let (x, y, z) = (low & 1, (low >> 1) & 1, (low >> 2) & 1);
    match a ^ b {
        1 => y + 2 * z,
        2 => 4 + x + 2 * z,
        _ => 8 + x + 2 * y,
    }
}

/// The corners at the lower and upper ends of cube edge `e`.
pub const fn edge_corners(e: u8) -> (u8, u8) {
    match e {
        0..=3 => {
            let low = ((e & 1) << 1) | ((e >> 1) << 2);
            (low, low | 1)
        }
        4..=7 => {
            let r = e - 4;
            let low = (r & 1) | ((r >> 1) << 2);
            (low, low | 2)
        }
        _ => {
            let low = e - 8;
            (low, low | 4)
        }
    }
}

/// How a face is split, from its four labels in cyclic order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Split {
    /// One label: no side.
    Uniform,
    /// Every maximal run of corners not labelled like corner `connector` is cut off by one side;
    /// the connector's label holds the rest of the face. With two labels the connector is the
    /// smaller (Step 2's "do not cross ○–○ diagonals"); with three, the label on both corners of
    /// a diagonal. `either` marks two labels not in a checkerboard, where cutting off the runs
    /// of either label draws the same sides.
    Cut { connector: usize, either: bool },
    /// Three labels with the repeated one on an edge, or four: a vertex at the face's centre,
    /// joined by a side to each occupied edge.
    Centre,
}

/// The face rule.
pub(super) fn split<K: Ord + Copy>(l: [K; 4]) -> Split {
    let distinct = 1
        + usize::from(l[1] != l[0])
        + usize::from(l[2] != l[0] && l[2] != l[1])
        + usize::from(l[3] != l[0] && l[3] != l[1] && l[3] != l[2]);
    match distinct {
        1 => Split::Uniform,
        2 => {
            let min = (0..4).min_by_key(|&i| l[i]).unwrap_or(0);
            let checkerboard = l[0] == l[2] && l[1] == l[3];
            Split::Cut {
                connector: min,
                either: !checkerboard,
            }
        }
        3 if l[0] == l[2] => Split::Cut {
            connector: 0,
            either: false,
        },
        3 if l[1] == l[3] => Split::Cut {
            connector: 1,
            either: false,
        },
        _ => Split::Centre,
    }
}
