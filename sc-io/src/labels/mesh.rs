//! The bridge from a typed [`Grid`] of labels to the runtime's label sweep: one closed mesh per
//! label, placed in world units like a scan's surface.

use std::ops::RangeInclusive;

use sc_runtime::labels::{Atlas, Label as Sample, LabelParams, extract_labels};
use sc_runtime::{Mesh, Mode, Stats, Volume};

use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::space::{Coordinates, World};
use crate::volume::{Grid, Samples};

/// Which labels get a mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Selection {
    /// Every label present but the background.
    All,
    /// The labels in these ranges; each must be present.
    Only(Vec<RangeInclusive<u64>>),
}

impl Selection {
    /// Parses `all` or a list like `1,5,17-20`, for `--labels`.
    pub fn parse(text: &str) -> std::result::Result<Selection, String> {
        if text.trim() == "all" {
            return Ok(Selection::All);
        }
        let id = |s: &str| {
            s.trim()
                .parse::<u64>()
                .map_err(|_| format!("{s:?} is not a label id (a whole number, 0 or more)"))
        };
        let ranges = text
            .split(',')
            .map(|part| match part.split_once('-') {
                Some((a, b)) => {
                    let (a, b) = (id(a)?, id(b)?);
                    if a > b {
                        return Err(format!("{part:?}: the range runs backwards"));
                    }
                    Ok(a..=b)
                }
                None => id(part).map(|a| a..=a),
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        Ok(Selection::Only(ranges))
    }

    fn contains(&self, id: u64) -> bool {
        match self {
            Selection::All => true,
            Selection::Only(ranges) => ranges.iter().any(|r| r.contains(&id)),
        }
    }
}

/// `all`, or the ranges as [`Selection::parse`] reads them (`1,5,17-20`).
impl std::fmt::Display for Selection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Selection::All => f.write_str("all"),
            Selection::Only(ranges) => {
                let parts: Vec<String> = ranges.iter().map(range_text).collect();
                f.write_str(&parts.join(","))
            }
        }
    }
}

/// `5` or `17-20`.
fn range_text(r: &RangeInclusive<u64>) -> String {
    if r.start() == r.end() {
        r.start().to_string()
    } else {
        format!("{}-{}", r.start(), r.end())
    }
}

/// What to mesh in a label volume.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelRequest {
    /// The label of no region: not meshed, and what lies outside the volume.
    pub background: u64,
    /// Which steps run.
    pub mode: Mode,
    /// Whether to compute normals.
    pub normals: bool,
    /// Worker threads, 0 for all cores.
    pub threads: usize,
    /// Which coordinates the meshes are in.
    pub coordinates: Coordinates,
    /// Which labels get a mesh.
    pub selection: Selection,
    /// Gaussian width (voxels) of the smoothing along edges; 0 for midpoints.
    pub smoothing: f64,
}

/// One closed mesh per label selected, ascending by label.
#[derive(Clone, Debug, Default)]
pub struct LabelMeshes {
    /// Each label with its mesh.
    pub meshes: Vec<(u64, Mesh)>,
    /// The atlas's counts: each interface once.
    pub stats: Stats,
}

/// Meshes the labels `request` selects in `grid`: an integer volume, read as stored.
pub fn extract(
    grid: &Grid,
    request: &LabelRequest,
    progress: &dyn Progress,
) -> Result<LabelMeshes> {
    check_scale(grid)?;
    let world = World::new(grid.frame, grid.origin, request.coordinates);
    progress.phase("meshing labels", grid.dims[2].saturating_sub(1) as u64);
    let out = match &grid.samples {
        Samples::U8(v) => typed(v, grid, request, &world),
        Samples::I8(v) => {
            let wide: Vec<i16> = v.iter().map(|&l| i16::from(l)).collect();
            typed(&wide, grid, request, &world)
        }
        Samples::U16(v) => typed(v, grid, request, &world),
        Samples::I16(v) => typed(v, grid, request, &world),
        Samples::U32(v) => typed(v, grid, request, &world),
        Samples::I32(v) => typed(v, grid, request, &world),
        Samples::F32(_) | Samples::F64(_) => Err(not_integers(grid)),
    }?;
    Ok(placed(out, &world))
}

/// Refuses a volume whose samples are rescaled: a scan, not labels.
pub(super) fn check_scale(grid: &Grid) -> Result<()> {
    if grid.scale.is_identity() {
        return Ok(());
    }
    Err(Error::Usage(format!(
        "--labels: the volume rescales its samples (slope {}, intercept {}); labels are read as \
         stored integers, and a rescaled volume is a scan: give --iso instead",
        grid.scale.slope, grid.scale.inter
    )))
}

/// The refusal of floating-point samples as labels.
pub(super) fn not_integers(grid: &Grid) -> Error {
    Error::Usage(format!(
        "--labels: the volume holds {} samples; label volumes hold integers (give --iso to mesh \
         a scan)",
        grid.samples.dtype().name()
    ))
}

