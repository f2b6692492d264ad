//! The mesh writers' own cost: each format, with and without normals, encoding the embedded mesh
//! of the built-in 256³ sphere (296 k triangles) into memory, so that the disk is left out.
//!
//! ```sh
//! cargo bench -p sc-io --bench write
//! ```

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use sc_io::write::{MeshFormat, WriteOptions};
use sc_runtime::{Params, Volume, demo, extract};

fn writers(c: &mut Criterion) {
    let v = demo::sphere(256);
    let volume = Volume::new(&v.data, v.dims).expect("the demo volume is consistent");
    let mut group = c.benchmark_group("write");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2));
    for normals in [false, true] {
        let params = Params {
            normals,
            ..Params::new(v.iso)
        };
        let mesh = extract(&volume, &params).expect("the sphere meshes");
        let formats = [
            (MeshFormat::Ply, false, "ply"),
            (MeshFormat::Ply, true, "ply-ascii"),
            (MeshFormat::Obj, false, "obj"),
            (MeshFormat::Stl, false, "stl"),
            (MeshFormat::Glb, false, "glb"),
        ];
        for (format, ascii, name) in formats {
            let options = WriteOptions {
                ascii,
                ..WriteOptions::default()
            };
            let mut out = Vec::new();
            format
                .write(&mesh, &options, &mut out)
                .expect("writing to memory succeeds");
            group.throughput(Throughput::Bytes(out.len() as u64));
            let id = BenchmarkId::new(name, if normals { "normals" } else { "no-normals" });
            group.bench_function(id, |b| {
                b.iter(|| {
                    out.clear();
                    format
                        .write(&mesh, &options, &mut out)
                        .expect("writing to memory succeeds");
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, writers);
criterion_main!(benches);
