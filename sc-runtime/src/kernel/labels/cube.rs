//! Which construction a cube of labelled corners takes, and the triangles of the two that are
//! not a binary table's (docs/labels.md, "Cubes").

use super::face::{FACES, Split, corner_edge, edge_corners, split};

/// The most triangles a junction cube emits; the exhaustive test over every labelling checks
/// the bound.
pub const MAX_TRIANGLES: usize = 112;

/// A vertex of a junction cube's triangles. Nodes (`0..12` an edge, `12 + f` face `f`'s centre)
/// are shared with the neighbours; the centre and the inner vertices belong to the cube.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Local {
    /// The midpoint of cube edge `e` (SPEC §1 numbering).
    Edge(u8),
    /// The centre of face `f` (see [`FACES`](super::FACES)).
    Face(u8),
    /// The cube's centre.
    Centre,
    /// Node `n` moved halfway to the centre.
    InnerNode(u8),
    /// Corner `c` moved halfway to the centre.
    InnerCorner(u8),
}

impl Local {
    /// The position in quarters of the cube's side, from its lower corner: every vertex of the
    /// constructions sits on that lattice, so orientation tests are exact.
    pub const fn quarters(self) -> [i32; 3] {
        match self {
            Local::Edge(e) => {
                let (a, b) = edge_corners(e);
                mid(corner(a), corner(b))
            }
            Local::Face(f) => {
                let axis = (f / 2) as usize;
                let mut p = [2; 3];
                p[axis] = 4 * (f % 2) as i32;
                p
            }
            Local::Centre => [2; 3],
            Local::InnerNode(n) => inner(node(n).quarters()),
            Local::InnerCorner(c) => inner(corner(c)),
        }
    }
}

/// Node `n` as a vertex: an edge's midpoint or a face's centre.
const fn node(n: u8) -> Local {
    if n < 12 {
        Local::Edge(n)
    } else {
        Local::Face(n - 12)
    }
}

const fn corner(c: u8) -> [i32; 3] {
    [
        4 * (c & 1) as i32,
        4 * ((c >> 1) & 1) as i32,
        4 * ((c >> 2) & 1) as i32,
    ]
}

const fn mid(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2]
}

const fn inner(p: [i32; 3]) -> [i32; 3] {
    [2 + (p[0] - 2) / 2, 2 + (p[1] - 2) / 2, 2 + (p[2] - 2) / 2]
}

/// What a cube takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// One label: no surface.
    Uniform,
    /// Every face splits as the binary case `case` (bit `c` set iff corner `c` is not labelled
    /// like corner `background`) splits it, so the cube is that case's table entry: each loop
    /// separates the background's label from one other, and Step 4 applies as it is. Every
    /// two-label cube is one, with the smaller label as background.
    Binary {
        /// A corner with the label that plays "empty".
        background: u8,
        /// The binary case.
        case: u8,
    },
    /// Three or more labels that no binary case splits alike: [`junction`] builds it.
    Junction,
}

/// The construction for a cube whose corners have labels ordered by `keys`.
pub fn classify<K: Ord + Copy>(keys: &[K; 8]) -> Kind {
    few_labels(keys).unwrap_or_else(|| classify_many(keys))
}

/// [`classify`] for a cube of one or two labels, the common case, which needs no face test:
/// the smaller label is the background. `None` for three or more.
#[inline]
pub fn few_labels<K: Ord + Copy>(keys: &[K; 8]) -> Option<Kind> {
    // Masks of comparisons rather than a loop that stops at the third label: no branch per
    // corner, and most cubes asked have two labels.
    let first = keys[0];
    let differ = (1..8).fold(0u8, |m, c| m | u8::from(keys[c] != first) << c);
    if differ == 0 {
        return Some(Kind::Uniform);
    }
    let o = differ.trailing_zeros() as u8;
    let other = keys[usize::from(o)];
    let neither = (1..8).fold(0u8, |m, c| m | u8::from(keys[c] != other) << c) & differ;
    // The smaller label is the background, as in `binary`.
    (neither == 0).then_some(if first < other {
        Kind::Binary {
            background: 0,
            case: differ,
        }
    } else {
        Kind::Binary {
            background: o,
            case: !differ,
        }
    })
}

