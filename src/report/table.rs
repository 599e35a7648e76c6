//! Markdown tables and number formatting for study reports.
//!
//! [`Table`] checks its shape as it is built (every row as wide as the header), so
//! [`Table::to_markdown`] cannot fail. Cells are plain strings: format numbers with
//! [`fmt_sig`] and [`fmt_percent`] so a column reads with a constant precision.

use std::path::Path;

use super::file::write_atomic;
use crate::error::ReportError;

/// Column alignment in a Markdown table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Align {
    /// Markdown's own default for text; also ours (see [`Table::new`]).
    #[default]
    Left,
    /// For numbers, so digits line up.
    Right,
    Center,
}

/// A Markdown (GitHub / pandoc pipe) table: a header row, one alignment per column, rows of
/// exactly as many cells as the header.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    header: Vec<String>,
    align: Vec<Align>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// Table with the given column headers, no rows, every column [`Align::Left`]
    /// (Markdown's default; right-align numeric columns with [`Table::with_align`]).
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        let header: Vec<String> = header.into_iter().map(Into::into).collect();
        let align = vec![Align::Left; header.len()];
        Table { header, align, rows: Vec::new() }
    }

    /// Sets one alignment per column; an error if `align` is not as long as the header.
    pub fn with_align(mut self, align: &[Align]) -> Result<Self, ReportError> {
        if align.len() != self.header.len() {
            return Err(ReportError::AlignWidth { given: align.len(), columns: self.header.len() });
        }
        self.align = align.to_vec();
        Ok(self)
    }

    /// Appends a row; an error naming the row (0-based) if it is not as wide as the header.
    pub fn push_row<S: Into<String>>(&mut self, row: impl IntoIterator<Item = S>) -> Result<(), ReportError> {
        let row: Vec<String> = row.into_iter().map(Into::into).collect();
        if row.len() != self.header.len() {
            return Err(ReportError::RowWidth { row: self.rows.len(), cells: row.len(), columns: self.header.len() });
        }
        self.rows.push(row);
        Ok(())
    }

    pub fn header(&self) -> &[String] {
        &self.header
    }

    pub fn align(&self) -> &[Align] {
        &self.align
    }

    pub fn rows(&self) -> &[Vec<String>] {
        &self.rows
    }

    /// The table as Markdown, one line per row, each ending in `\n`.
    /// See [`Table::write_markdown_into`].
    pub fn to_markdown(&self) -> String {
        let mut out = String::new();
        self.write_markdown_into(&mut out);
        out
    }

    /// Appends the table as Markdown to `out`.
    ///
    /// Columns are padded to their widest cell (counted in `char`s) so the source reads as a
    /// table too; `|` in a cell is escaped as `\|` and a line break becomes `<br>` (a raw line
    /// break would end the row). A table without columns writes nothing.
    pub fn write_markdown_into(&self, out: &mut String) {
        if self.header.is_empty() {
            return;
        }
        let header: Vec<String> = self.header.iter().map(|c| escape_cell(c)).collect();
        let rows: Vec<Vec<String>> = self.rows.iter().map(|r| r.iter().map(|c| escape_cell(c)).collect()).collect();
        // At least 3: the shortest separator that carries an alignment colon on both sides.
        let widths: Vec<usize> = (0..header.len())
            .map(|j| rows.iter().map(|r| r[j].chars().count()).chain([header[j].chars().count(), 3]).max().unwrap_or(3))
            .collect();
        push_line(out, &header, &widths, &self.align);
        out.push('|');
        for (w, a) in widths.iter().zip(&self.align) {
            let dashes = match a {
                Align::Left => format!(":{}", "-".repeat(w - 1)),
                Align::Right => format!("{}:", "-".repeat(w - 1)),
                Align::Center => format!(":{}:", "-".repeat(w - 2)),
            };
            out.push(' ');
            out.push_str(&dashes);
            out.push_str(" |");
        }
        out.push('\n');
        for r in &rows {
            push_line(out, r, &widths, &self.align);
        }
    }

    /// Writes the Markdown to `path` atomically (temporary file in the same directory, then
    /// rename), creating the parent directory if needed.
    pub fn write_markdown(&self, path: &Path) -> Result<(), ReportError> {
        write_atomic(path, self.to_markdown().as_bytes())
    }
}

fn escape_cell(c: &str) -> String {
    c.replace('|', "\\|").replace("\r\n", "<br>").replace('\n', "<br>")
}

fn push_line(out: &mut String, cells: &[String], widths: &[usize], align: &[Align]) {
    out.push('|');
    for ((c, &w), a) in cells.iter().zip(widths).zip(align) {
        let pad = w - c.chars().count();
        let (left, right) = match a {
            Align::Left => (0, pad),
            Align::Right => (pad, 0),
            Align::Center => (pad / 2, pad - pad / 2),
        };
        out.push(' ');
        out.extend(std::iter::repeat_n(' ', left));
        out.push_str(c);
        out.extend(std::iter::repeat_n(' ', right));
        out.push_str(" |");
    }
    out.push('\n');
}

