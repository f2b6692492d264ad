//! The label table formats, from bytes. Every error is a message naming the line; the caller
//! adds the file.

use std::collections::BTreeMap;
use std::collections::btree_map::Entry;

use super::Label;

/// MRIcron's palette: 256 reds, 256 greens, 256 blues.
const PALETTE_BYTES: usize = 768;

/// The text formats, told apart by the first label line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    /// `IDX R G B A VIS MSH "LABEL"`.
    ItkSnap,
    /// `id name R G B [A]`.
    FreeSurfer,
    /// `id name [anything]`, or `id<TAB>name[<TAB>anything]`.
    Names,
}

impl Format {
    fn shape(self) -> &'static str {
        match self {
            Format::ItkSnap => {
                "an ITK-SNAP label description line, IDX R G B A VIS MSH \"LABEL\", was expected"
            }
            Format::FreeSurfer => "a FreeSurfer colour table line, id name R G B A, was expected",
            Format::Names => "a label line, id name, was expected",
        }
    }
}

/// Parses a table: a palette if `named_lut` (a `.lut` file) or if the bytes are 768 and not
/// text, else text.
pub(super) fn table(bytes: &[u8], named_lut: bool) -> Result<BTreeMap<u64, Label>, String> {
    let text = text(bytes);
    if bytes.len() == PALETTE_BYTES && (named_lut || text.is_err()) {
        return Ok(palette(bytes));
    }
    let text = match text {
        Ok(text) => text,
        Err(_) if named_lut => {
            return Err(format!(
                "{} bytes: an MRIcron palette (.lut) is {PALETTE_BYTES} (256 reds, greens, blues)",
                bytes.len()
            ));
        }
        Err(message) => return Err(message),
    };
    lines(text)
}

/// The bytes as text, or why they are not: not UTF-8, or control characters other than tabs
/// and line ends (binary data).
fn text(bytes: &[u8]) -> Result<&str, String> {
    let line_of = |at: usize| 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "line {}: not UTF-8 text: not a label table",
            line_of(e.valid_up_to())
        )
    })?;
    if let Some(at) = text.find(|c: char| c.is_control() && !matches!(c, '\t' | '\r' | '\n')) {
        return Err(format!(
            "line {}: binary data (byte {at}): not a label table",
            line_of(at)
        ));
    }
    Ok(text.strip_prefix('\u{feff}').unwrap_or(text))
}

/// A palette: label `i` gets colour `i`, and no name.
fn palette(bytes: &[u8]) -> BTreeMap<u64, Label> {
    (0..256)
        .map(|i| {
            let rgb = [bytes[i], bytes[256 + i], bytes[512 + i]];
            (
                i as u64,
                Label {
                    name: String::new(),
                    rgb: Some(rgb),
                },
            )
        })
        .collect()
}

/// The labels of a text table, its format told by the first label line.
fn lines(text: &str) -> Result<BTreeMap<u64, Label>, String> {
    let mut labels = BTreeMap::new();
    let mut first_line = BTreeMap::new();
    let mut format = None;
    for (i, line) in text.lines().enumerate() {
        let number = i + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let format = *format.get_or_insert_with(|| detect(line));
        let (id, label) = match format {
            Format::ItkSnap => itk_snap(line),
            Format::FreeSurfer => free_surfer(line),
            Format::Names => names(line),
        }
        .map_err(|why| {
            let why = if why.is_empty() {
                format.shape().to_string()
            } else {
                why
            };
            format!("line {number}: {why}; found {}", shown(line))
        })?;
        match labels.entry(id) {
            Entry::Occupied(_) => {
                return Err(format!(
                    "line {number}: label {id} again (first on line {})",
                    first_line[&id]
                ));
            }
            Entry::Vacant(slot) => {
                slot.insert(label);
                first_line.insert(id, number);
            }
        }
    }
    if labels.is_empty() {
        return Err("no labels in it (empty, or only comments)".into());
    }
    Ok(labels)
}

/// The line for a message: quoted, control characters escaped, cut at 60 characters.
fn shown(line: &str) -> String {
    let cut: String = line.chars().take(60).collect();
    if cut.len() < line.len() {
        format!("{cut:?}…")
    } else {
        format!("{cut:?}")
    }
}