/// [`classify`] for three or more labels.
fn classify_many<K: Ord + Copy>(keys: &[K; 8]) -> Kind {
    let splits = FACES.map(|f| split(f.map(|c| keys[c as usize])));
    let mut sorted = *keys;
    sorted.sort_unstable();
    for (i, &w) in sorted.iter().enumerate() {
        if i > 0 && sorted[i - 1] == w {
            continue;
        }
        let agrees = FACES.iter().zip(&splits).all(|(face, s)| match *s {
            Split::Uniform => true,
            Split::Centre => false,
            Split::Cut { connector, either } => {
                keys[face[connector] as usize] == w
                    || (either && face.iter().any(|&c| keys[c as usize] == w))
            }
        });
        if agrees {
            return binary(keys, w);
        }
    }
    Kind::Junction
}

/// The binary cube whose empty corners are those with key `w`.
fn binary<K: Ord + Copy>(keys: &[K; 8], w: K) -> Kind {
    let mut case = 0u8;
    let mut background = 0u8;
    for c in (0..8u8).rev() {
        if keys[c as usize] == w {
            background = c;
        } else {
            case |= 1 << c;
        }
    }
    Kind::Binary { background, case }
}

/// A junction cube's triangles.
#[derive(Clone, Debug)]
pub struct Junction {
    /// Triangles, the first [`Junction::len`] used, wound so that `(b − a) × (c − a)` points
    /// from the first label of their pair to the second.
    pub triangles: [[Local; 3]; MAX_TRIANGLES],
    /// Per triangle, a corner labelled like the region it faces away from, then one labelled
    /// like the region it faces toward.
    pub pairs: [[u8; 2]; MAX_TRIANGLES],
    /// Triangles used.
    pub len: usize,
}

impl Default for Junction {
    fn default() -> Self {
        Junction {
            triangles: [[Local::Centre; 3]; MAX_TRIANGLES],
            pairs: [[0; 2]; MAX_TRIANGLES],
            len: 0,
        }
    }
}

impl Junction {
    fn push(&mut self, triangle: [Local; 3], toward: [i32; 3], pair: [u8; 2]) {
        self.triangles[self.len] = orient(triangle, toward);
        self.pairs[self.len] = pair;
        self.len += 1;
    }
}

/// `triangle` wound so that its normal points to the side of its plane where `toward` lies.
fn orient(t: [Local; 3], toward: [i32; 3]) -> [Local; 3] {
    let [a, b, c] = t.map(Local::quarters);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let w = [toward[0] - a[0], toward[1] - a[1], toward[2] - a[2]];
    let side = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    debug_assert!(side != 0, "{t:?} is flat or contains {toward:?}");
    if side < 0 { [t[0], t[2], t[1]] } else { t }
}

/// A side on the cube's surface: between two nodes, with a corner on each side of it.
#[derive(Clone, Copy, Default)]
struct Side {
    nodes: [u8; 2],
    from: u8,
    to: u8,
}

/// A piece of one face held by one region: a convex polygon of corners (`0..8`) and nodes
/// (`8 + n`), with a corner of the region.
#[derive(Clone, Copy, Default)]
struct Piece {
    polygon: [u8; 8],
    len: usize,
    corner: u8,
}

impl Piece {
    fn push(&mut self, entry: u8) {
        self.polygon[self.len] = entry;
        self.len += 1;
    }
}

/// The cube's surface cut by the face rule: its sides, its pieces, and which corners' regions
/// are one (a union–find over the 24 corner-in-face slots).
struct Surface {
    sides: [Side; 24],
    n_sides: usize,
    pieces: [Piece; 24],
    n_pieces: usize,
    parent: [u8; 24],
    centres: usize,
}

