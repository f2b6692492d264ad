//! Label tables read from the real files in `tests/data/labels` (see its README), and the label
//! mesh writers read back.

use std::path::{Path, PathBuf};

use sc_io::labels::{Label, LabelTable, file_stem, tables_beside};
use sc_io::write::{LabelFiles, LabelMesh, MeshFormat, MeshSlices, WriteOptions, write_atlas};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/labels")
        .join(name)
}

fn label(name: &str, rgb: Option<[u8; 3]>) -> Label {
    Label {
        name: name.into(),
        rgb,
    }
}

/// MRIcron's AAL names: 116 regions, `id name code` with CRLF line ends and a blank last line;
/// the code is not part of the name.
#[test]
fn mricron_names_aal() {
    let t = LabelTable::read(&data("aal-crop-24x24x16.u8.txt")).unwrap();
    assert_eq!(t.len(), 116);
    assert_eq!(
        t.iter().map(|(id, _)| id).collect::<Vec<_>>(),
        (1..=116).collect::<Vec<_>>()
    );
    assert_eq!(t.get(1), Some(&label("Precentral_L", None)));
    assert_eq!(t.get(73), Some(&label("Putamen_L", None)));
    assert_eq!(t.get(116), Some(&label("Vermis_10", None)));
    assert_eq!(t.get(0), None);
}

/// MRIcron's JHU names: tab-separated, with label 0 named.
#[test]
fn mricron_names_jhu() {
    let t = LabelTable::read(&data("JHU-WhiteMatter-labels-1mm.nii.txt")).unwrap();
    assert_eq!(t.len(), 49);
    assert_eq!(t.get(0), Some(&label("Unclassified", None)));
    assert_eq!(
        t.get(2),
        Some(&label("Pontine_crossing_tract_(a_part_of_MCP)", None))
    );
    assert_eq!(t.get(48), Some(&label("Tapetum_L", None)));
}

/// MRIcron's palette: planar (256 reds, then greens, then blues). Left and right regions of
/// AAL (odd and even ids) share a colour in it, which only the planar reading gives: read as
/// interleaved triples, colours 1 and 2 would differ.
#[test]
fn mricron_palette() {
    let path = data("aal-crop-24x24x16.u8.lut");
    let bytes = std::fs::read(&path).unwrap();
    let t = LabelTable::read(&path).unwrap();
    assert_eq!(t.len(), 256);
    for (id, l) in t.iter() {
        let i = id as usize;
        assert_eq!(l.rgb, Some([bytes[i], bytes[256 + i], bytes[512 + i]]));
        assert!(l.name.is_empty());
    }
    assert_eq!(t.get(0).unwrap().rgb, Some([255, 255, 255]));
    assert_eq!(t.get(1).unwrap().rgb, Some([204, 204, 204]));
    // 1 to 108: the regions with a left and a right (109 to 116 are the vermis).
    for pair in (1..108).step_by(2) {
        assert_eq!(
            t.get(pair).unwrap().rgb,
            t.get(pair + 1).unwrap().rgb,
            "{pair}"
        );
    }
}

/// FreeSurfer's table: 1,266 labels, the largest id 14175.
#[test]
fn freesurfer_lut() {
    let t = LabelTable::read(&data("FreeSurferColorLUT.txt")).unwrap();
    assert_eq!(t.len(), 1266);
    assert_eq!(t.get(0), Some(&label("Unknown", Some([0, 0, 0]))));
    assert_eq!(
        t.get(17),
        Some(&label("Left-Hippocampus", Some([220, 216, 20])))
    );
    assert_eq!(t.iter().last().unwrap().0, 14175);
}

#[test]
fn itk_snap_description() {
    let t = LabelTable::read(&data("itksnap-labels.txt")).unwrap();
    assert_eq!(t.len(), 5);
    assert_eq!(t.get(0), Some(&label("Clear Label", Some([0, 0, 0]))));
    assert_eq!(
        t.get(3),
        Some(&label("CSF (ventricles)", Some([0, 0, 255])))
    );
    assert_eq!(t.get(71), Some(&label("Caudate_L", Some([255, 255, 0]))));
}

/// Beside the crop: its names and its palette, merged.
#[test]
fn tables_beside_the_crop_merge() {
    let volume = data("aal-crop-24x24x16.u8.raw");
    let found = tables_beside(&volume);
    assert_eq!(
        found,
        [
            data("aal-crop-24x24x16.u8.txt"),
            data("aal-crop-24x24x16.u8.lut")
        ]
    );
    let beside = LabelTable::beside(&volume);
    assert_eq!(beside.sources, found);
    assert!(beside.unread.is_empty());
    let t = beside.table.unwrap();
    assert_eq!(t.len(), 256);
    assert_eq!(t.get(73), Some(&label("Putamen_L", Some([72, 72, 200]))));
    let lut = LabelTable::read(&data("aal-crop-24x24x16.u8.lut")).unwrap();
    for id in 1..=116 {
        assert_eq!(t.get(id).unwrap().rgb, lut.get(id).unwrap().rgb);
    }
    assert_eq!(t.get(200), Some(&label("", lut.get(200).unwrap().rgb)));
}

