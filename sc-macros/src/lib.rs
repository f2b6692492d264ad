//! `include_tables!`: compiles a Skeleton Climbing RON table set into `static` arrays.
//!
//! The RON is parsed and validated (every check of `sc_tablegen::validate`, geometric embedding
//! included) while the crate compiles, so the runtime never parses, allocates or lazily builds a
//! table, and a broken table is a compile error naming the file, the entry and the problem.
//!
//! ```ignore
//! // The committed tables, relative to the invoking crate's Cargo.toml:
//! static TABLES: sc_runtime::tables::CaseTables = sc_macros::include_tables!("../tables/skeleton-climbing.ron");
//! // Tables a build script wrote into OUT_DIR:
//! static MINE: sc_runtime::tables::CaseTables = sc_macros::include_tables!(out_dir "my-tables.ron");
//! ```

use std::path::PathBuf;

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::quote;
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
    let input = syn::parse_macro_input!(input as Input);
    match expand(&input) {
        Ok(tokens) => tokens.into(),
        Err(msg) => syn::Error::new(input.path.span(), msg)
            .to_compile_error()
            .into(),
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
    let embedded = set
        .classes
        .iter()
        .flat_map(|c| &c.cases)
        .map(|e| packed(&e.triangles, &e.grey));
    let paper = set
        .classes
        .iter()
        .flat_map(|c| &c.cases)
        .map(|e| match &e.paper {
            Some(p) => packed(&p.triangles, &p.grey),
            None => packed(&e.triangles, &e.grey),
        });
    let embedded: Vec<Tokens> = embedded.collect();
    let paper: Vec<Tokens> = paper.collect();
    Ok(quote! {{
        // Makes the compiler rebuild this crate when the tables file changes.
        const _: &[u8] = include_bytes!(#shown);
        static EMBEDDED: [::sc_runtime::tables::Entry; 2048] = [#(#embedded),*];
        static PAPER: [::sc_runtime::tables::Entry; 2048] = [#(#paper),*];
        ::sc_runtime::tables::CaseTables::from_static(&EMBEDDED, &PAPER)
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

/// One runtime `Entry`: triangles padded to five, ears rotated to `[back, grey, forward]`.
fn packed(triangles: &[[u8; 3]], grey: &[Grey]) -> Tokens {
    let mut tris = [[0u8; 3]; 5];
    tris[..triangles.len()].copy_from_slice(triangles);
    let mut ears = [NO_EAR; 3];
    let mut mergeable = 0u8;
    for g in grey {
        let axis = usize::from(g.edge / 4);
        if let Some(i) = g.ear {
            let t = &mut tris[usize::from(i)];
            while t[1] != g.edge {
                t.rotate_left(1);
            }
            ears[axis] = i;
        }
        mergeable |= u8::from(g.mergeable) << axis;
    }
    let count = triangles.len() as u8;
    let tris = tris.iter().map(|[a, b, c]| quote!([#a, #b, #c]));
    quote! {
        ::sc_runtime::tables::Entry { tris: [#(#tris),*], count: #count, ears: [#(#ears),*], mergeable: #mergeable }
    }
}

/// Mirrors `sc_runtime::tables::NO_EAR` (the macro cannot depend on the runtime it feeds).
const NO_EAR: u8 = 0xFF;