impl Surface {
    fn new<K: Ord + Copy>(keys: &[K; 8]) -> Surface {
        let mut s = Surface {
            sides: [Side::default(); 24],
            n_sides: 0,
            pieces: [Piece::default(); 24],
            n_pieces: 0,
            parent: core::array::from_fn(|i| i as u8),
            centres: 0,
        };
        for (f, face) in FACES.iter().enumerate() {
            let l = face.map(|c| keys[c as usize]);
            // The node on the edge from position `i` to `i + 1`.
            let node = |i: usize| 8 + corner_edge(face[i % 4], face[(i + 1) % 4]);
            match split(l) {
                Split::Uniform => {
                    let mut p = Piece::default();
                    for (i, &c) in face.iter().enumerate() {
                        p.push(c);
                        s.union(f, 0, i);
                    }
                    p.corner = face[0];
                    s.add_piece(p);
                }
                Split::Cut { connector, .. } => {
                    let w = l[connector];
                    let mut held = Piece {
                        corner: face[connector],
                        ..Piece::default()
                    };
                    for step in 0..4 {
                        let i = (connector + step) % 4;
                        if l[i] == w {
                            held.push(face[i]);
                            s.union(f, connector, i);
                        }
                        if l[i] != l[(i + 1) % 4] {
                            held.push(node(i));
                        }
                    }
                    s.add_piece(held);
                    for i in 0..4 {
                        if l[i] == w || l[(i + 3) % 4] == l[i] {
                            continue;
                        }
                        let j = s.add_run(f, &l, i, &[node(i + 3)]);
                        s.add_side(Side {
                            nodes: [node(i + 3) - 8, node(j) - 8],
                            from: face[i],
                            to: face[(i + 3) % 4],
                        });
                    }
                }
                Split::Centre => {
                    s.centres += 1;
                    let centre = 8 + 12 + f as u8;
                    for i in 0..4 {
                        if l[i] == l[(i + 1) % 4] {
                            continue;
                        }
                        s.add_side(Side {
                            nodes: [node(i) - 8, centre - 8],
                            from: face[i],
                            to: face[(i + 1) % 4],
                        });
                    }
                    for i in 0..4 {
                        if l[(i + 3) % 4] == l[i] {
                            continue;
                        }
                        s.add_run(f, &l, i, &[centre, node(i + 3)]);
                    }
                }
            }
        }
        // A corner's slots in its three faces are one region.
        for c in 0..8u8 {
            let mut first = None;
            for (f, face) in FACES.iter().enumerate() {
                if let Some(i) = face.iter().position(|&x| x == c) {
                    match first {
                        None => first = Some((f, i)),
                        Some((g, k)) => s.union_slots(g * 4 + k, f * 4 + i),
                    }
                }
            }
        }
        s
    }

    fn add_side(&mut self, side: Side) {
        self.sides[self.n_sides] = side;
        self.n_sides += 1;
    }

    /// Adds the piece of face `f` (labels `l`) held by the run of corners from position `i`:
    /// `lead`, the run's corners, then the node after it. Returns the run's last position.
    fn add_run<K: PartialEq + Copy>(
        &mut self,
        f: usize,
        l: &[K; 4],
        i: usize,
        lead: &[u8],
    ) -> usize {
        let face = FACES[f];
        let mut run = Piece {
            corner: face[i],
            ..Piece::default()
        };
        for &entry in lead {
            run.push(entry);
        }
        let mut j = i;
        loop {
            run.push(face[j % 4]);
            self.union(f, i, j % 4);
            if l[(j + 1) % 4] != l[i] {
                break;
            }
            j += 1;
        }
        run.push(8 + corner_edge(face[j % 4], face[(j + 1) % 4]));
        self.add_piece(run);
        j
    }

    fn add_piece(&mut self, piece: Piece) {
        self.pieces[self.n_pieces] = piece;
        self.n_pieces += 1;
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            let up = self.parent[self.parent[x] as usize];
            self.parent[x] = up;
            x = up as usize;
        }
        x
    }

    fn union_slots(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        self.parent[ra] = rb as u8;
    }

    fn union(&mut self, f: usize, i: usize, j: usize) {
        self.union_slots(f * 4 + i, f * 4 + j);
    }

    /// The region of corner `c`, as a slot id.
    fn region(&mut self, c: u8) -> usize {
        let (f, i) = FACES
            .iter()
            .enumerate()
            .find_map(|(f, face)| face.iter().position(|&x| x == c).map(|i| (f, i)))
            .unwrap_or((0, 0));
        self.find(f * 4 + i)
    }
}

