//! The paper's knotted torus at 64³ (SPEC §8), and the measured difference between Paper and
//! Embedded mode (SPEC §5): paper mode leaves edges shared by four triangles, embedded none.

use sc_runtime::{Mode, demo};
use sc_tests::topology::{edge_multiplicities, overused_edges};
use sc_tests::volumes::{self, Sample, Vol, brainsmall_crop, itk_t1_crop, stent_crop};

#[test]
fn knot_triangle_counts() {
    let knot = volumes::demo(demo::knot(64));
    let s123 = knot.extract(Mode::Steps123);
    let paper = knot.extract(Mode::Paper);
    let emb = knot.extract(Mode::Embedded);
    assert_eq!(
        s123.triangles.len(),
        13_968,
        "Steps 1–3: the paper's Table 1 figure"
    );
    assert_eq!(s123.stats.t13, 13_968);
    assert_eq!(
        paper.triangles.len(),
        10_468,
        "paper mode (the paper reports 10,464)"
    );
    assert_eq!(emb.triangles.len(), 10_520, "embedded mode");
    assert_eq!(paper.stats.t13, 13_968);
    assert_eq!(emb.stats.t13, 13_968);
    println!(
        "knot 64³: steps 1–3 {} / paper {} (merged {}) / embedded {} (merged {}, blocked {}); embedded − paper = {}",
        s123.triangles.len(),
        paper.triangles.len(),
        paper.stats.merged,
        emb.triangles.len(),
        emb.stats.merged,
        emb.stats.blocked,
        emb.triangles.len() as i64 - paper.triangles.len() as i64
    );
    assert_eq!(overused_edges(&emb.triangles), 0);
    assert_eq!(overused_edges(&s123.triangles), 0);
    let four = edge_multiplicities(&paper.triangles);
    println!("knot 64³ paper mode edge multiplicities: {four:?}");
    assert_eq!(
        four.get(&4),
        Some(&8),
        "paper mode: 8 edges in 4 triangles (measured)"
    );
    assert_eq!(four.keys().copied().collect::<Vec<_>>(), vec![2, 4]);
}

fn paper_vs_embedded<T: Sample>(vol: &Vol<T>, what: &str) -> (usize, usize) {
    let paper = vol.extract(Mode::Paper);
    let emb = vol.extract(Mode::Embedded);
    let h = edge_multiplicities(&paper.triangles);
    let four = h.get(&4).copied().unwrap_or(0);
    println!(
        "{what}: paper {} triangles, {} edges in 4 triangles (multiplicities {h:?}); embedded {} triangles (+{:.2}%), {} edges in >2",
        paper.triangles.len(),
        four,
        emb.triangles.len(),
        100.0 * (emb.triangles.len() as f64 / paper.triangles.len() as f64 - 1.0),
        overused_edges(&emb.triangles)
    );
    assert_eq!(overused_edges(&emb.triangles), 0, "{what}: embedded mode");
    assert!(emb.triangles.len() >= paper.triangles.len());
    (four, emb.triangles.len() - paper.triangles.len())
}

/// SPEC §5: paper mode is non-manifold on real data; embedded mode is not.
#[test]
fn paper_mode_is_non_manifold_on_real_data_embedded_is_not() {
    let (four, _) = paper_vs_embedded(&brainsmall_crop().padded(0), "brainsmall crop, iso 20");
    assert!(
        four > 0,
        "paper mode should leave edges in 4 triangles on the brainsmall crop"
    );
    paper_vs_embedded(&stent_crop(281.0).padded(0), "stent crop, iso 281");
    paper_vs_embedded(&stent_crop(250.0).padded(0), "stent crop, iso 250");
    paper_vs_embedded(&itk_t1_crop().padded(0), "itk-t1 crop, iso 20");
    paper_vs_embedded(&volumes::demo(demo::sphere_noise(48)), "sphere_noise 48³");
}
