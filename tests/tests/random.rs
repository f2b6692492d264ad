//! Property tests: random volumes up to 12³, every scalar type, random iso values (often equal to
//! samples, so ties are common; NaN and infinities for floats). The runtime must equal the
//! reference in every mode, and a padded copy must give a closed 2-manifold that separates filled
//! from empty samples (Steps123 and Embedded) and a separating surface in Paper mode; Steps123
//! also without self-intersections.

use proptest::prelude::*;
use sc_runtime::Mode;
use sc_tests::checks::{
    assert_closed_manifold, assert_no_self_intersections, assert_separates, assert_spec6,
    matches_reference,
};
use sc_tests::volumes::{Sample, Vol};

fn check<T: Sample>(data: Vec<T>, dims: [usize; 3], iso: f64, pad: T) {
    let vol = Vol::new(data, dims, iso);
    for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
        let mesh = matches_reference(&vol, mode);
        assert_spec6(&vol, mode, &mesh);
    }
    let padded = vol.padded(pad);
    for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
        let mesh = matches_reference(&padded, mode);
        if mode != Mode::Paper {
            assert_closed_manifold(&mesh, &format!("padded random {mode:?}"));
        }
        // Embedded mode is left out: it can hit the flat-z-quad defect (rules.rs).
        if mode == Mode::Steps123 {
            assert_no_self_intersections(&mesh, "padded random Steps123");
        }
        if !mesh.triangles.is_empty() {
            assert_separates(&padded, &mesh, 1, &format!("padded random {mode:?}"));
        }
    }
}

fn dims() -> impl Strategy<Value = [usize; 3]> {
    (1usize..=12, 1usize..=12, 1usize..=12).prop_map(|(x, y, z)| [x, y, z])
}

/// Samples from a small set of levels (ties with an integer iso are frequent) or anywhere.
macro_rules! int_prop {
    ($name:ident, $t:ty, $lo:expr, $hi:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
            #[test]
            fn $name(
                (dims, data) in dims().prop_flat_map(|d| {
                    let n = d[0] * d[1] * d[2];
                    let small = prop::collection::vec($lo..=$hi, n).boxed();
                    let full = prop::collection::vec(any::<$t>(), n).boxed();
                    (Just(d), prop_oneof![3 => small, 1 => full])
                }),
                pick in 0usize..1000,
                frac in prop_oneof![Just(0.0), Just(0.5), 0.0f64..1.0],
            ) {
                // An iso at (or just above) one of the samples, never at the type's minimum, so the
                // minimum pads with empty samples.
                let base = data[pick % data.len()] as f64;
                let iso = (base + frac).max(<$t>::MIN as f64 + 1.0);
                check(data, dims, iso, <$t>::MIN);
            }
        }
    };
}

int_prop!(random_u8, u8, 0u8, 5u8);
int_prop!(random_i8, i8, -3i8, 3i8);
int_prop!(random_u16, u16, 0u16, 5u16);
int_prop!(random_i16, i16, -3i16, 3i16);
int_prop!(random_u32, u32, 0u32, 5u32);
int_prop!(random_i32, i32, -3i32, 3i32);

/// Floats: small integer levels, arbitrary finite values, and NaN / ±∞ samples.
macro_rules! float_prop {
    ($name:ident, $t:ty) => {
        proptest! {
            #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
            #[test]
            fn $name(
                (dims, data) in dims().prop_flat_map(|d| {
                    let n = d[0] * d[1] * d[2];
                    let sample = prop_oneof![
                        6 => (-3i32..=3).prop_map(|v| v as $t),
                        3 => -4.0 as $t..4.0,
                        1 => Just(<$t>::NAN),
                        1 => Just(<$t>::INFINITY),
                        1 => Just(<$t>::NEG_INFINITY),
                    ];
                    (Just(d), prop::collection::vec(sample, n))
                }),
                iso in prop_oneof![(-3i32..=3).prop_map(f64::from), -3.5f64..3.5],
                nan_pad in any::<bool>(),
            ) {
                let pad = if nan_pad { <$t>::NAN } else { <$t>::MIN };
                check(data, dims, iso, pad);
            }
        }
    };
}

float_prop!(random_f32, f32);
float_prop!(random_f64, f64);
