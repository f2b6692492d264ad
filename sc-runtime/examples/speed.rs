use sc_runtime::{Mode, Params, Volume, extract};
fn main() {
    let raw = std::fs::read("/work/shared/data/mni152-mri/mni152-mri.raw").unwrap();
    let mni = Volume::new(&raw, [197, 233, 189]).unwrap();
    for mode in [Mode::Steps123, Mode::Embedded] {
        for normals in [false, true] {
            let p = Params {
                mode,
                normals,
                ..Params::new(80.0)
            };
            let mut ts = vec![];
            for _ in 0..15 {
                let t = std::time::Instant::now();
                let m = extract(&mni, &p).unwrap();
                ts.push(t.elapsed());
                std::hint::black_box(m);
            }
            ts.sort();
            println!("mni {mode:?} normals={normals}: median {:?}", ts[7]);
        }
    }
}
