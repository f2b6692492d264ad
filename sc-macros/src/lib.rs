//! `include_tables!`: compiles a Skeleton Climbing RON table set into `static` arrays.
//!
//! The RON is parsed and validated (every check of `sc_tablegen::validate`, geometric embedding
//! included) while the crate compiles, so the runtime never parses, allocates or lazily builds a
//! table, and a broken table is a compile error naming the file, the entry and the problem.
//!
//! ```text
//! // The committed tables, relative to the invoking crate's Cargo.toml:
//! static TABLES: sc_runtime::tables::CaseTables = sc_macros::include_tables!("../tables/skeleton-climbing.ron");
//! // Tables a build script wrote into OUT_DIR:
//! static MINE: sc_runtime::tables::CaseTables = sc_macros::include_tables!(out_dir "my-tables.ron");
//! ```

use std::path::PathBuf;

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::quote;
use sc_tablegen::cube::Face;
use sc_tablegen::{Grey, TableSet};
use syn::parse::{Parse, ParseStream};
use syn::{Ident, LitStr};

/// Where the RON file lives: relative to `CARGO_MANIFEST_DIR`, or with `out_dir`, to `OUT_DIR`.
struct Input {
    base_var: &'static str,
    path: LitStr,
}

impl Parse for Input {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        if input.peek(Ident) {
            let kw: Ident = input.parse()?;
            if kw != "out_dir" {
                return Err(syn::Error::new(
                    kw.span(),
                    "expected `out_dir \"file.ron\"` or a path string",
                ));
            }
            return Ok(Input {
                base_var: "OUT_DIR",
                path: input.parse()?,
            });
        }
        Ok(Input {
            base_var: "CARGO_MANIFEST_DIR",
            path: input.parse()?,
        })
    }
}

/// Expands to a `sc_runtime::tables::CaseTables` constant expression built from a RON file.
#[proc_macro]
pub fn include_tables(input: TokenStream) -> TokenStream {
    include_tables_tokens(input.into()).into()
}

/// The macro on `proc_macro2` tokens, so tests can check its output, errors included.
fn include_tables_tokens(input: Tokens) -> Tokens {
    let input: Input = match syn::parse2(input) {
        Ok(i) => i,
        Err(e) => return e.to_compile_error(),
    };
    match expand(&input) {
        Ok(tokens) => tokens,
        Err(msg) => syn::Error::new(input.path.span(), msg).to_compile_error(),
    }
}

