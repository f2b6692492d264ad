/// Counts of one extraction (SPEC §6 names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stats {
    /// Occupied grid edges: the vertices of Steps 1–3.
    pub v13: u64,
    /// Triangles of Steps 1–3.
    pub t13: u64,
    /// Grey edges merged by Step 4.
    pub merged: u64,
    /// Occupied interior grey edges that Step 4 left alone (embedded mode's blocking rules, or
    /// the error bound).
    pub blocked: u64,
    /// Of those, the ones only the error bound ([`crate::Params::max_error`]) kept.
    pub bounded: u64,
    /// Vertices in the output.
    pub vertices: u64,
    /// Triangles in the output.
    pub triangles: u64,
}

impl Stats {
    /// The counts' names in declaration order, the order of [`Stats::to_array`]: what shard
    /// manifests call them.
    pub const NAMES: [&'static str; 7] = [
        "v13",
        "t13",
        "merged",
        "blocked",
        "bounded",
        "vertices",
        "triangles",
    ];

    /// The counts as every front end reports them (`skelclimb extract --stats-json`, Python's
    /// `stats` dict), by name and in this order: the meshes of Steps 1–3 (`steps123`) and of
    /// the whole run (`result`), then the grey edges merged, blocked and bounded.
    pub fn report(&self) -> [(&'static str, Figure); 5] {
        [
            ("steps123", Figure::mesh(self.v13, self.t13)),
            ("result", Figure::mesh(self.vertices, self.triangles)),
            ("merged", Figure::Edges(self.merged)),
            ("blocked", Figure::Edges(self.blocked)),
            ("bounded", Figure::Edges(self.bounded)),
        ]
    }

    /// Triangles saved against Steps 1–3, in percent (0 when Steps 1–3 made none): reported
    /// beside [`Stats::report`] as `reduction_percent`.
    pub fn reduction_percent(&self) -> f64 {
        if self.t13 == 0 {
            0.0
        } else {
            100.0 * (1.0 - self.triangles as f64 / self.t13 as f64)
        }
    }

    /// The counts in declaration order: v13, t13, merged, blocked, bounded, vertices, triangles.
    /// Front ends that pass counts through plain arrays (Python tuples, JSON) use this order.
    pub fn to_array(self) -> [u64; 7] {
        [
            self.v13,
            self.t13,
            self.merged,
            self.blocked,
            self.bounded,
            self.vertices,
            self.triangles,
        ]
    }

    /// The inverse of [`Stats::to_array`].
    pub fn from_array(c: [u64; 7]) -> Stats {
        let [v13, t13, merged, blocked, bounded, vertices, triangles] = c;
        Stats {
            v13,
            t13,
            merged,
            blocked,
            bounded,
            vertices,
            triangles,
        }
    }
}

/// One figure of [`Stats::report`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    /// A mesh's size.
    Mesh {
        /// Its vertices.
        vertices: u64,
        /// Its triangles.
        triangles: u64,
    },
    /// A number of grey edges.
    Edges(u64),
}

impl Figure {
    fn mesh(vertices: u64, triangles: u64) -> Figure {
        Figure::Mesh {
            vertices,
            triangles,
        }
    }
}

/// Counts of disjoint parts (parallel chunks, blocks) add up to the counts of the whole.
impl core::ops::Add for Stats {
    type Output = Stats;

    fn add(self, b: Stats) -> Stats {
        Stats {
            v13: self.v13 + b.v13,
            t13: self.t13 + b.t13,
            merged: self.merged + b.merged,
            blocked: self.blocked + b.blocked,
            bounded: self.bounded + b.bounded,
            vertices: self.vertices + b.vertices,
            triangles: self.triangles + b.triangles,
        }
    }
}
