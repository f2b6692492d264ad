use sc_runtime::{Mode, Params, Volume, demo, extract, extract_par};
fn main() {
    let k = demo::knot(64);
    let vol = Volume::new(&k.data, k.dims).unwrap();
    for mode in [Mode::Steps123, Mode::Paper, Mode::Embedded] {
        let p = Params {
            mode,
            spacing: k.spacing,
            origin: k.origin,
            ..Params::new(k.iso)
        };
        let m = extract(&vol, &p).unwrap();
        let m2 = extract_par(&vol, &p, 2, &|_| {}).unwrap();
        println!("{mode:?}: {:?} par_eq={}", m.stats, m == m2);
    }
}