fn expand(input: &Input) -> Result<Tokens, String> {
    let base = std::env::var(input.base_var).map_err(|_| {
        format!(
            "{} is not set; `out_dir` needs a build script",
            input.base_var
        )
    })?;
    let path = PathBuf::from(base).join(input.path.value());
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read tables file {shown}: {e}"))?;
    let set = TableSet::from_ron(&text).map_err(|e| format!("{shown}: malformed tables: {e}"))?;
    check_shape(&set).map_err(|e| format!("{shown}: {e}"))?;
    if let Err(errors) = sc_tablegen::validate(&set) {
        let first: Vec<String> = errors.iter().take(5).map(ToString::to_string).collect();
        return Err(format!(
            "{shown}: {} invalid entries: {}",
            errors.len(),
            first.join("; ")
        ));
    }
    let entries = || set.classes.iter().flat_map(|c| &c.cases).enumerate();
    let embedded = entries().map(|(n, e)| packed(n / 256, &e.triangles, &e.grey));
    let paper = entries().map(|(n, e)| match &e.paper {
        Some(p) => packed(n / 256, &p.triangles, &p.grey),
        None => packed(n / 256, &e.triangles, &e.grey),
    });
    let embedded: Vec<Tokens> = embedded.collect::<Result<_, _>>()?;
    let paper: Vec<Tokens> = paper.collect::<Result<_, _>>()?;
    // One byte per entry, so the merge decision reads 2 KiB rather than the whole table.
    let mergeable = set.classes.iter().flat_map(|c| &c.cases).map(|e| {
        e.grey
            .iter()
            .filter(|g| g.mergeable)
            .fold(0u8, |m, g| m | 1 << (g.edge / 4))
    });
    Ok(quote! {{
        // Makes the compiler rebuild this crate when the tables file changes.
        const _: &[u8] = include_bytes!(#shown);
        static EMBEDDED: [::sc_runtime::tables::Entry; 2048] = [#(#embedded),*];
        static PAPER: [::sc_runtime::tables::Entry; 2048] = [#(#paper),*];
        static MERGEABLE: [u8; 2048] = [#(#mergeable),*];
        ::sc_runtime::tables::CaseTables::from_static(&EMBEDDED, &PAPER, &MERGEABLE)
    }})
}

/// The checks whose failure would make the packed arrays themselves wrong, with messages that
/// name the entry; `validate` then checks the geometry and topology.
fn check_shape(set: &TableSet) -> Result<(), String> {
    if set.classes.len() != 8 {
        return Err(format!("{} classes, expected 8", set.classes.len()));
    }
    for (p, class) in set.classes.iter().enumerate() {
        if class.cases.len() != 256 {
            return Err(format!(
                "class {p} has {} entries, expected 256",
                class.cases.len()
            ));
        }
        for (case, e) in class.cases.iter().enumerate() {
            let at = format!("class {p} case {case}");
            let all = std::iter::once(e.triangles.as_slice())
                .chain(e.paper.as_ref().map(|p| p.triangles.as_slice()));
            for tris in all {
                if tris.len() > 5 {
                    return Err(format!(
                        "{at}: {} triangles, at most 5 fit in a cube",
                        tris.len()
                    ));
                }
                if let Some(bad) = tris.iter().flatten().find(|&&x| x > 11) {
                    return Err(format!("{at}: edge id {bad} > 11"));
                }
            }
        }
    }
    Ok(())
}

/// One runtime `Entry` of class `class`: triangles padded to five, ears rotated to
/// `[back, grey, forward]`.
fn packed(class: usize, triangles: &[[u8; 3]], grey: &[Grey]) -> Result<Tokens, String> {
    let mut tris = [[0u8; 3]; 5];
    tris[..triangles.len()].copy_from_slice(triangles);
    let mut ears = [NO_EAR; 3];
    let mut mergeable = 0u8;
    for g in grey {
        let axis = usize::from(g.edge / 4);
        if let Some(i) = g.ear {
            let t = &mut tris[usize::from(i)];
            *t = ear(*t, g.edge);
            ears[axis] = i;
        }
        mergeable |= u8::from(g.mergeable) << axis;
    }
    let count = triangles.len() as u8;
    let all = ((1u16 << count) - 1) as u8;
    let kept = (0..8u8).map(|merged| {
        (0..3)
            .filter(|&axis| merged >> axis & 1 == 1 && ears[axis] != NO_EAR)
            .fold(all, |k, axis| k & !(1 << ears[axis]))
    });
    let mut merge = [0u8; 3];
    let mut owned_ears = 0u8;
    for axis in 0..3 {
        if ears[axis] != NO_EAR {
            let (byte, owner) = merge_byte(class, axis, tris[usize::from(ears[axis])])
                .ok_or_else(|| format!("class {class}: the ear of grey axis {axis} does not cross the faces of its edge"))?;
            merge[axis] = byte;
            owned_ears |= u8::from(owner) << axis;
        }
    }
    let tris = tris.iter().map(|[a, b, c]| quote!([#a, #b, #c]));
    Ok(quote! {
        ::sc_runtime::tables::Entry {
            tris: [#(#tris),*],
            count: #count,
            ears: [#(#ears),*],
            mergeable: #mergeable,
            owned_ears: #owned_ears,
            kept: [#(#kept),*],
            merge: [#(#merge),*],
        }
    })
}

/// `Entry::merge` for the ear `[back, grey, forward]` of a grey edge along `axis` in a cube of
/// class `class`: the ear's outer vertices lie one on each of the cube's two faces through the
/// grey edge, and one of those faces is shared with the merge partner, the neighbour along the
/// pairing axis (y for x-greys, x for y-greys, y or x for z-greys in even or odd layers). The
/// grey edge lies on the cube's high face there if the cube owns the pair, on its low face if it
/// is the partner. With the byte, whether the cube owns the pair. `None` if the outer vertices do
/// not lie one on each face.
fn merge_byte(class: usize, axis: usize, [back, grey, forward]: [u8; 3]) -> Option<(u8, bool)> {
    let face = |side: u8| Face {
        axis: pairing(class, axis),
        side,
    };
    let side = u8::from(face(1).contains_edge(grey));
    let (back_on, forward_on) = (
        face(side).contains_edge(back),
        face(side).contains_edge(forward),
    );
    if back_on == forward_on {
        return None;
    }
    Some(if side == 1 {
        // The owner: which of its outer vertices is the shared one.
        (if back_on { BACK_SHARED } else { 0 }, true)
    } else {
        // The partner: the outer vertex off the shared face.
        (if back_on { forward } else { back }, false)
    })
}

/// The ear triangle `t` of grey edge `grey` rotated to `[back, grey, forward]`.
fn ear(mut t: [u8; 3], grey: u8) -> [u8; 3] {
    while t[1] != grey {
        t.rotate_left(1);
    }
    t
}

/// The axis along which a cube of class `class` pairs with its merge partner for the grey edge
/// along `axis`: y for x-greys, x for y-greys, y or x for z-greys in even or odd layers.
fn pairing(class: usize, axis: usize) -> usize {
    let z_layer_odd = class >> 2 & 1 == 1;
    if axis == 0 || axis == 2 && !z_layer_odd {
        1
    } else {
        0
    }
}

/// Mirrors `sc_runtime::tables::NO_EAR` (the macro cannot depend on the runtime it feeds).
const NO_EAR: u8 = 0xFF;

/// Mirrors `sc_runtime::tables::BACK_SHARED`.
const BACK_SHARED: u8 = 1 << 4;

#[cfg(test)]
mod tests {
    use super::*;

    fn committed() -> TableSet {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tables/skeleton-climbing.ron"
        );
        TableSet::from_ron(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// Expands the macro on a RON text written to a temporary file; returns the output tokens
    /// as a string and the file's path.
    fn expand_text(name: &str, ron: &str) -> (String, String) {
        let dir = std::env::temp_dir().join(format!("sc-macros-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, ron).unwrap();
        let shown = path.display().to_string();
        let out = include_tables_tokens(quote!(#shown)).to_string();
        (out, shown)
    }

    /// The macro must give a `compile_error!` that names the file, the entry and the problem.
    fn assert_compile_error(out: &str, needles: &[&str]) {
        assert!(
            out.contains("compile_error"),
            "expected compile_error!, got: {}",
            &out[..out.len().min(300)]
        );
        for n in needles {
            assert!(out.contains(n), "message lacks {n:?}: {out}");
        }
    }

    #[test]
    fn committed_tables_expand_to_static_arrays() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tables/skeleton-climbing.ron"
        );
        let out = include_tables_tokens(quote!(#path)).to_string();
        assert!(!out.contains("compile_error"));
        assert!(
            out.contains("static EMBEDDED")
                && out.contains("static PAPER")
                && out.contains("include_bytes")
        );
        assert_eq!(out.matches("Entry {").count(), 4096);
    }

    /// Ownership is a property of a cube's class and the grey axis, and of the two cubes a merged
    /// pair joins (neighbours along the pairing axis, whose classes differ in that axis's bit),
    /// exactly one owns it: the triangle pass emits each merged triangle once.
    #[test]
    fn one_owner_per_merged_pair() {
        let set = committed();
        let mut owner: [[Option<bool>; 3]; 8] = [[None; 3]; 8];
        for (class, entries) in set.classes.iter().enumerate() {
            for entry in &entries.cases {
                for g in &entry.grey {
                    let Some(i) = g.ear else { continue };
                    let axis = usize::from(g.edge / 4);
                    let ear = ear(entry.triangles[usize::from(i)], g.edge);
                    let (_, owns) = merge_byte(class, axis, ear).unwrap();
                    let seen = owner[class][axis].get_or_insert(owns);
                    assert_eq!(*seen, owns, "class {class} axis {axis}");
                }
            }
        }
        for (class, axes) in owner.iter().enumerate() {
            for (axis, &owns) in axes.iter().enumerate() {
                // The partner's class differs in the pairing axis's parity bit.
                let partner = class ^ 1 << pairing(class, axis);
                let pair = (owns, owner[partner][axis]);
                let (Some(a), Some(b)) = pair else {
                    panic!("class {class} axis {axis}: no ear in the tables")
                };
                assert_ne!(a, b, "class {class} axis {axis}");
            }
        }
    }

    #[test]
    fn wrong_entry_count_names_the_class() {
        let mut set = committed();
        set.classes[3].cases.pop();
        let (out, file) = expand_text("short.ron", &set.to_ron());
        assert_compile_error(&out, &[&file, "class 3", "255 entries"]);
    }

    #[test]
    fn edge_id_over_eleven_names_the_entry() {
        let mut set = committed();
        set.classes[2].cases[7].triangles[0][1] = 12;
        let (out, file) = expand_text("edge.ron", &set.to_ron());
        assert_compile_error(&out, &[&file, "class 2 case 7", "edge id 12 > 11"]);
    }

    #[test]
    fn too_many_triangles_names_the_entry() {
        let mut set = committed();
        let extra = set.classes[0].cases[254].triangles[0];
        set.classes[0].cases[254].triangles.extend([extra; 5]);
        let (out, file) = expand_text("many.ron", &set.to_ron());
        assert_compile_error(&out, &[&file, "class 0 case 254", "at most 5"]);
    }

    #[test]
    fn inconsistent_triangles_fail_validation() {
        let mut set = committed();
        // Reversing one triangle breaks the face-side orientation check.
        set.classes[5].cases[1].triangles[0].reverse();
        let (out, file) = expand_text("flipped.ron", &set.to_ron());
        assert_compile_error(&out, &[&file, "class 5 case 1", "face side"]);
    }

    #[test]
    fn malformed_ron_and_missing_files_are_errors() {
        let (out, file) = expand_text("broken.ron", "(order: [0, 1,");
        assert_compile_error(&out, &[&file, "malformed tables"]);
        let out = include_tables_tokens(quote!("/nonexistent/tables.ron")).to_string();
        assert_compile_error(
            &out,
            &["cannot read tables file", "/nonexistent/tables.ron"],
        );
        let out = include_tables_tokens(quote!(in_dir "x.ron")).to_string();
        assert_compile_error(&out, &["out_dir"]);
    }
}