/// The node a cone is drawn from instead of the cube's centre: the first face centre that every
/// region touches (its sides number the regions), if any.
///
/// Seen from a point inside one face, the other five faces are each met once along every ray
/// into the cube, so the cone from there over their sides is embedded as the centre's is; the
/// sides through the apex, all on its own face, need no triangle, which saves one per region.
/// Every region must touch the apex: a label reaching it at one point only would be pinched
/// there when the cube across that face draws its cone from the same centre.
fn cone_apex(sides: &[Side], regions: usize) -> Option<u8> {
    (12..18u8).find(|&n| sides.iter().filter(|s| s.nodes.contains(&n)).count() == regions)
}

/// Builds a junction cube ([`Kind::Junction`]) into `out`.
///
/// When the sides form one connected graph on the cube's surface and every label holds one
/// region of it, each region is a disk and the cube is cut by a cone over the sides: from a face
/// centre every region touches ([`cone_apex`]), one triangle per side off that face, or else
/// from the cube's centre, one triangle per side. Otherwise one label, the one on most corners,
/// takes a hub, the cube shrunk by half about its centre, and every region of another label
/// becomes the slab between its part of the surface and the hub's: walls of two triangles over
/// each side, and a floor. Both are radial from a point that sees each face's sides once, so
/// their triangles cannot cross, wherever the nodes lie on their edges.
pub fn junction<K: Ord + Copy>(keys: &[K; 8], out: &mut Junction) {
    out.len = 0;
    let mut s = Surface::new(keys);
    let region: [usize; 8] = core::array::from_fn(|c| s.region(c as u8));
    let mut regions = 0;
    let mut one_per_label = true;
    for c in 0..8 {
        if (0..c).all(|d| region[d] != region[c]) {
            regions += 1;
        }
        for d in 0..c {
            if keys[d] == keys[c] && region[d] != region[c] {
                one_per_label = false;
            }
        }
    }
    let occupied = (0..12u8)
        .filter(|&e| {
            let (a, b) = edge_corners(e);
            keys[a as usize] != keys[b as usize]
        })
        .count();
    let nodes = occupied + s.centres;
    let connected = nodes + regions == s.n_sides + 2;
    let node = |n: u8| {
        if n < 12 {
            Local::Edge(n)
        } else {
            Local::Face(n - 12)
        }
    };
    if connected && one_per_label {
        let sides = &s.sides[..s.n_sides];
        let apex = cone_apex(sides, regions);
        let tip = apex.map_or(Local::Centre, node);
        for side in sides {
            let [a, b] = side.nodes;
            if Some(a) == apex || Some(b) == apex {
                continue;
            }
            out.push(
                [tip, node(a), node(b)],
                corner(side.to),
                [side.from, side.to],
            );
        }
        return;
    }
    let hub = (0..8u8)
        .max_by(|&a, &b| {
            let count = |c: u8| keys.iter().filter(|&&k| k == keys[c as usize]).count();
            count(a)
                .cmp(&count(b))
                .then(keys[b as usize].cmp(&keys[a as usize]))
        })
        .unwrap_or(0);
    for side in &s.sides[..s.n_sides] {
        let [a, b] = side.nodes;
        let (inner_a, inner_b) = (Local::InnerNode(a), Local::InnerNode(b));
        let pair = [side.from, side.to];
        out.push([node(a), node(b), inner_b], corner(side.to), pair);
        out.push([node(a), inner_b, inner_a], corner(side.to), pair);
    }
    let inner_of = |entry: u8| {
        if entry < 8 {
            Local::InnerCorner(entry)
        } else {
            Local::InnerNode(entry - 8)
        }
    };
    for piece in &s.pieces[..s.n_pieces] {
        if keys[piece.corner as usize] == keys[hub as usize] {
            continue;
        }
        let p = &piece.polygon[..piece.len];
        // Fan from a node (the face's centre first): a corner can be in line with the next two
        // entries, a node never is with two others of a convex piece.
        let apex = p
            .iter()
            .position(|&e| e >= 8 + 12)
            .or_else(|| p.iter().position(|&e| e >= 8))
            .unwrap_or(0);
        for k in 1..p.len() - 1 {
            let t = [
                inner_of(p[apex]),
                inner_of(p[(apex + k) % p.len()]),
                inner_of(p[(apex + k + 1) % p.len()]),
            ];
            out.push(t, [2; 3], [piece.corner, hub]);
        }
    }
}
