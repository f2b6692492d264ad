//! The generated table set: what `tables/skeleton-climbing.ron` holds and `dump` prints.

use serde::{Deserialize, Serialize};

/// All 8 parity classes × 256 cases.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TableSet {
    /// Class 0's order of the nine non-grey edges, nibbled after the greys 8, 3, 5.
    pub order: [u8; 9],
    /// One table per parity class, in class order.
    pub classes: Vec<ClassTable>,
}

/// The 256 entries of one parity class.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClassTable {
    /// Parity class `p = (i & 1) | (j & 1) << 1 | (k & 1) << 2`.
    pub class: u8,
    /// Entries for cases 0..=255, in case order.
    pub cases: Vec<Entry>,
}

/// One cube case of one class.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Entry {
    /// Bit `c` set iff corner `c` is filled.
    pub case: u8,
    /// Triangles as edge-id triples, wound outward from the filled solid (SPEC §7).
    pub triangles: Vec<[u8; 3]>,
    /// One record per occupied grey edge, ordered x-grey, y-grey, z-grey.
    pub grey: Vec<Grey>,
    /// The rule that produced the triangles.
    pub rule: Rule,
    /// For forced-fold entries only: the paper-mode triangulation (all greys first, the ear's
    /// fold kept), which the runtime's Paper mode uses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paper: Option<PaperEntry>,
}

/// The paper-mode alternative of a forced-fold entry.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PaperEntry {
    /// Triangles as edge-id triples.
    pub triangles: Vec<[u8; 3]>,
    /// Grey records as in [`Entry::grey`]; the folded grey is marked not mergeable.
    pub grey: Vec<Grey>,
    /// The rule whose order produced the triangles.
    pub rule: Rule,
}

/// An occupied grey edge of an entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Grey {
    /// The edge id.
    pub edge: u8,
    /// Index of the only triangle touching the edge's vertex, if there is exactly one and both of
    /// its sides at the vertex are face sides.
    pub ear: Option<u8>,
    /// Whether Step 4 may merge this edge: false exactly for forced folds.
    pub mergeable: bool,
}

/// How an entry's nibbling order was obtained (SPEC §4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Rule {
    /// The class order.
    Base,
    /// The class order composed with ρ.
    Rot1,
    /// The class order composed with ρ².
    Rot2,
    /// A forced fold: one grey moved out of the first three.
    Demoted,
    /// No rotation worked: the first greys-first order that is fold-free and embedded.
    Fallback,
}

impl Rule {
    /// The rule's name as written in the tables.
    pub fn name(self) -> &'static str {
        match self {
            Rule::Base => "base",
            Rule::Rot1 => "rot1",
            Rule::Rot2 => "rot2",
            Rule::Demoted => "demoted",
            Rule::Fallback => "fallback",
        }
    }
}

impl TableSet {
    /// The entry for a class and case.
    pub fn entry(&self, class: u8, case: u8) -> &Entry {
        &self.classes[usize::from(class)].cases[usize::from(case)]
    }

    /// Writes the set as pretty RON (the committed format).
    pub fn to_ron(&self) -> String {
        let cfg = ron::ser::PrettyConfig::new()
            .depth_limit(3)
            .indentor(" ".to_string());
        let mut s = ron::ser::to_string_pretty(self, cfg).expect("table sets always serialize");
        s.push('\n');
        s
    }

    /// Parses a set from RON.
    pub fn from_ron(text: &str) -> Result<TableSet, ron::error::SpannedError> {
        ron::from_str(text)
    }
}
