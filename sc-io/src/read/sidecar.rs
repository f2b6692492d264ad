//! A raw volume described by a JSON file beside it (`scan.json` next to `scan.raw`), as data sets
//! that ship bare samples often do: `dims`, `dtype` and optionally `spacing`, `origin`, `endian`,
//! `header_bytes`, and `iso_suggestions` (name → value), which `info` shows.
//!
//! ```json
//! {"dims": [128, 128, 62], "dtype": "i16", "spacing": [2, 2, 3],
//!  "iso_suggestions": {"skin": 20}}
//! ```

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::raw::RawLayout;
use crate::error::{Error, Result};
use crate::volume::{Dtype, Endian};

/// What a sidecar says.
#[derive(Clone, Debug, PartialEq)]
pub struct Sidecar {
    /// The samples' file: the sidecar's name with `.raw`.
    pub data: PathBuf,
    /// How the samples are laid out.
    pub layout: RawLayout,
    /// Distance between samples, if given.
    pub spacing: Option<[f64; 3]>,
    /// Position of the first sample, if given.
    pub origin: Option<[f64; 3]>,
    /// Named iso values, by name.
    pub iso_suggestions: Vec<(String, f64)>,
}

/// The sidecar of `path`: `path` itself if it ends in `.json`, else `path` with `.json` if that
/// file exists and `path` is not itself JSON.
pub fn find(path: &Path) -> Option<PathBuf> {
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        return Some(path.to_path_buf());
    }
    let beside = path.with_extension("json");
    beside.is_file().then_some(beside)
}

impl Sidecar {
    /// Reads and checks the sidecar at `json`.
    pub fn read(json: &Path) -> Result<Sidecar> {
        let mut text = String::new();
        std::io::Read::read_to_string(&mut crate::input::open(json)?, &mut text)
            .map_err(|e| Error::io(json, e))?;
        let meta: Value = serde_json::from_str(&text)
            .map_err(|e| Error::file(json, format!("not valid JSON: {e}")))?;
        let field = |name: &str| meta.get(name).filter(|v| !v.is_null());
        let bad = |name: &str, what: &str| Error::file(json, format!("`{name}` {what}"));

        let dims = field("dims")
            .and_then(|d| triple(d, |v| v.as_u64().and_then(|n| usize::try_from(n).ok())))
            .filter(|d| d.iter().all(|&n| n > 0))
            .ok_or_else(|| bad("dims", "must be three positive whole numbers"))?;
        let dtype = field("dtype")
            .and_then(Value::as_str)
            .and_then(Dtype::from_name)
            .ok_or_else(|| {
                bad(
                    "dtype",
                    "must be one of u8, i8, u16, i16, u32, i32, f32, f64 (or NumPy's uint8, …)",
                )
            })?;
        let endian = match field("endian").map(|v| v.as_str()) {
            None | Some(Some("little")) => Endian::Little,
            Some(Some("big")) => Endian::Big,
            Some(_) => return Err(bad("endian", "must be \"little\" or \"big\"")),
        };
        let header_bytes = match field("header_bytes") {
            None => 0,
            Some(v) => v
                .as_u64()
                .ok_or_else(|| bad("header_bytes", "must be a whole number"))?,
        };
        let real = |v: &Value| v.as_f64().filter(|x| x.is_finite());
        let spacing = match field("spacing") {
            None => None,
            Some(v) => Some(
                triple(v, real)
                    .filter(|s| s.iter().all(|&x| x > 0.0))
                    .ok_or_else(|| bad("spacing", "must be three positive numbers"))?,
            ),
        };
        let origin = match field("origin") {
            None => None,
            Some(v) => {
                Some(triple(v, real).ok_or_else(|| bad("origin", "must be three finite numbers"))?)
            }
        };
        let iso_suggestions = field("iso_suggestions")
            .and_then(Value::as_object)
            .map(|o| {
                o.iter()
                    .filter_map(|(k, v)| Some((k.clone(), real(v)?)))
                    .collect()
            })
            .unwrap_or_default();
        Ok(Sidecar {
            data: json.with_extension("raw"),
            layout: RawLayout {
                dims,
                dtype,
                endian,
                header_bytes,
            },
            spacing,
            origin,
            iso_suggestions,
        })
    }
}

fn triple<T>(v: &Value, item: impl Fn(&Value) -> Option<T>) -> Option<[T; 3]> {
    let items: Vec<T> = v.as_array()?.iter().map(item).collect::<Option<_>>()?;
    items.try_into().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sidecar(text: &str) -> Result<Sidecar> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.json");
        std::fs::write(&path, text).unwrap();
        Sidecar::read(&path)
    }

    #[test]
    fn reads_the_fields_and_defaults() {
        let s = sidecar(
            r#"{"dims": [4, 5, 6], "dtype": "int16", "spacing": [2, 2, 3.5],
                "iso_suggestions": {"skin": 20, "note": "x", "bone": 300.5}}"#,
        )
        .unwrap();
        assert_eq!(s.layout.dims, [4, 5, 6]);
        assert_eq!(s.layout.dtype, Dtype::I16);
        assert_eq!(s.layout.endian, Endian::Little);
        assert_eq!(s.layout.header_bytes, 0);
        assert_eq!(s.spacing, Some([2.0, 2.0, 3.5]));
        assert_eq!(s.origin, None);
        // In the file's order (serde_json keeps it: sc-io turns on `preserve_order`).
        assert_eq!(
            s.iso_suggestions,
            [("skin".to_string(), 20.0), ("bone".to_string(), 300.5)]
        );
        assert!(s.data.ends_with("v.raw"));
    }

    #[test]
    fn bad_fields_are_named() {
        for (text, field) in [
            (r#"{"dtype": "u8"}"#, "`dims`"),
            (r#"{"dims": [1, 0, 1], "dtype": "u8"}"#, "`dims`"),
            (r#"{"dims": [1, 2, 3], "dtype": "u64"}"#, "`dtype`"),
            (
                r#"{"dims": [1, 2, 3], "dtype": "u8", "spacing": [1, -1, 1]}"#,
                "`spacing`",
            ),
            (
                r#"{"dims": [1, 2, 3], "dtype": "u8", "origin": [1, 1]}"#,
                "`origin`",
            ),
            (
                r#"{"dims": [1, 2, 3], "dtype": "u8", "endian": "middle"}"#,
                "`endian`",
            ),
            ("{", "not valid JSON"),
        ] {
            let err = sidecar(text).unwrap_err().to_string();
            assert!(
                err.contains("v.json") && err.contains(field),
                "{text}: {err}"
            );
        }
    }

    #[test]
    fn finds_a_sidecar_beside_a_raw_file() {
        let dir = tempfile::tempdir().unwrap();
        let raw = dir.path().join("v.raw");
        assert_eq!(find(&raw), None);
        std::fs::write(dir.path().join("v.json"), "{}").unwrap();
        assert_eq!(find(&raw), Some(dir.path().join("v.json")));
        assert_eq!(
            find(&dir.path().join("w.JSON")),
            Some(dir.path().join("w.JSON"))
        );
    }
}