fn detect(line: &str) -> Format {
    let fields: Vec<&str> = line.split_whitespace().collect();
    let numbers = |f: &[&str]| f.iter().all(|s| s.parse::<i64>().is_ok());
    if line.contains('"') {
        Format::ItkSnap
    } else if matches!(fields.len(), 5 | 6) && numbers(&fields[2..]) {
        Format::FreeSurfer
    } else {
        Format::Names
    }
}

/// `IDX R G B A VIS MSH "LABEL"`; the opacity and the two flags are checked to be numbers and
/// otherwise ignored. An empty string ("") leaves the label unnamed.
fn itk_snap(line: &str) -> Result<(u64, Label), String> {
    let (fields, rest) = leading_fields(line, 7).ok_or_else(String::new)?;
    let name = rest
        .strip_prefix('"')
        .and_then(|r| r.strip_suffix('"'))
        .ok_or_else(|| "the label's name is not in double quotes".to_string())?;
    let id = id(fields[0])?;
    let rgb = rgb(&fields[1..4])?;
    if fields[4].parse::<f64>().map_or(true, |a| !a.is_finite()) {
        return Err(format!("opacity {} is not a number", shown(fields[4])));
    }
    for flag in &fields[5..7] {
        if flag.parse::<i64>().is_err() {
            return Err(format!(
                "visibility flag {} is not a whole number",
                shown(flag)
            ));
        }
    }
    Ok((id, label(name, Some(rgb))?))
}

/// `id name R G B A`, or without the `A` (FreeSurfer's is 255 minus the opacity; ignored).
fn free_surfer(line: &str) -> Result<(u64, Label), String> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    if !matches!(fields.len(), 5 | 6) {
        return Err(String::new());
    }
    let id = id(fields[0])?;
    let rgb = rgb(&fields[2..5])?;
    if let Some(a) = fields.get(5)
        && a.parse::<i64>().is_err()
    {
        return Err(format!("alpha {} is not a whole number", shown(a)));
    }
    Ok((id, label(fields[1], Some(rgb))?))
}

/// `id<TAB>name[<TAB>...]` (the name may hold spaces), or `id name [...]`.
fn names(line: &str) -> Result<(u64, Label), String> {
    let (id_text, name) = match line.split_once('\t') {
        Some((id, rest)) => (id.trim(), rest.split('\t').next().unwrap_or("").trim()),
        None => {
            let mut fields = line.split_whitespace();
            (fields.next().unwrap_or(""), fields.next().unwrap_or(""))
        }
    };
    let id = id(id_text)?;
    if name.is_empty() {
        return Err(format!("label {id} has no name"));
    }
    Ok((id, label(name, None)?))
}

/// The first `n` whitespace-separated fields of `line`, and the rest of it, trimmed.
fn leading_fields(line: &str, n: usize) -> Option<(Vec<&str>, &str)> {
    let mut fields = Vec::with_capacity(n);
    let mut rest = line.trim_start();
    for _ in 0..n {
        let end = rest.find(char::is_whitespace)?;
        fields.push(&rest[..end]);
        rest = rest[end..].trim_start();
    }
    Some((fields, rest.trim_end()))
}

fn id(text: &str) -> Result<u64, String> {
    text.parse::<u64>().map_err(|_| {
        let magnitude = text.strip_prefix('-').unwrap_or(text);
        let digits = !magnitude.is_empty() && magnitude.bytes().all(|b| b.is_ascii_digit());
        match (digits, text.starts_with('-')) {
            (true, true) => format!("label id {} is negative", cut(text)),
            (true, false) => format!(
                "label id {} is larger than the largest, 2^64 - 1",
                cut(text)
            ),
            _ => format!("{} is not a label id (a whole number)", shown(text)),
        }
    })
}

