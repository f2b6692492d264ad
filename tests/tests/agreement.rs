//! The runtime's meshes equal the reference implementation's exactly (same vertices, same oriented
//! triangles up to renumbering, same counts) on every kind of volume, in all three modes.

use sc_runtime::{Mode, demo};
use sc_tests::checks::{
    assert_closed_manifold, assert_no_self_intersections, assert_separates, assert_spec6,
    matches_reference,
};
use sc_tests::volumes::{
    self, Sample, Vol, bare_case, brainsmall_crop, integer_noise, itk_t1_crop, single_case,
    stent_crop, touching_spheres,
};

const MODES: [Mode; 3] = [Mode::Steps123, Mode::Embedded, Mode::Paper];

fn all_modes<T: Sample>(vol: &Vol<T>) {
    for mode in MODES {
        let mesh = matches_reference(vol, mode);
        assert_spec6(vol, mode, &mesh);
    }
}

#[test]
fn analytic_solids_match_reference() {
    all_modes(&volumes::demo(demo::sphere(20)));
    all_modes(&volumes::demo(demo::torus(24)));
    all_modes(&volumes::demo(demo::sphere_noise(18)));
    all_modes(&touching_spheres(17, 4.0));
    all_modes(&touching_spheres(16, 3.5));
}

#[test]
fn knot_matches_reference() {
    all_modes(&volumes::demo(demo::knot(64)));
}

#[test]
fn integer_ties_match_reference() {
    for seed in 0..4 {
        let v = integer_noise([11, 9, 10], 3, seed);
        assert!(v.data.iter().filter(|&&x| x as f64 == v.iso).count() > 200);
        all_modes(&v);
        all_modes(&v.padded(0));
    }
}

#[test]
fn real_crops_match_reference() {
    all_modes(&brainsmall_crop());
    all_modes(&stent_crop(281.0));
    all_modes(&stent_crop(250.0));
    all_modes(&itk_t1_crop());
}

/// All 256 cases in each of the 8 parity classes, embedded in an empty 5³ grid (also checked
/// closed, embedded and separating), and each case alone on a bare 2×2×2 grid.
#[test]
fn every_case_in_every_class_matches_reference() {
    for class in 0..8 {
        for case in 0..=255u8 {
            let vol = single_case(case, class);
            all_modes(&vol);
            if case == 0 {
                continue;
            }
            // The border is empty: closed, embedded and separating in every mode but Paper.
            for mode in [Mode::Steps123, Mode::Embedded] {
                let mesh = vol.extract(mode);
                let what = format!("class {class} case {case} {mode:?}");
                assert_closed_manifold(&mesh, &what);
                assert_no_self_intersections(&mesh, &what);
                assert_separates(&vol, &mesh, 1, &what);
            }
            assert_separates(&vol, &vol.extract(Mode::Paper), 1, "single case, Paper");
        }
    }
    for case in 0..=255u8 {
        all_modes(&bare_case(case));
    }
}