/// Files that are not tables: refused with the file's name, the line where there is one, and
/// why; a missing file and a folder likewise.
#[test]
fn hostile_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[u8], &str); 6] = [
        ("empty.txt", b"", "no labels"),
        (
            "junk.txt",
            &[0x7f, 0x45, 0x4c, 0x46, 2, 1, 1, 0, 0, 0],
            "line 1: binary data",
        ),
        (
            "huge.txt",
            b"1 a\n2 b\n340282366920938463463374607431768211456 c\n",
            "line 3: label id 340282366920938463463374607431… is larger",
        ),
        (
            "dup.txt",
            b"# t\n0 Unknown 0 0 0 0\n5 A 1 2 3 0\n5 B 1 2 3 0\n",
            "line 4: label 5 again (first on line 3)",
        ),
        (
            "bad.txt",
            b"1 a\n2 b\nthree c\n",
            "line 3: \"three\" is not a label id",
        ),
        (
            "short.lut",
            &[1, 2, 3],
            "3 bytes: an MRIcron palette (.lut) is 768",
        ),
    ];
    for (name, bytes, want) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = LabelTable::read(&path).unwrap_err().to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
        assert!(err.contains(want), "{name}: {err}");
    }
    let big = dir.path().join("big.txt");
    std::fs::write(&big, vec![b'#'; 17 << 20]).unwrap();
    let err = LabelTable::read(&big).unwrap_err().to_string();
    assert!(err.contains("larger than 16 MiB"), "{err}");
    let err = LabelTable::read(&dir.path().join("none.txt"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("none.txt: no such file"), "{err}");
    assert!(LabelTable::read(dir.path()).is_err());
    // A table beside a volume that does not parse is set aside with its error; one that does
    // is read.
    let volume = dir.path().join("seg.nii.gz");
    std::fs::write(dir.path().join("seg.nii.txt"), "1 a\n1 b\n").unwrap();
    std::fs::write(dir.path().join("seg.txt"), "1 a\n2 b\n").unwrap();
    let beside = LabelTable::beside(&volume);
    assert_eq!(beside.sources, [dir.path().join("seg.txt")]);
    assert_eq!(beside.table.unwrap().len(), 2);
    assert_eq!(beside.unread.len(), 1);
    let err = beside.unread[0].to_string();
    assert!(err.contains("seg.nii.txt: line 2"), "{err}");
}

/// Two tetrahedra over one vertex array (as an atlas's labels share it), one of them wound the
/// other way, and a label without triangles.
struct Fixture {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    a: Vec<[u32; 3]>,
    b: Vec<[u32; 3]>,
    own_positions: Vec<[f32; 3]>,
}

fn fixture() -> Fixture {
    Fixture {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [0.0, 2.25, 0.0],
            [0.0, 0.0, -3.125],
            [4.0, 4.0, 4.0],
        ],
        normals: vec![[0.0, 0.0, 1.0]; 5],
        a: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        b: vec![[1, 2, 4], [2, 1, 3]],
        own_positions: vec![[9.0, 9.0, 9.0], [10.0, 9.0, 9.0], [9.0, 10.0, 9.0]],
    }
}

