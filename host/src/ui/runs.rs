//! The Runs panel's record, read as it arrives: a record of an evening runs to hundreds of megabytes (an 80 s run at
//! 100 Hz is 2.6 MB), more than a page should hold twice or a chart can draw. Each row is read once and kept in at
//! most [`SPANS`] spans of consecutive rows; a span is drawn by the smallest and the largest value of each series in
//! the order they came, so that every peak of the record is on the chart at a few thousand points. The memory kept
//! is the spans', whatever the record's length.

use std::f64::consts::{PI, TAU};

use serde_json::{json, Value};

use crate::stream::record::{Columns, RecordError, Row, COLUMNS};

/// The largest record the panel reads: over nine hours at 100 Hz.
pub const MOST_BYTES: u64 = 1 << 30;
/// The spans a record is kept in (each drawn as two points).
const SPANS: usize = 2048;
/// State changes marked at most; the ones after are counted.
const MOST_CHANGES: usize = 2000;
/// A line longer than this is not a record's (a binary file, a file of one line).
const LONGEST_LINE: usize = 1 << 20;
/// Series per row: commanded, followed, steps, six each.
const SERIES: usize = 18;

/// Why a record was not opened.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// More than [`MOST_BYTES`].
    #[error("the record is larger than {} MiB, the most the Runs panel reads: plot a part of it with `ringpod plot`", MOST_BYTES >> 20)]
    TooLarge,
    /// Not UTF-8.
    #[error("line {0}: not text (is it a run record?)")]
    NotText(usize),
    /// No line end within [`LONGEST_LINE`].
    #[error("line {line}: longer than {kib} KiB (is it a run record?)", line = .0, kib = LONGEST_LINE >> 10)]
    LineTooLong(usize),
    /// A header or row that does not read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The upload broke off.
    #[error("the record did not arrive whole: {0}")]
    Upload(String),
}

/// Consecutive rows: their first and last time, and per series the smallest and largest value with its row.
#[derive(Clone)]
struct Span {
    t: (f64, f64),
    rows: u64,
    low: [(f64, u64); SERIES],
    high: [(f64, u64); SERIES],
    limited: bool,
    refused: bool,
}

impl Span {
    fn of(row: &Row, values: &[f64; SERIES], n: u64) -> Self {
        let at = values.map(|v| (v, n));
        Self {
            t: (row.t, row.t),
            rows: 1,
            low: at,
            high: at,
            limited: row.limited,
            refused: row.refused,
        }
    }

    /// `self` followed by `next`. A value that is not a number never stands for a span's extreme.
    fn join(&mut self, next: &Self) {
        self.t.1 = next.t.1;
        self.rows += next.rows;
        for (mine, theirs) in self.low.iter_mut().zip(&next.low) {
            if theirs.0 < mine.0 || mine.0.is_nan() {
                *mine = *theirs;
            }
        }
        for (mine, theirs) in self.high.iter_mut().zip(&next.high) {
            if theirs.0 > mine.0 || mine.0.is_nan() {
                *mine = *theirs;
            }
        }
        self.limited |= next.limited;
        self.refused |= next.refused;
    }
}

/// A record being read.
pub struct Reader {
    columns: Option<Columns>,
    /// The bytes of a line not ended yet.
    partial: Vec<u8>,
    lines: usize,
    bytes: u64,
    rows: u64,
    /// Rows per span.
    width: u64,
    spans: Vec<Span>,
    /// The last row's angles, made continuous (commanded then followed).
    angles: Option<[f64; 6]>,
    state: Option<String>,
    changes: Vec<(f64, String)>,
    more_changes: u64,
}

impl Default for Reader {
    fn default() -> Self {
        Self {
            columns: None,
            partial: Vec::new(),
            lines: 0,
            bytes: 0,
            rows: 0,
            width: 1,
            spans: Vec::new(),
            angles: None,
            state: None,
            changes: Vec::new(),
            more_changes: 0,
        }
    }
}

impl Reader {
    /// The next bytes of the record, cut anywhere.
    pub fn take(&mut self, mut bytes: &[u8]) -> Result<(), RunError> {
        self.bytes += bytes.len() as u64;
        if self.bytes > MOST_BYTES {
            return Err(RunError::TooLarge);
        }
        while let Some(end) = bytes.iter().position(|&b| b == b'\n') {
            let line = if self.partial.is_empty() {
                self.line(&bytes[..end])
            } else {
                let mut whole = std::mem::take(&mut self.partial);
                whole.extend_from_slice(&bytes[..end]);
                self.line(&whole)
            };
            line?;
            bytes = &bytes[end + 1..];
        }
        if self.partial.len() + bytes.len() > LONGEST_LINE {
            return Err(RunError::LineTooLong(self.lines + 1));
        }
        self.partial.extend_from_slice(bytes);
        Ok(())
    }

