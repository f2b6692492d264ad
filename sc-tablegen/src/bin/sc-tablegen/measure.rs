//! `optimize-order`: the paper's measurement (§3.1) redone on our data. For each candidate order
//! of the nine non-grey edges, build the tables and sum the L1 length of every interior side the
//! surface gets on real volumes at their suggested iso values. Face sides do not depend on the
//! order, so only interior sides are counted.

use std::path::Path;

use sc_tablegen::cube::{corner_offset, edge_corners};
use sc_tablegen::rng::SplitMix;
use sc_tablegen::sides::cube_sides;
use sc_tablegen::{ORDER0, TableSet};

/// A surface cube: parity class, case, and its vertices (world units) on each edge.
struct SurfaceCube {
    class: u8,
    case: u8,
    vertex: [[f64; 3]; 12],
}

struct Volume {
    name: String,
    iso: f64,
    cubes: Vec<SurfaceCube>,
}

pub fn optimize(
    volumes: &[std::path::PathBuf],
    candidates: usize,
    seed: u64,
) -> Result<(), String> {
    let mut vols = vec![];
    for v in volumes {
        vols.extend(load(v)?);
    }
    for v in &vols {
        println!(
            "{} at iso {}: {} surface cubes",
            v.name,
            v.iso,
            v.cubes.len()
        );
    }
    let mut rng = SplitMix(seed);
    let mut orders = vec![ORDER0];
    for _ in 0..candidates {
        let mut o = ORDER0;
        for i in (1..9).rev() {
            o.swap(i, rng.below(i + 1));
        }
        orders.push(o);
    }
    let mut results = vec![];
    for (n, order) in orders.iter().enumerate() {
        let set = match sc_tablegen::build(order) {
            Ok(set) => set,
            Err(e) => {
                eprintln!("  skipping order {order:?}: {}", e[0]);
                continue;
            }
        };
        let lengths: Vec<f64> = vols.iter().map(|v| interior_length(&set, v)).collect();
        let total: f64 = lengths.iter().sum();
        results.push((total, *order, lengths));
        if (n + 1) % 20 == 0 {
            eprintln!("  {}/{} orders measured", n + 1, orders.len());
        }
    }
    let current = results[0].0;
    results.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (best, worst) = (results[0].0, results[results.len() - 1].0);
    println!("\norders measured: {}", results.len());
    println!(
        "{:>14}  {:<34} per volume",
        "L1 total", "order (after greys 8 3 5)"
    );
    for (total, order, lengths) in results.iter().take(5).chain(results.iter().rev().take(2)) {
        let per: Vec<String> = lengths.iter().map(|l| format!("{l:.0}")).collect();
        println!(
            "{total:>14.1}  {:<34} {}",
            format!("{order:?}"),
            per.join(" ")
        );
    }
    println!(
        "best is {:.2}% below the worst; the current order ({ORDER0:?}) is {:.2}% above the best",
        100.0 * (worst - best) / worst,
        100.0 * (current - best) / best
    );
    println!(
        "best order: {}",
        results[0].1.map(|e| e.to_string()).join(",")
    );
    Ok(())
}

/// Sum of L1 lengths of interior sides (each counted once) over all surface cubes.
fn interior_length(set: &TableSet, v: &Volume) -> f64 {
    // Interior sides per entry: a triangle side whose direction is not a face side, taken once.
    let interior: Vec<Vec<[u8; 2]>> = (0..2048)
        .map(|i| {
            let (p, case) = ((i / 256) as u8, (i % 256) as u8);
            let face = cube_sides(case);
            let mut sides = vec![];
            for t in &set.entry(p, case).triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let is_face = face
                        .iter()
                        .any(|s| (s.from, s.to) == (a, b) || (s.from, s.to) == (b, a));
                    if !is_face && a < b {
                        sides.push([a, b]);
                    }
                }
            }
            sides
        })
        .collect();
    v.cubes
        .iter()
        .map(|c| {
            interior[usize::from(c.class) * 256 + usize::from(c.case)]
                .iter()
                .map(|&[a, b]| {
                    let (p, q) = (c.vertex[usize::from(a)], c.vertex[usize::from(b)]);
                    (0..3).map(|i| (p[i] - q[i]).abs()).sum::<f64>()
                })
                .sum::<f64>()
        })
        .sum()
}

