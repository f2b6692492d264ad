//! The counts of an extraction as JSON, as `skelclimb extract --stats-json` and `merge
//! --stats-json` report them and shard manifests record the error bound: names from the
//! runtime's tables ([`Mode::NAMES`], [`ErrorUnits::NAMES`](sc_runtime::ErrorUnits::NAMES),
//! [`Stats::report`]), so that every front end spells them alike.

use sc_runtime::{ErrorBound, Figure, Mode, Stats};
use serde_json::{Map, Value, json};

/// The mode, the error bound (`null` if none), [`Stats::report`]'s figures and
/// `reduction_percent`, in the order `--stats-json` writes them.
pub fn counts(mode: Mode, max_error: Option<ErrorBound>, stats: &Stats) -> Map<String, Value> {
    let mut j = Map::new();
    j.insert("mode".into(), mode.name().into());
    for (name, figure) in stats.report() {
        j.insert(name.into(), figure_json(figure));
    }
    j.insert("max_error".into(), max_error.map(bound).into());
    j.insert("reduction_percent".into(), stats.reduction_percent().into());
    j
}

/// An error bound: `{"value": 0.5, "units": "world"}`.
pub fn bound(bound: ErrorBound) -> Value {
    json!({ "value": bound.value(), "units": bound.units().name() })
}

fn figure_json(figure: Figure) -> Value {
    match figure {
        Figure::Mesh {
            vertices,
            triangles,
        } => json!({ "vertices": vertices, "triangles": triangles }),
        Figure::Edges(n) => n.into(),
    }
}