#[test]
fn atlas_glb_reads_back() {
    let f = fixture();
    let names: LabelTable = [
        (3, label("Left/Right thing", Some([255, 0, 0]))),
        (8, label("", None)),
    ]
    .into_iter()
    .collect();
    let own = [[0, 1, 2]];
    let meshes = [
        LabelMesh {
            id: 3,
            label: names.get(3),
            mesh: MeshSlices {
                positions: &f.positions,
                normals: &f.normals,
                triangles: &f.a,
            },
        },
        LabelMesh {
            id: 8,
            label: names.get(8),
            mesh: MeshSlices {
                positions: &f.positions,
                normals: &f.normals,
                triangles: &f.b,
            },
        },
        LabelMesh {
            id: 1000,
            label: None,
            mesh: MeshSlices {
                positions: &f.own_positions,
                normals: &[],
                triangles: &own,
            },
        },
        LabelMesh {
            id: 9,
            label: None,
            mesh: MeshSlices::default(),
        },
    ];
    let mut bytes = Vec::new();
    write_atlas(&meshes, &WriteOptions::default(), &mut bytes).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    // The shared vertex array is stored once: 5 positions and 5 normals, 3 positions, and the
    // three index arrays.
    assert_eq!(blob.len(), 12 * (5 + 5 + 3) + 12 * (4 + 2 + 1));
    let nodes: Vec<_> = gltf.nodes().collect();
    assert_eq!(nodes.len(), 4);
    // Names and ids, from the JSON chunk itself.
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let node_json = doc["nodes"].as_array().unwrap();
    let names: Vec<&str> = node_json
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["Left/Right thing", "label-8", "label-1000", "label-9"]
    );
    let ids: Vec<u64> = node_json
        .iter()
        .map(|n| n["extras"]["label"].as_u64().unwrap())
        .collect();
    assert_eq!(ids, [3, 8, 1000, 9]);
    assert!(nodes[3].mesh().is_none());
    for (node, m) in nodes.iter().zip(&meshes[..3]) {
        let (positions, triangles) = (m.mesh.positions, m.mesh.triangles);
        let normals = !m.mesh.normals.is_empty();
        let primitive = node.mesh().unwrap().primitives().next().unwrap();
        let reader = primitive.reader(|_| Some(&blob));
        assert_eq!(
            reader.read_positions().unwrap().collect::<Vec<_>>(),
            positions
        );
        assert_eq!(reader.read_normals().is_some(), normals);
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(
            indices,
            triangles.iter().flatten().copied().collect::<Vec<_>>()
        );
    }
    // Colours: the table's red, as a linear factor; the unnamed labels get the default palette,
    // also converted, so different labels differ.
    let colour = |i: usize| {
        nodes[i]
            .mesh()
            .unwrap()
            .primitives()
            .next()
            .unwrap()
            .material()
            .pbr_metallic_roughness()
            .base_color_factor()
    };
    assert_eq!(colour(0), [1.0, 0.0, 0.0, 1.0]);
    let linear = |c: u8| {
        let c = f64::from(c) / 255.0;
        let l = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        ((l * 1e4).round() / 1e4) as f32
    };
    let rgb = sc_io::labels::default_rgb(8).map(linear);
    assert_eq!(colour(1), [rgb[0], rgb[1], rgb[2], 1.0]);
    assert_ne!(colour(1), colour(2));
}

#[test]
fn an_empty_atlas_is_a_valid_file() {
    let mut bytes = Vec::new();
    write_atlas(&[], &WriteOptions::default(), &mut bytes).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    assert_eq!(gltf.nodes().count(), 0);
    assert!(gltf.blob.is_none());
}

