//! Every entry point gives the same mesh, bit for bit: `extract_par` on 1, 2 and 8 threads,
//! `SliceStreamer` fed one z-slice at a time, and allocation-free `extract_into` all equal
//! `extract` (SPEC §7: output identical for any number of threads), and `Axes::Zyx` gives it
//! with its coordinates reversed. Also the error paths: bad
//! input is an `Err`, never a panic or a wrap.

use sc_runtime::{
    Axes, Error, Mesh, Mode, Params, Scratch, SliceStreamer, Stats, Volume, demo, extract,
    extract_into, extract_par,
};
use sc_tests::volumes::{self, Sample, Vol, brainsmall_crop, integer_noise, stent_crop};

/// A mesh as bits: positions, normals, values, triangles, stats.
type Bits<'a> = (
    Vec<[u32; 3]>,
    Vec<[u32; 3]>,
    Vec<u32>,
    &'a [[u32; 3]],
    Stats,
);

/// Meshes compared as bits, so even a NaN or a signed zero would count.
fn bits(m: &Mesh) -> Bits<'_> {
    let f = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
    let values = m.values.iter().map(|v| v.to_bits()).collect();
    (
        f(&m.positions),
        f(&m.normals),
        values,
        &m.triangles,
        m.stats,
    )
}

fn all_entry_points_agree<T: Sample>(vol: &Vol<T>, what: &str) {
    for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
        // Normals and values together or neither: each column on its own is the same code.
        for normals in [true, false] {
            let params = Params {
                normals,
                values: normals,
                ..vol.params(mode)
            };
            let v = Volume::new(&vol.data, vol.dims).expect("valid");
            let base = extract(&v, &params).expect("extract");
            assert!(!base.triangles.is_empty(), "{what}: empty");
            assert_eq!(base.normals.is_empty(), !normals);
            let columns = if normals { base.positions.len() } else { 0 };
            assert_eq!((base.normals.len(), base.values.len()), (columns, columns));
            for threads in [1, 2, 8] {
                let done = std::sync::atomic::AtomicUsize::new(0);
                let par = extract_par(&v, &params, threads, &|n| {
                    done.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
                })
                .expect("extract_par");
                assert!(
                    bits(&par) == bits(&base),
                    "{what} {mode:?}: {threads} threads differ"
                );
                assert_eq!(
                    done.into_inner(),
                    vol.dims[2] - 1,
                    "progress counts every layer"
                );
            }
            // Coordinates in `(z, y, x)` order: the same mesh, each position and normal
            // reversed, on one thread and on two.
            let zyx = Params {
                axes: Axes::Zyx,
                ..params
            };
            let mut want = base.clone();
            for p in want.positions.iter_mut().chain(&mut want.normals) {
                p.reverse();
            }
            for threads in [1, 2] {
                let got = extract_par(&v, &zyx, threads, &|_| {}).expect("extract_par");
                assert!(
                    bits(&got) == bits(&want),
                    "{what} {mode:?}: (z, y, x) on {threads} threads differs"
                );
            }
            // Streaming, one slice at a time, through a four-slice ring.
            let len = Scratch::len(vol.dims).expect("len");
            let (mut b, mut w) = (vec![0u8; len.bytes], vec![0u32; len.words]);
            let mut ring = vec![vol.data[0]; SliceStreamer::<T, Mesh>::ring_len(vol.dims)];
            let scratch = Scratch::new(&mut b, &mut w, vol.dims).expect("scratch");
            let mut s = SliceStreamer::new(vol.dims, &params, scratch, &mut ring, Mesh::default())
                .expect("streamer");
            let nxy = vol.dims[0] * vol.dims[1];
            for slice in vol.data.chunks(nxy) {
                s.push(slice).expect("push");
            }
            let (mut streamed, stats) = s.finish().expect("finish");
            streamed.stats = stats;
            assert!(
                bits(&streamed) == bits(&base),
                "{what} {mode:?}: streaming differs"
            );
            // No allocation: caller's scratch and sink.
            let (mut b, mut w) = (vec![0u8; len.bytes], vec![0u32; len.words]);
            let mut into = Mesh::default();
            into.stats = extract_into(
                &v,
                &params,
                Scratch::new(&mut b, &mut w, vol.dims).expect("scratch"),
                &mut into,
            )
            .expect("extract_into");
            assert!(
                bits(&into) == bits(&base),
                "{what} {mode:?}: extract_into differs"
            );
        }
    }
}