    fn line(&mut self, bytes: &[u8]) -> Result<(), RunError> {
        self.lines += 1;
        let text = std::str::from_utf8(bytes).map_err(|_| RunError::NotText(self.lines))?;
        let text = text.strip_suffix('\r').unwrap_or(text);
        let Some(columns) = &self.columns else {
            self.columns = Some(Columns::of(text)?);
            return Ok(());
        };
        if let Some(row) = columns.row(self.lines, text)? {
            self.push(&row);
        }
        Ok(())
    }

    fn push(&mut self, row: &Row) {
        // Each angle continuous across the device's and a source's wrapping, as `ringpod plot` draws it.
        let mut angles: [f64; 6] = std::array::from_fn(|i| if i < 3 { row.commanded[3 + i] } else { row.target[i] });
        if let Some(last) = self.angles {
            for (a, l) in angles.iter_mut().zip(last) {
                *a = l + ((*a - l + PI).rem_euclid(TAU) - PI);
            }
        }
        self.angles = Some(angles);
        let mut values = [0.0; SERIES];
        values[..3].copy_from_slice(&row.commanded[..3]);
        values[3..6].copy_from_slice(&angles[..3]);
        values[6..9].copy_from_slice(&row.target[..3]);
        values[9..12].copy_from_slice(&angles[3..]);
        values[12..].copy_from_slice(&row.steps);
        if self.state.as_deref().is_some_and(|s| s != row.state) {
            if self.changes.len() < MOST_CHANGES {
                self.changes.push((row.t, row.state.clone()));
            } else {
                self.more_changes += 1;
            }
        }
        if self.state.as_deref() != Some(row.state.as_str()) {
            self.state = Some(row.state.clone());
        }
        let span = Span::of(row, &values, self.rows);
        self.rows += 1;
        match self.spans.last_mut() {
            Some(last) if last.rows < self.width => last.join(&span),
            _ => self.spans.push(span),
        }
        if self.spans.len() > SPANS {
            // Twice as many rows per span: neighbours joined.
            self.spans = self
                .spans
                .chunks(2)
                .map(|pair| {
                    let mut joined = pair[0].clone();
                    if let Some(next) = pair.get(1) {
                        joined.join(next);
                    }
                    joined
                })
                .collect();
            self.width *= 2;
        }
    }