/// A written mesh's positions and triangles: through `mesh_in`, or the `gltf` crate for `.glb`.
fn read_back(path: &Path) -> sc_io::mesh_in::TriangleMesh {
    if path.extension().is_some_and(|e| e == "glb") {
        let bytes = std::fs::read(path).unwrap();
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = gltf.blob.clone().unwrap();
        let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
        let reader = primitive.reader(|_| Some(&blob));
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        sc_io::mesh_in::TriangleMesh {
            positions: reader.read_positions().unwrap().collect(),
            triangles: indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect(),
        }
    } else {
        sc_io::mesh_in::read(path).unwrap()
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A file per label, named from the table, each reading back as its label's mesh; nothing in
/// place before the commit; an existing directory's other files left alone.
#[test]
fn label_files_read_back() {
    let f = fixture();
    let table = LabelTable::read(&data("itksnap-labels.txt")).unwrap();
    let meshes = [
        LabelMesh {
            id: 3,
            label: table.get(3),
            mesh: MeshSlices {
                positions: &f.positions,
                normals: &f.normals,
                triangles: &f.a,
            },
        },
        LabelMesh {
            id: 77,
            label: table.get(77),
            mesh: MeshSlices {
                positions: &f.positions,
                normals: &f.normals,
                triangles: &f.b,
            },
        },
    ];
    let parent = tempfile::tempdir().unwrap();
    let dir = parent.path().join("out");
    for format in [
        MeshFormat::Ply,
        MeshFormat::Obj,
        MeshFormat::Stl,
        MeshFormat::Glb,
    ] {
        let files = LabelFiles::fill(&dir, &meshes, format, &WriteOptions::default()).unwrap();
        let ext = match format {
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
            MeshFormat::Stl => "stl",
            MeshFormat::Glb => "glb",
        };
        let want = [
            format!("3-CSF_(ventricles).{ext}"),
            format!("label-77.{ext}"),
        ];
        assert_eq!(
            files.paths().map(|p| p.to_path_buf()).collect::<Vec<_>>(),
            want.iter().map(|n| dir.join(n)).collect::<Vec<_>>()
        );
        assert!(
            entries(&dir).iter().all(|e| !want.contains(e)),
            "renamed before the commit"
        );
        let written = files.commit().unwrap();
        for (path, m) in written.iter().zip(&meshes) {
            let back = read_back(path);
            assert_eq!(
                back.triangles.len(),
                m.mesh.triangles.len(),
                "{}",
                path.display()
            );
            // Every triangle's corners are where the label's triangle puts them.
            for (t, want) in back.triangles.iter().zip(m.mesh.triangles) {
                for k in 0..3 {
                    assert_eq!(
                        back.positions[t[k] as usize],
                        m.mesh.positions[want[k] as usize]
                    );
                }
            }
        }
    }
    assert_eq!(entries(&dir).len(), 8);
    assert!(entries(&dir).iter().all(|e| !e.ends_with(".tmp")));
}

/// A failure leaves no file of the set and no temporary file; a directory made for the set is
/// removed again; a missing parent, or a file where the directory should be, is refused.
#[test]
fn label_files_all_or_nothing() {
    let f = fixture();
    let parent = tempfile::tempdir().unwrap();
    let dir = parent.path().join("made");
    let meshes = [LabelMesh {
        id: 1,
        label: None,
        mesh: MeshSlices {
            positions: &f.positions,
            normals: &f.normals,
            triangles: &f.a,
        },
    }];
    let files = LabelFiles::fill(&dir, &meshes, MeshFormat::Ply, &WriteOptions::default()).unwrap();
    assert_eq!(entries(&dir).len(), 1); // the temporary file
    drop(files);
    assert!(!dir.exists());

    let err = LabelFiles::fill(
        &parent.path().join("no/such"),
        &meshes,
        MeshFormat::Ply,
        &WriteOptions::default(),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("parent does not exist"), "{err}");
    let file = parent.path().join("file");
    std::fs::write(&file, b"x").unwrap();
    let err = LabelFiles::fill(&file, &meshes, MeshFormat::Ply, &WriteOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("is not a directory"), "{err}");

    // The second label's file cannot be made (a directory has its name): the first's temporary
    // file is removed, and the directory made for the set with it.
    let dir = parent.path().join("set");
    std::fs::create_dir(&dir).unwrap();
    std::fs::create_dir(dir.join(format!("{}.ply", file_stem(2, "")))).unwrap();
    let two = [meshes[0], LabelMesh { id: 2, ..meshes[0] }];
    assert!(LabelFiles::fill(&dir, &two, MeshFormat::Ply, &WriteOptions::default()).is_err());
    assert_eq!(entries(&dir), ["label-2.ply"]);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    fn read_bytes(name: &str, bytes: &[u8]) -> sc_io::Result<LabelTable> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        LabelTable::read(&path)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// Any bytes: a table or an error naming the file, never a panic.
        #[test]
        fn any_bytes_read_or_refused(bytes in proptest::collection::vec(any::<u8>(), 0..2000), lut in any::<bool>()) {
            let name = if lut { "t.lut" } else { "t.txt" };
            if let Err(e) = read_bytes(name, &bytes) {
                prop_assert!(e.to_string().contains(name));
            }
        }

        /// Labels written in each text format read back as written.
        #[test]
        fn each_format_round_trips(
            labels in proptest::collection::btree_map(
                any::<u64>(),
                ("[A-Za-z][A-Za-z0-9_()-]{0,20}", any::<[u8; 3]>()),
                1..40,
            ),
        ) {
            let mut itk = String::from("# ITK-SnAP Label Description File\n");
            let mut fs = String::from("#No. Label Name: R G B A\r\n\r\n");
            let mut names = String::new();
            for (id, (name, [r, g, b])) in &labels {
                itk.push_str(&format!("{id:>5} {r:>5} {g:>4} {b:>4}        1  1  1    \"{name} x\"\n"));
                fs.push_str(&format!("{id:<4} {name:<40}{r:<4}{g:<4}{b:<4}0\r\n"));
                names.push_str(&format!("{id}\t{name} y\r\n"));
            }
            let read = |text: &str| read_bytes("t.txt", text.as_bytes()).unwrap();
            let want = |suffix: &str, coloured: bool| -> LabelTable {
                labels
                    .iter()
                    .map(|(&id, (name, rgb))| {
                        (id, label(&format!("{name}{suffix}"), coloured.then_some(*rgb)))
                    })
                    .collect()
            };
            prop_assert_eq!(read(&itk), want(" x", true));
            prop_assert_eq!(read(&fs), want("", true));
            prop_assert_eq!(read(&names), want(" y", false));
        }
    }
}