/// The meshes moved into the world, when the map to it is more than the translation the sweep
/// applies.
pub(super) fn placed(mut out: LabelMeshes, world: &World) -> LabelMeshes {
    if !world.is_translation() {
        for (_, mesh) in &mut out.meshes {
            world.place(mesh);
        }
    }
    out
}

/// [`extract`] for one sample type.
fn typed<L>(data: &[L], grid: &Grid, request: &LabelRequest, world: &World) -> Result<LabelMeshes>
where
    L: Sample + TryFrom<u64> + TryInto<i64>,
{
    let params = params(grid, request, world)?;
    let volume = Volume::new(data, grid.dims)?;
    let atlas = extract_labels(volume, &params)?;
    select(atlas, params.background, request)
}

/// The sweep's parameters for `request` on `grid`, whose samples are of type `L`.
pub(super) fn params<L>(
    grid: &Grid,
    request: &LabelRequest,
    world: &World,
) -> Result<LabelParams<L>>
where
    L: Sample + TryFrom<u64>,
{
    let name = grid.samples.dtype().name();
    let background = L::try_from(request.background).map_err(|_| {
        Error::Usage(format!(
            "--background {} does not fit the volume's {name} samples",
            request.background
        ))
    })?;
    Ok(LabelParams {
        background,
        mode: request.mode,
        pad: true,
        spacing: grid.spacing,
        origin: if world.is_translation() {
            world.offset
        } else {
            [0.0; 3]
        },
        threads: request.threads,
        smoothing: request.smoothing,
        ..LabelParams::default()
    })
}

/// The meshes of the labels `request` selects, cut from `atlas`; refuses a selection of labels
/// no sample holds, negative labels, and a volume of background only.
pub(super) fn select<L>(
    atlas: Atlas<L>,
    background: L,
    request: &LabelRequest,
) -> Result<LabelMeshes>
where
    L: Sample + TryInto<i64>,
{
    let chosen = chosen(&atlas.labels(background, request.threads), request)?;
    let meshes = atlas
        .meshes(&chosen, request.normals, request.threads)
        .into_iter()
        .filter_map(|(l, mesh)| Some((id(l)?, mesh)))
        .collect();
    Ok(LabelMeshes {
        meshes,
        stats: atlas.stats,
    })
}

/// A label's id, if it is one (0 or more).
fn id<L: TryInto<i64>>(l: L) -> Option<u64> {
    l.try_into().ok().and_then(|v: i64| u64::try_from(v).ok())
}

/// The labels of `present` (ascending, without the background) that `request` selects; refuses
/// a selection of labels not present, negative labels, and none present.
pub(super) fn chosen<L>(present: &[L], request: &LabelRequest) -> Result<Vec<L>>
where
    L: Sample + TryInto<i64>,
{
    if let Some(&negative) = present.iter().find(|&&l| id(l).is_none()) {
        return Err(Error::Usage(format!(
            "--labels: the volume holds the label {negative:?}; label ids are whole numbers, 0 or more"
        )));
    }
    let chosen: Vec<L> = present
        .iter()
        .copied()
        .filter(|&l| id(l).is_some_and(|i| request.selection.contains(i)))
        .collect();
    if let Selection::Only(ranges) = &request.selection {
        let missing: Vec<String> = ranges
            .iter()
            .filter(|r| {
                !present
                    .iter()
                    .any(|&l| id(l).is_some_and(|i| r.contains(&i)))
            })
            .map(range_text)
            .collect();
        if !missing.is_empty() {
            let some: Vec<String> = present
                .iter()
                .take(12)
                .filter_map(|&l| id(l))
                .map(|i| i.to_string())
                .collect();
            return Err(Error::Usage(format!(
                "--labels: no sample holds {} (present: {}{})",
                missing.join(", "),
                some.join(", "),
                if present.len() > some.len() {
                    ", …"
                } else {
                    ""
                }
            )));
        }
    }
    if chosen.is_empty() {
        return Err(Error::Usage(format!(
            "--labels: the volume holds no label besides the background {}",
            request.background
        )));
    }
    Ok(chosen)
}

#[cfg(test)]
mod tests {
    use super::Selection;

    #[test]
    fn selections_parse_or_say_why_not() {
        assert_eq!(Selection::parse("all"), Ok(Selection::All));
        assert_eq!(
            Selection::parse("1,5,17-20"),
            Ok(Selection::Only(vec![1..=1, 5..=5, 17..=20]))
        );
        for bad in ["", "1,,2", "x", "-3", "5-2", "1.5", "all,3"] {
            assert!(Selection::parse(bad).is_err(), "{bad:?}");
        }
        assert!(Selection::parse("5-2").unwrap_err().contains("backwards"));
        // Written as it is read, for shard manifests.
        for text in ["all", "7", "1,5,17-20", "0-0,3-4"] {
            let selection = Selection::parse(text).unwrap();
            assert_eq!(Selection::parse(&selection.to_string()), Ok(selection));
        }
        assert_eq!(Selection::parse("3, 4-6").unwrap().to_string(), "3,4-6");
    }
}
