//! Line-oriented `key: value` / `Key = Value` headers, shared by NRRD and MetaImage, which differ
//! only in the separator, in where the header ends, and in their key names.

use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::error::{Error, Result};

/// Corrupt or binary files have no line breaks; give up instead of reading them whole.
const MAX_HEADER_BYTES: u64 = 1 << 20;

/// How one format writes its header.
pub struct Syntax {
    /// Between key and value: `":"` for NRRD, `"="` for MetaImage.
    pub separator: &'static str,
    /// The header ends after the line with this key (MetaImage's `ElementDataFile`), else at the
    /// first blank line or the end of the file (NRRD).
    pub last_key: Option<&'static str>,
    /// The format's name, for error messages.
    pub format: &'static str,
}

/// The fields of a text header, in file order, and where the data starts.
pub struct TextHeader {
    path: PathBuf,
    format: &'static str,
    fields: Vec<(String, String)>,
    /// Bytes from the start of the file to the first byte after the header.
    pub data_offset: u64,
}

impl TextHeader {
    /// Reads header lines from `reader`, which is positioned after any magic line already
    /// consumed (`offset` bytes into the file).
    pub fn read(
        path: &Path,
        reader: &mut impl BufRead,
        offset: u64,
        syntax: &Syntax,
    ) -> Result<Self> {
        let mut header = TextHeader {
            path: path.to_path_buf(),
            format: syntax.format,
            fields: Vec::new(),
            data_offset: offset,
        };
        let mut raw = Vec::new();
        loop {
            raw.clear();
            let n = reader
                .read_until(b'\n', &mut raw)
                .map_err(|e| Error::io(path, e))?;
            header.data_offset += n as u64;
            if header.data_offset > MAX_HEADER_BYTES {
                return Err(header.error("no end of header in the first MiB: not a text header"));
            }
            let line = std::str::from_utf8(&raw)
                .map_err(|_| header.error("the header has a line that is not text"))?
                .trim();
            if n == 0 || (line.is_empty() && syntax.last_key.is_none()) {
                break;
            }
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let Some((key, value)) = line.split_once(syntax.separator) else {
                return Err(header.error(format!("cannot read header line {line:?}")));
            };
            // NRRD key/value pairs (`key:=value`) are free-form metadata: not needed here.
            if value.starts_with('=') && syntax.separator == ":" {
                continue;
            }
            let key = key.trim().to_ascii_lowercase();
            let done = syntax
                .last_key
                .is_some_and(|k| k.eq_ignore_ascii_case(&key));
            header.fields.push((key, value.trim().to_string()));
            if done {
                break;
            }
        }
        if header.fields.is_empty() {
            return Err(header.error("the header is empty"));
        }
        Ok(header)
    }

    /// An error about this header's file.
    pub fn error(&self, message: impl std::fmt::Display) -> Error {
        Error::file(&self.path, format!("{} header: {message}", self.format))
    }

    /// The value of `key` (case-insensitive), if present.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(key))
            .map(|(_, v)| v.as_str())
    }

    /// The value of the first of `keys` present (formats have synonyms, e.g. MetaImage `Offset`,
    /// `Origin` and `Position`).
    pub fn get_any(&self, keys: &[&str]) -> Option<&str> {
        keys.iter().find_map(|k| self.get(k))
    }

    /// The value of `key`, which the format requires.
    pub fn require(&self, key: &str) -> Result<&str> {
        self.get(key)
            .ok_or_else(|| self.error(format!("the required field \"{key}\" is missing")))
    }

    /// `value` as `n` numbers separated by blanks, commas or parentheses; `what` names it in errors.
    pub fn numbers<T: FromStr>(&self, what: &str, value: &str, n: usize) -> Result<Vec<T>> {
        let parsed: Option<Vec<T>> = value
            .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().ok())
            .collect();
        match parsed {
            Some(v) if v.len() == n => Ok(v),
            _ => Err(self.error(format!("\"{what}\" should be {n} numbers, not {value:?}"))),
        }
    }

    /// The path of a detached data file named in the header, relative to the header's folder.
    /// It must stay in that folder or below (no absolute path, no `..`), and be a regular file:
    /// a header can then not make the reader open `/dev/zero` or another user's files.
    pub fn sibling(&self, name: &str) -> Result<PathBuf> {
        if name.is_empty() {
            return Err(self.error("the data file name is empty"));
        }
        let relative = Path::new(name);
        let escapes = relative.components().any(|c| {
            !matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        });
        if escapes {
            return Err(self.error(format!(
                "data file {name:?} points outside the header's folder"
            )));
        }
        let path = self.path.parent().unwrap_or(Path::new(".")).join(relative);
        if path.exists() && !path.is_file() {
            return Err(self.error(format!("data file {name:?} is not a regular file")));
        }
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NRRD: Syntax = Syntax {
        separator: ":",
        last_key: None,
        format: "NRRD",
    };
    const META: Syntax = Syntax {
        separator: "=",
        last_key: Some("ElementDataFile"),
        format: "MetaImage",
    };

    #[test]
    fn nrrd_header_stops_at_blank_line() {
        let text = b"# comment\ntype: short\nsizes: 2 3 4\nkey:=value\n\nBINARY";
        let h = TextHeader::read(Path::new("a.nrrd"), &mut &text[..], 9, &NRRD).unwrap();
        assert_eq!(h.get("TYPE"), Some("short"));
        assert_eq!(h.get("key"), None);
        assert_eq!(h.data_offset, 9 + text.len() as u64 - 6);
        assert_eq!(
            h.numbers::<usize>("sizes", h.get("sizes").unwrap(), 3)
                .unwrap(),
            [2, 3, 4]
        );
    }

    #[test]
    fn metaimage_header_stops_after_data_file() {
        let text = b"NDims = 3\nElementDataFile = LOCAL\n\x00\x01";
        let h = TextHeader::read(Path::new("a.mha"), &mut &text[..], 0, &META).unwrap();
        assert_eq!(h.get("elementdatafile"), Some("LOCAL"));
        assert_eq!(h.data_offset, text.len() as u64 - 2);
    }

    #[test]
    fn errors_name_the_file_and_field() {
        let h = TextHeader::read(Path::new("x.mha"), &mut &b"NDims = 3\n"[..], 0, &META).unwrap();
        let e = h.require("DimSize").unwrap_err().to_string();
        assert!(
            e.starts_with("x.mha: MetaImage header:") && e.contains("DimSize"),
            "{e}"
        );
        let e = h
            .numbers::<f64>("spacing", "1 2", 3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("3 numbers"), "{e}");
    }
}