#[test]
fn thread_count_streaming_and_scratch_do_not_change_the_mesh() {
    all_entry_points_agree(&volumes::demo(demo::knot(64)), "knot");
    all_entry_points_agree(&volumes::demo(demo::sphere_noise(40)), "sphere_noise");
    all_entry_points_agree(&integer_noise([20, 17, 33], 3, 1), "integer ties");
    all_entry_points_agree(&brainsmall_crop(), "brainsmall crop");
    all_entry_points_agree(&stent_crop(250.0), "stent crop");
    all_entry_points_agree(&half_huge(), "half at 1e25");
    // Fewer layers than threads, and a single layer.
    all_entry_points_agree(&integer_noise([9, 9, 3], 3, 2), "3 slices");
    all_entry_points_agree(&integer_noise([9, 9, 2], 3, 3), "2 slices");
}

/// The noisy sphere with level 0, its samples for `x` below the middle scaled by 1e25: the same
/// surface, whose gradients there have squared lengths past `f32`'s range. Those normals come in
/// `f64`, already of unit length, among the others that sinks which keep their normals scale a
/// layer at a time (`Sink::edge_vertex_toward`), so every entry point's mesh must still agree,
/// and every normal must have unit length.
fn half_huge() -> Vol<f64> {
    let mut vol = volumes::demo(demo::sphere_noise(40));
    let nx = vol.dims[0];
    for (i, v) in vol.data.iter_mut().enumerate() {
        *v = (*v - vol.iso) * if i % nx < nx / 2 { 1e25 } else { 1.0 };
    }
    vol.iso = 0.0;
    let params = Params {
        normals: true,
        ..vol.params(Mode::Embedded)
    };
    let mesh = extract(&Volume::new(&vol.data, vol.dims).expect("valid"), &params).expect("mesh");
    for n in &mesh.normals {
        let length = n.iter().map(|c| f64::from(*c).powi(2)).sum::<f64>().sqrt();
        assert!((length - 1.0).abs() < 1e-6, "{n:?}");
    }
    vol
}

/// Records each vertex's grid edge and value, as the sweep hands them over.
#[derive(Default)]
struct EdgeValues {
    edges: Vec<([usize; 3], usize)>,
    values: Vec<f32>,
}

impl sc_runtime::Sink for EdgeValues {
    fn vertex(&mut self, _: [f32; 3], _: Option<[f32; 3]>) {
        unreachable!("the sweep names every vertex's edge")
    }
    fn edge_vertex(&mut self, lower: [usize; 3], axis: usize, _: [f32; 3], _: Option<[f32; 3]>) {
        self.edges.push((lower, axis));
    }
    fn vertex_value(&mut self, value: f32) {
        assert_eq!(
            self.values.len() + 1,
            self.edges.len(),
            "one value per vertex"
        );
        self.values.push(value);
    }
    fn triangle(&mut self, _: [u32; 3]) {}
}

/// `Params::values`: each vertex's value is the larger of the samples at its edge's ends, and
/// NaN where either end is NaN (as NumPy's `maximum`), in every mode, for integer ties and for
/// floats with NaN holes.
#[test]
fn values_are_the_larger_sample_of_each_vertex_edge() {
    fn check<T: Sample>(vol: &Vol<T>, what: &str) {
        let at = |p: [usize; 3]| vol.data[p[0] + vol.dims[0] * (p[1] + vol.dims[1] * p[2])];
        for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
            let params = Params {
                values: true,
                ..vol.params(mode)
            };
            let v = Volume::new(&vol.data, vol.dims).expect("valid");
            let len = Scratch::len(vol.dims).expect("len");
            let (mut b, mut w) = (vec![0u8; len.bytes], vec![0u32; len.words]);
            let scratch = Scratch::new(&mut b, &mut w, vol.dims).expect("scratch");
            let mut sink = EdgeValues::default();
            extract_into(&v, &params, scratch, &mut sink).expect("extract_into");
            assert!(!sink.edges.is_empty(), "{what}: empty");
            assert_eq!(sink.values.len(), sink.edges.len(), "{what} {mode:?}");
            for (&(lower, axis), &value) in sink.edges.iter().zip(&sink.values) {
                let mut upper = lower;
                upper[axis] += 1;
                let (a, b) = (at(lower).as_f64(), at(upper).as_f64());
                let want = if a.is_nan() || b.is_nan() {
                    f64::NAN
                } else {
                    a.max(b)
                };
                assert_eq!(
                    value.to_bits(),
                    (want as f32).to_bits(),
                    "{what} {mode:?}: edge {lower:?} along {axis}"
                );
            }
        }
    }
    check(&integer_noise([20, 17, 33], 3, 1), "integer ties");
    check(&stent_crop(250.0), "stent crop");
    let mut holes = volumes::demo(demo::sphere_noise(24));
    for i in (0..holes.data.len()).step_by(97) {
        holes.data[i] = f64::NAN;
    }
    check(&holes, "sphere with NaN holes");
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let data = vec![0u8; 26];
    assert!(matches!(
        Volume::new(&data, [3, 3, 3]),
        Err(Error::DataLength {
            expected: 27,
            actual: 26
        })
    ));
    assert!(matches!(
        Volume::new(&data, [usize::MAX, 2, 1]),
        Err(Error::DimsOverflow(_))
    ));
    assert!(matches!(
        Volume::new(&data, [1 << 40, 1 << 40, 1]),
        Err(Error::DimsOverflow(_))
    ));
    assert!(Scratch::len([usize::MAX, 3, 1]).is_err());
    // Scratch too small.
    let (mut b, mut w) = (vec![0u8; 1], vec![0u32; 1]);
    assert!(matches!(
        Scratch::new(&mut b, &mut w, [8, 8, 8]),
        Err(Error::ScratchTooSmall)
    ));
    // Streaming: wrong slice length, too many slices, finishing early.
    let dims = [4, 4, 3];
    let len = Scratch::len(dims).expect("len");
    let params = Params::new(0.5);
    with_streamer(dims, &params, |mut s| {
        assert!(matches!(s.push(&[0.0; 15]), Err(Error::SliceLength { .. })));
        s.push(&[1.0; 16]).expect("slice 0");
        for _ in 0..2 {
            s.push(&[0.0; 16]).expect("slices 1, 2");
        }
        assert_eq!(
            s.push(&[0.0; 16]),
            Err(Error::TooManySlices { nz: 3 }),
            "a fourth slice of three"
        );
        let (mesh, stats) = s.finish().expect("finish");
        assert_eq!(mesh.triangles.len() as u64, stats.triangles);
    });
    with_streamer(dims, &params, |mut s| {
        s.push(&[0.0; 16]).expect("slice 0");
        assert!(s.finish().is_err(), "finishing after 1 of 3 slices");
    });
    let mut short_ring = vec![0f32; 3];
    let (mut b, mut w) = (vec![0u8; len.bytes], vec![0u32; len.words]);
    assert!(matches!(
        SliceStreamer::new(
            dims,
            &params,
            Scratch::new(&mut b, &mut w, dims).expect("scratch"),
            &mut short_ring,
            Mesh::default()
        ),
        Err(Error::ScratchTooSmall)
    ));
}

