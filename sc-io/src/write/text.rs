//! Lines of text for the text formats (OBJ, ASCII PLY), built in a buffer and written in large
//! pieces. Through `write!` each number and each piece of text between them would be a formatter
//! call and a write of its own, several times slower, and more so behind a progress counter.

use std::io::{self, Write};

/// A buffer of lines, written out whenever it grows past [`Lines::FLUSH_AT`].
pub(crate) struct Lines<W> {
    buf: Vec<u8>,
    out: W,
    floats: zmij::Buffer,
    ints: itoa::Buffer,
}

impl<W: Write> Lines<W> {
    /// 64 KiB: large enough that the pieces pass straight through the output's `BufWriter`.
    const FLUSH_AT: usize = 1 << 16;

    pub fn new(out: W) -> Self {
        Lines {
            buf: Vec::with_capacity(Self::FLUSH_AT + 256),
            out,
            floats: zmij::Buffer::new(),
            ints: itoa::Buffer::new(),
        }
    }

    pub fn text(&mut self, s: &str) -> &mut Self {
        self.buf.extend_from_slice(s.as_bytes());
        self
    }

    /// A float in the shortest form that reads back as the same `f32` (`1`, `0.25`, `1e-7`), as
    /// `Display` writes it but for the exponent of very large and small values. Non-finite
    /// values, which a mesh never holds, are written as `NaN`, `inf` and `-inf`.
    pub fn float(&mut self, v: f32) -> &mut Self {
        let s = self.floats.format(v);
        // Whole numbers without `.0`: grid coordinates are whole in two of three axes.
        let s = s.strip_suffix(".0").unwrap_or(s);
        self.buf.extend_from_slice(s.as_bytes());
        self
    }

    pub fn int(&mut self, v: u64) -> &mut Self {
        let s = self.ints.format(v);
        self.buf.extend_from_slice(s.as_bytes());
        self
    }

    /// Ends a line, writing the buffer out if it is full enough.
    pub fn end(&mut self) -> io::Result<()> {
        self.buf.push(b'\n');
        if self.buf.len() >= Self::FLUSH_AT {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    /// Writes out what is left.
    pub fn finish(mut self) -> io::Result<()> {
        self.out.write_all(&self.buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every float reads back as itself, lines end where asked, and a buffer that fills is
    /// written out in order.
    #[test]
    fn lines_read_back() {
        let values: Vec<f32> = (0..40_000u32)
            .map(|i| {
                f32::from_bits(i.wrapping_mul(2_654_435_761) & 0x7F7F_FFFF)
                    * [1.0, -1.0][i as usize % 2]
            })
            .chain([
                0.0,
                -0.0,
                1.0,
                0.1,
                1e-7,
                3.402_823_5e38,
                f32::MIN_POSITIVE,
                1e-45,
            ])
            .collect();
        let mut bytes = Vec::new();
        let mut lines = Lines::new(&mut bytes);
        for (i, &v) in values.iter().enumerate() {
            lines
                .text("v ")
                .float(v)
                .text(" ")
                .int(i as u64)
                .end()
                .unwrap();
        }
        lines.finish().unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let parsed: Vec<(f32, u64)> = text
            .lines()
            .map(|l| {
                let mut f = l.split(' ');
                assert_eq!(f.next(), Some("v"));
                let v = f.next().unwrap().parse().unwrap();
                (v, f.next().unwrap().parse().unwrap())
            })
            .collect();
        assert_eq!(parsed.len(), values.len());
        for (i, (&want, (got, n))) in values.iter().zip(parsed).enumerate() {
            assert_eq!(got.to_bits(), want.to_bits(), "{want}");
            assert_eq!(n, i as u64);
        }
    }
}