/// `x` with `sig` significant digits, trailing zeros kept (they state the precision):
/// `fmt_sig(0.5, 4) == "0.5000"`, `fmt_sig(1234.5678, 4) == "1235"`.
///
/// Fixed notation for decimal exponents -4 ..= sig-1, scientific (`1.235e6`, `2.000e-5`)
/// outside, the rule of C's `%g`, so no digit beyond `sig` is ever printed. `sig = 0` is
/// taken as 1 (no digits is not a number). Non-finite values print as `NaN`, `inf`, `-inf`;
/// -0 prints as `0`.
pub fn fmt_sig(x: f64, sig: usize) -> String {
    if x.is_nan() {
        return "NaN".to_string();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_string();
    }
    let sig = sig.max(1);
    let x = if x == 0.0 { 0.0 } else { x };
    // Rounding first, in scientific form, gives the exponent after rounding (9.9996 → 1.000e1).
    let sci = format!("{:.*e}", sig - 1, x);
    let exp: i32 = sci.split_once('e').and_then(|(_, e)| e.parse().ok()).unwrap_or(0);
    if exp < -4 || exp >= sig as i32 {
        sci
    } else {
        format!("{:.*}", (sig as i32 - 1 - exp).max(0) as usize, x)
    }
}

/// A fraction as per cent with `decimals` decimals and a space before the sign, as in the
/// rest of the project's reports: `fmt_percent(0.1234, 1) == "12.3 %"`. A value that rounds
/// to zero prints without a minus sign; non-finite values as in [`fmt_sig`].
pub fn fmt_percent(fraction: f64, decimals: usize) -> String {
    if !fraction.is_finite() {
        return format!("{} %", fmt_sig(fraction, 1));
    }
    let s = format!("{:.*}", decimals, 100.0 * fraction);
    let s = match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    };
    format!("{s} %")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_sig_keeps_the_number_of_significant_digits() {
        assert_eq!(fmt_sig(0.5, 4), "0.5000");
        assert_eq!(fmt_sig(1234.5678, 4), "1235");
        assert_eq!(fmt_sig(1.23456, 3), "1.23");
        assert_eq!(fmt_sig(-0.00123456, 3), "-0.00123");
        assert_eq!(fmt_sig(0.0, 4), "0.000");
        assert_eq!(fmt_sig(-0.0, 2), "0.0");
        // Rounding carries into the next decade.
        assert_eq!(fmt_sig(9.9996, 4), "10.00");
        assert_eq!(fmt_sig(99999.0, 4), "1.000e5");
        // Scientific outside 1e-4 ..< 10^sig.
        assert_eq!(fmt_sig(12346.0, 4), "1.235e4");
        assert_eq!(fmt_sig(2.5e6, 3), "2.50e6");
        assert_eq!(fmt_sig(2e-5, 4), "2.000e-5");
        assert_eq!(fmt_sig(1e-4, 2), "0.00010");
        assert_eq!(fmt_sig(7.0, 0), "7");
        assert_eq!(fmt_sig(f64::NAN, 3), "NaN");
        assert_eq!(fmt_sig(f64::NEG_INFINITY, 3), "-inf");
    }

    #[test]
    fn fmt_percent_scales_and_spaces() {
        assert_eq!(fmt_percent(0.1234, 1), "12.3 %");
        assert_eq!(fmt_percent(1.0, 0), "100 %");
        assert_eq!(fmt_percent(-0.00001, 2), "0.00 %");
        assert_eq!(fmt_percent(-0.05, 1), "-5.0 %");
        assert_eq!(fmt_percent(f64::NAN, 1), "NaN %");
    }

    #[test]
    fn markdown_table_pads_aligns_and_escapes() {
        let mut t = Table::new(["case", "slip [m]", "ok"]).with_align(&[Align::Left, Align::Right, Align::Center]).unwrap();
        t.push_row(["a|b", "0.0123", "yes"]).unwrap();
        t.push_row(["long name", "12.50", "no"]).unwrap();
        let md = t.to_markdown();
        let expected = "\
| case      | slip [m] | ok  |
| :-------- | -------: | :-: |
| a\\|b      |   0.0123 | yes |
| long name |    12.50 | no  |
";
        assert_eq!(md, expected, "\n{md}");
    }

    #[test]
    fn table_shape_errors_name_the_row() {
        let mut t = Table::new(["a", "b"]);
        t.push_row(["1", "2"]).unwrap();
        let e = t.push_row(["1"]).unwrap_err();
        assert!(matches!(e, ReportError::RowWidth { row: 1, cells: 1, columns: 2 }), "{e}");
        assert!(e.to_string().contains("row 1"), "{e}");
        assert!(matches!(Table::new(["a"]).with_align(&[]), Err(ReportError::AlignWidth { given: 0, columns: 1 })));
        assert_eq!(Table::new(Vec::<String>::new()).to_markdown(), "");
    }

    #[test]
    fn line_breaks_do_not_end_the_row() {
        let mut t = Table::new(["x"]);
        t.push_row(["two\nlines"]).unwrap();
        assert_eq!(t.to_markdown().lines().count(), 3);
        assert!(t.to_markdown().contains("two<br>lines"));
    }
}