/// Dims below 2 on any axis have no cube: an empty mesh and zero counts, from every entry point.
#[test]
fn grids_without_cubes_give_empty_meshes() {
    for dims in [
        [0, 0, 0],
        [1, 5, 5],
        [5, 1, 5],
        [5, 5, 1],
        [1, 1, 1],
        [0, 4, 4],
        [2, 2, 1],
    ] {
        let n: usize = dims.iter().product();
        let data: Vec<f32> = (0..n).map(|i| (i % 2) as f32).collect();
        let v = Volume::new(&data, dims).expect("valid");
        let params = Params::new(0.5);
        let m = extract(&v, &params).expect("extract");
        assert_eq!(m, Mesh::default(), "{dims:?}");
        assert_eq!(
            extract_par(&v, &params, 2, &|_| {}).expect("par"),
            Mesh::default()
        );
    }
}

/// A constant volume has no surface at any iso, in any mode, whatever the type.
#[test]
fn constant_volumes_are_empty() {
    fn check<T: Sample>(value: T, isos: &[f64]) {
        let data = vec![value; 6 * 5 * 4];
        for &iso in isos {
            for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
                let vol = Vol::new(data.clone(), [6, 5, 4], iso);
                let m = vol.extract(mode);
                assert!(
                    m.triangles.is_empty() && m.positions.is_empty(),
                    "{value:?} iso {iso}"
                );
                assert_eq!(m.stats, Stats::default());
            }
        }
    }
    check(7u8, &[0.0, 7.0, 7.5, 255.0]);
    check(-3i8, &[-3.0, -2.5, 100.0]);
    check(1000u16, &[1000.0, 1e9]);
    check(-5i16, &[-5.0, 0.0]);
    check(u32::MAX, &[4294967295.0, 1.0]);
    check(i32::MIN, &[-2147483648.0, 0.0]);
    check(0.25f32, &[0.25, 0.3, -1.0]);
    check(f64::NAN, &[0.0, f64::NEG_INFINITY]);
}

/// Runs `f` on a fresh f32 streamer over `dims`, with scratch and ring buffers lent for the call.
fn with_streamer(dims: [usize; 3], params: &Params, f: impl FnOnce(SliceStreamer<'_, f32, Mesh>)) {
    let len = Scratch::len(dims).expect("len");
    let (mut b, mut w) = (vec![0u8; len.bytes], vec![0u32; len.words]);
    let mut ring = vec![0f32; SliceStreamer::<f32, Mesh>::ring_len(dims)];
    let scratch = Scratch::new(&mut b, &mut w, dims).expect("scratch");
    f(SliceStreamer::new(dims, params, scratch, &mut ring, Mesh::default()).expect("streamer"));
}