    /// The record as the page draws it: each span's extremes in the order they came, the state changes, and how
    /// many rows each point stands for.
    pub fn finish(mut self) -> Result<Value, RunError> {
        if !self.partial.is_empty() {
            let last = std::mem::take(&mut self.partial);
            self.line(&last)?;
        }
        if self.columns.is_none() {
            return Err(RecordError::NoColumn(COLUMNS[0]).into());
        }
        if self.rows == 0 {
            return Err(RecordError::NoRows.into());
        }
        let (mut t, mut commanded, mut target, mut steps) = (vec![], vec![], vec![], vec![]);
        let (mut limited, mut refused) = (vec![], vec![]);
        for span in &self.spans {
            let ordered: Vec<[f64; 2]> = (0..SERIES)
                .map(|k| {
                    let (low, high) = (span.low[k], span.high[k]);
                    if low.1 <= high.1 {
                        [low.0, high.0]
                    } else {
                        [high.0, low.0]
                    }
                })
                .collect();
            let points: &[usize] = if span.rows == 1 { &[0] } else { &[0, 1] };
            for &p in points {
                t.push(if p == 0 { span.t.0 } else { span.t.1 });
                let six = |from: usize| -> [f64; 6] { std::array::from_fn(|i| ordered[from + i][p]) };
                commanded.push(six(0));
                target.push(six(6));
                steps.push(six(12));
                limited.push(span.limited);
                refused.push(span.refused);
            }
        }
        Ok(json!({
            "rows": self.rows,
            "rows_per_span": self.width,
            "t": t,
            "commanded": commanded,
            "target": target,
            "steps": steps,
            "limited": limited,
            "refused": refused,
            "changes": self.changes.iter().map(|(t, s)| json!({ "t": t, "state": s })).collect::<Vec<_>>(),
            "more_changes": self.more_changes,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stream::record::AUX_COLUMNS;

    /// A record of `n` rows at 100 Hz: z a slow sine with one spike at row `spike`, the state Running after row 10.
    fn record(n: usize, spike: usize) -> String {
        let mut text = format!("{},{}\n", COLUMNS.join(","), AUX_COLUMNS.join(","));
        for i in 0..n {
            let t = i as f64 * 0.01;
            let z = if i == spike { 0.5 } else { 0.23 + 0.01 * (t * 0.5).sin() };
            let yaw = (t * 2.0).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            let state = if i < 10 { "Ready" } else { "Running" };
            text += &format!(
                "{t:.6},{t:.6},0,0,{z},0,0,{yaw},0,0,{z},0,0,{yaw},{i},1,2,3,4,5,{state},{},0,0,{i},0,0,100,0,0\n",
                u8::from(i == spike)
            );
        }
        text
    }

    fn read(text: &[u8], chunk: usize) -> Result<Value, RunError> {
        let mut r = Reader::default();
        for piece in text.chunks(chunk) {
            r.take(piece)?;
        }
        r.finish()
    }

    fn column(v: &Value, series: &str, k: usize) -> Vec<f64> {
        v[series]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p[k].as_f64().unwrap())
            .collect()
    }

    #[test]
    fn a_short_record_is_every_row_and_reads_the_same_however_it_arrives() {
        let text = record(400, 120);
        let whole = read(text.as_bytes(), text.len()).unwrap();
        assert_eq!(whole["rows"], 400);
        assert_eq!(whole["t"].as_array().unwrap().len(), 400);
        for chunk in [1, 7, 4096] {
            assert_eq!(read(text.as_bytes(), chunk).unwrap(), whole, "in pieces of {chunk}");
        }
        // The same as `ringpod plot` reads it, angles made continuous.
        let plot = crate::stream::record::parse(&text).unwrap();
        let yaw = column(&whole, "commanded", 5);
        for (a, b) in yaw.iter().zip(plot.commanded.iter().map(|p| p[5])) {
            assert!((a - b).abs() < 1e-12, "{a} {b}");
        }
        assert!(yaw.last().unwrap() > &PI, "continuous past a turn: {:?}", yaw.last());
        assert_eq!(whole["changes"], json!([{ "t": 0.1, "state": "Running" }]));
        let onsets = whole["limited"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|l| **l == true)
            .count();
        assert_eq!(onsets, 1);
    }

    #[test]
    fn a_long_record_is_drawn_at_a_few_thousand_points_keeping_every_peak() {
        // Over half an hour at 100 Hz.
        let n = 200_000;
        let text = record(n, 123_457);
        let v = read(text.as_bytes(), 65_536).unwrap();
        assert_eq!(v["rows"], n);
        let points = v["t"].as_array().unwrap().len();
        assert!(points <= 2 * SPANS && points > SPANS, "{points} points");
        let z = column(&v, "commanded", 2);
        assert_eq!(z.iter().copied().fold(f64::MIN, f64::max), 0.5, "the spike is kept");
        let low = z.iter().copied().fold(f64::MAX, f64::min);
        assert!((low - 0.22).abs() < 1e-4, "the sine's trough is kept: {low}");
        assert!(v["limited"].as_array().unwrap().iter().any(|l| *l == true));
        // Time runs forward.
        let t = v["t"].as_array().unwrap();
        assert!(t.windows(2).all(|w| w[0].as_f64() <= w[1].as_f64()));
        assert!((t.last().unwrap().as_f64().unwrap() - (n - 1) as f64 * 0.01).abs() < 1e-9);
    }

    #[test]
    fn what_is_not_a_record_is_refused_in_words() {
        let e = |text: &[u8]| read(text, 100).unwrap_err().to_string();
        assert!(e(b"a,b\n1,2\n").contains("no column"));
        assert!(e(b"").contains("no column"));
        let header = format!("{}\n", COLUMNS.join(","));
        assert_eq!(e(header.as_bytes()), "no rows");
        assert!(e(&[header.as_bytes(), b"\xff\xfe\n"].concat()).starts_with("line 2: not text"));
        assert!(e(&vec![b'x'; LONGEST_LINE + 1]).starts_with("line 1: longer than"));
        // The page says the same limit before it sends a file.
        assert!(crate::ui::SCRIPT.contains(&format!("const RUN_MOST_BYTES = {MOST_BYTES};")));
        let mut r = Reader {
            bytes: MOST_BYTES,
            ..Reader::default()
        };
        let e = r.take(b"1").unwrap_err().to_string();
        assert!(e.contains("larger than 1024 MiB"), "{e}");
    }
}