/// A number for a message, cut at 30 characters.
fn cut(text: &str) -> String {
    match text.char_indices().nth(30) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

fn rgb(fields: &[&str]) -> Result<[u8; 3], String> {
    let mut rgb = [0; 3];
    for ((c, text), what) in rgb.iter_mut().zip(fields).zip(["red", "green", "blue"]) {
        *c = text
            .parse()
            .map_err(|_| format!("{what} {} is not a whole number from 0 to 255", shown(text)))?;
    }
    Ok(rgb)
}

fn label(name: &str, rgb: Option<[u8; 3]>) -> Result<Label, String> {
    if name.chars().any(char::is_control) {
        return Err("a control character in the name".into());
    }
    Ok(Label {
        name: name.trim().to_string(),
        rgb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<BTreeMap<u64, Label>, String> {
        table(text.as_bytes(), false)
    }

    fn named(name: &str, rgb: Option<[u8; 3]>) -> Label {
        Label {
            name: name.into(),
            rgb,
        }
    }

    #[test]
    fn each_text_format() {
        let itk = "# ITK-SnAP Label Description File\n    0     0    0    0        0  0  0    \"Clear Label\"\n   12   255  128    0     0.5  1  1    \"two words \"\r\n";
        let t = parse(itk).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t[&0], named("Clear Label", Some([0, 0, 0])));
        assert_eq!(t[&12], named("two words", Some([255, 128, 0])));

        let fs = "#$Id$\n\n#No. Label Name: R G B A\n\n0   Unknown  0   0   0   0\r\n14175 wm_rh_S_temporal_transverse 221 60 60 0\n";
        let t = parse(fs).unwrap();
        assert_eq!(
            t[&14175],
            named("wm_rh_S_temporal_transverse", Some([221, 60, 60]))
        );

        let tabs = "0\tUnclassified\r\n2\tPontine crossing tract\textra\r\n";
        let t = parse(tabs).unwrap();
        assert_eq!(t[&2], named("Pontine crossing tract", None));

        let aal = "1 Precentral_L 2001\r\n116 Vermis_10 9170\r\n\r\n";
        let t = parse(aal).unwrap();
        assert_eq!(t.keys().copied().collect::<Vec<_>>(), [1, 116]);
        assert_eq!(t[&116], named("Vermis_10", None));
    }

    #[test]
    fn palettes_by_name_or_by_content() {
        let mut bytes = vec![0u8; 768];
        bytes[5] = 10;
        bytes[256 + 5] = 20;
        bytes[512 + 5] = 30;
        let t = table(&bytes, true).unwrap();
        assert_eq!(t.len(), 256);
        assert_eq!(t[&5], named("", Some([10, 20, 30])));
        // 768 bytes that are not text are a palette whatever the file's name.
        assert_eq!(table(&bytes, false).unwrap(), t);
        let err = table(&bytes[..700], true).unwrap_err();
        assert!(err.contains("700 bytes") && err.contains("768"), "{err}");
    }

    /// Every hostile table is refused with the line that is wrong and why.
    #[test]
    fn hostile_tables() {
        let cases: [(&str, &str); 14] = [
            ("", "no labels"),
            ("# only a comment\n\n", "no labels"),
            ("1 a\nx b\n", "line 2: \"x\" is not a label id"),
            ("1 a\n-3 b\n", "line 2: label id -3 is negative"),
            (
                "1 a\n18446744073709551616 b\n",
                "line 2: label id 18446744073709551616 is larger",
            ),
            (
                "1 a\n99999999999999999999999999999999999999999 b\n",
                "line 2: label id 9999",
            ),
            ("1 a\n2 b\n1 c\n", "line 3: label 1 again (first on line 1)"),
            ("1 a\n2\n", "line 2: label 2 has no name"),
            (
                "0 Unknown 0 0 0 0\n1 Left 300 0 0 0\n",
                "line 2: red \"300\" is not a whole number",
            ),
            (
                "0 Unknown 0 0 0 0\n1 Left 1 2\n",
                "line 2: a FreeSurfer colour table line",
            ),
            (
                "0 0 0 0 0 0 0 \"a\"\n1 1 1 1 1 1 1 b\n",
                "line 2: the label's name is not in double quotes",
            ),
            (
                "0 0 0 0 0 0 0 \"a\"\n1 1 1 \"b\"\n",
                "line 2: an ITK-SNAP label description line",
            ),
            ("1 a\n2 b\u{1b}[31m\n", "line 2: binary data"),
            ("1 a\n\n2 \u{0}\u{1}\u{2}\n", "line 3: binary data"),
        ];
        for (text, want) in cases {
            let err = parse(text).unwrap_err();
            assert!(err.contains(want), "{text:?}: {err}");
        }
        let err = table(b"1 a\n2 \xff\xfe\n", false).unwrap_err();
        assert!(err.contains("line 2: not UTF-8"), "{err}");
        // A control character inside an ITK-SNAP name (the only format that quotes names).
        let err = parse("0 0 0 0 0 0 0 \"a\tb\"\n").unwrap_err();
        assert!(err.contains("line 1: a control character"), "{err}");
        // A long bad line is shown cut.
        let err = parse(&format!("1 a\n{}\n", "x".repeat(500))).unwrap_err();
        assert!(err.len() < 200 && err.ends_with('…'), "{err}");
    }
}