/// Loads `name.json` + `name.raw` and collects surface cubes at each suggested iso value.
fn load(json_path: &Path) -> Result<Vec<Volume>, String> {
    let err = |m: String| format!("{}: {m}", json_path.display());
    let text = std::fs::read_to_string(json_path).map_err(|e| err(e.to_string()))?;
    let meta: serde_json::Value = serde_json::from_str(&text).map_err(|e| err(e.to_string()))?;
    let dims: Vec<usize> = meta["dims"]
        .as_array()
        .and_then(|d| d.iter().map(|x| x.as_u64().map(|x| x as usize)).collect())
        .ok_or_else(|| err("no dims".into()))?;
    let spacing: Vec<f64> = meta["spacing"]
        .as_array()
        .and_then(|d| d.iter().map(serde_json::Value::as_f64).collect())
        .unwrap_or(vec![1.0; 3]);
    let isos: Vec<f64> = meta["iso_suggestions"]
        .as_object()
        .map(|o| o.values().filter_map(serde_json::Value::as_f64).collect())
        .unwrap_or_default();
    let raw = std::fs::read(json_path.with_extension("raw"))
        .map_err(|e| err(format!("raw data: {e}")))?;
    let values: Vec<f64> = match meta["dtype"].as_str() {
        Some("u8") => raw.iter().map(|&b| f64::from(b)).collect(),
        Some("i16") => raw
            .chunks_exact(2)
            .map(|b| f64::from(i16::from_le_bytes([b[0], b[1]])))
            .collect(),
        Some("u16") => raw
            .chunks_exact(2)
            .map(|b| f64::from(u16::from_le_bytes([b[0], b[1]])))
            .collect(),
        Some("f32") => raw
            .chunks_exact(4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .collect(),
        other => return Err(err(format!("unsupported dtype {other:?}"))),
    };
    let [nx, ny, nz] = [dims[0], dims[1], dims[2]];
    if values.len() != nx * ny * nz {
        return Err(err(format!(
            "{} samples, dims say {}",
            values.len(),
            nx * ny * nz
        )));
    }
    let name = json_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(isos
        .into_iter()
        .map(|iso| Volume {
            name: name.clone(),
            iso,
            cubes: surface_cubes(&values, [nx, ny, nz], &spacing, iso),
        })
        .collect())
}

fn surface_cubes(
    f: &[f64],
    [nx, ny, nz]: [usize; 3],
    spacing: &[f64],
    iso: f64,
) -> Vec<SurfaceCube> {
    let mut out = vec![];
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let val = |c: u8| {
                    let o = corner_offset(c);
                    f[(i + usize::from(o[0]))
                        + nx * ((j + usize::from(o[1])) + ny * (k + usize::from(o[2])))]
                };
                let case = (0..8u8)
                    .filter(|&c| val(c) >= iso)
                    .fold(0u8, |m, c| m | 1 << c);
                if case == 0 || case == 255 {
                    continue;
                }
                let vertex = std::array::from_fn(|e| {
                    let [a, b] = edge_corners(e as u8);
                    let t =
                        ((iso - val(a)) / (val(b) - val(a))).clamp(1.0 / 1024.0, 1023.0 / 1024.0);
                    let (pa, pb) = (corner_offset(a), corner_offset(b));
                    [0, 1, 2].map(|d| {
                        let x = f64::from(pa[d]) + t * (f64::from(pb[d]) - f64::from(pa[d]));
                        x * spacing[d]
                    })
                });
                let class = (i & 1 | (j & 1) << 1 | (k & 1) << 2) as u8;
                out.push(SurfaceCube {
                    class,
                    case,
                    vertex,
                });
            }
        }
    }
    out
}
