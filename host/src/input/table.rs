//! Number tables in CSV whose header names the columns: the pose files of `stream`, the telemetry of `cue`.

use serde::Serialize;

/// A line that could not be used, or a setpoint the device refused.
#[derive(Debug, Clone, Serialize)]
pub struct InputError {
    /// 1-based line number (datagram number for UDP).
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// Input times beyond this (s, about 115 days) are refused as garbage.
pub const MAX_TIME_S: f64 = 1e7;

/// One row: its line number and its numbers in the order of the requested columns.
pub type Row = (usize, Vec<f64>);

/// Reads a CSV whose header names `columns` in any order (case-insensitive; no other columns). Lines may end in LF,
/// CRLF or CR; blank lines and lines starting with `#` are skipped. The first column is a time in seconds that
/// must increase from row to row. Bad rows are returned with their line numbers, not fatal; a missing or wrong
/// header is.
pub fn read(text: &str, columns: &[&str]) -> Result<(Vec<Row>, Vec<InputError>), String> {
    read_with_optional(text, columns, &[]).map(|(rows, errors, _)| (rows, errors))
}

/// Rows, bad rows, and which optional columns the header names.
pub type Table = (Vec<Row>, Vec<InputError>, Vec<bool>);

/// [`read`] with `optional` columns besides the required `columns` (a pose file's `aux1`, `aux2`): a row holds the
/// required values, then one per optional column (NaN where the header does not name it); the flags say which
/// optional columns the header names.
pub fn read_with_optional(text: &str, columns: &[&str], optional: &[&str]) -> Result<Table, String> {
    let mut present = vec![false; optional.len()];
    // A byte-order mark is how spreadsheets ("CSV UTF-8") start a file: not part of the first column's name.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    let mut last_t = f64::NEG_INFINITY;
    let mut order: Option<Vec<usize>> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let raw = raw.trim();
        if raw.is_empty() || raw.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = raw.split(',').map(str::trim).collect();
        let Some(order) = &order else {
            let found: Option<Vec<usize>> = columns
                .iter()
                .map(|c| fields.iter().position(|f| f.eq_ignore_ascii_case(c)))
                .collect();
            let extra: Vec<Option<usize>> = optional
                .iter()
                .map(|c| fields.iter().position(|f| f.eq_ignore_ascii_case(c)))
                .collect();
            let named = columns.len() + extra.iter().flatten().count();
            match found {
                Some(mut found) if fields.len() == named => {
                    for (k, at) in extra.iter().enumerate() {
                        present[k] = at.is_some();
                        // An absent optional column reads as NaN: its index is past the row.
                        found.push(at.unwrap_or(usize::MAX));
                    }
                    order = Some(found);
                }
                _ => {
                    // At most a line's worth of what was found: a header of megabytes is not echoed.
                    let found: String = raw.chars().take(80).collect();
                    let more = if found.len() < raw.len() { "..." } else { "" };
                    let optional = if optional.is_empty() {
                        String::new()
                    } else {
                        format!(" and may name {}", optional.join(","))
                    };
                    return Err(format!(
                        "line {line}: the header must name the columns {}{optional} (in any order), found `{found}{more}`",
                        columns.join(",")
                    ));
                }
            }
            continue;
        };
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        let width = columns.len() + present.iter().filter(|p| **p).count();
        let v = match values {
            Ok(v) if v.len() == width => order
                .iter()
                .map(|k| v.get(*k).copied().unwrap_or(f64::NAN))
                .collect::<Vec<f64>>(),
            Ok(v) => {
                errors.push(InputError {
                    line,
                    reason: format!("expected {width} fields, got {}", v.len()),
                });
                continue;
            }
            Err(e) => {
                errors.push(InputError {
                    line,
                    reason: format!("not a number: {e}"),
                });
                continue;
            }
        };
        let t = v[0];
        if !(t.is_finite() && t.abs() <= MAX_TIME_S) {
            errors.push(InputError {
                line,
                reason: format!("time {t} is not a number of seconds within +-{MAX_TIME_S:e}"),
            });
            continue;
        }
        if t <= last_t {
            errors.push(InputError {
                line,
                reason: "time is not increasing".into(),
            });
            continue;
        }
        last_t = t;
        rows.push((line, v));
    }
    if order.is_none() {
        return Err(format!("no header line naming the columns {}", columns.join(",")));
    }
    Ok((rows, errors, present))
}
