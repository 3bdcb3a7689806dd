//! The pose strings motion front ends send (FlyPT Mover, SimTools, SimHub): a template of literal bytes and axis
//! placeholders, each axis a fixed-point number in a bit range (decimal or hexadecimal text, or raw bytes) or a
//! signed fraction with decimal places, read into an offset of the pose from the platform's neutral.
//!
//! The syntax follows what the front ends document:
//! - SimTools' "Interface settings": an output string with `<Axis1a>`..`<Axis6a>` placeholders, an "Output - Bit
//!   Range" and an "Output - Type" of binary, decimal or hex (xsimulator.net, SimTools 2 user manual, "Interface
//!   Settings").
//! - FlyPT Mover's output strings: `<N>` is one byte of value N (a start or end marker such as `<255><255>` or
//!   `<10><13>`), other chars are sent as they are, `<` and `>` are reserved, keywords are replaced by the string of
//!   their value (flyptmover.com, "Outputs / The decimal output string"); binary axes of a fixed width between such
//!   markers (docs.motion4sim.com, "Direct Motion Mode": `<255><255>` + 3 bytes per axis + `<10><13>`).
//! - SimHub's generic serial motion controller: axis placeholders `<Axis1>`.., a resolution in bits, and a format
//!   "Binary" (raw bytes, e.g. 0xFF), "Decimal (string)" (e.g. "127") or "Hex (string)" (e.g. "7F")
//!   (manual.simhubdash.com, "Motion Addon / Supported controllers / Generic serial controller").
//!
//! What none of them states, and is therefore assumed here (the book says so): a fixed-point axis spans `0..2^bits-1`
//! with its neutral half-way; binary axes are most significant byte first; decimal and hex text are not padded
//! (read at any width); an axis placeholder's number is its axis in ringpod's pose order.

use std::fmt;

/// The pose axes a placeholder can name, in the order of `x y z alpha beta gamma`.
pub const AXES: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

/// The full-scale offsets (surge, sway, heave in mm; roll, pitch, yaw in degrees) an axis spans either way from
/// neutral unless `--pose-range` says otherwise: the trainer model's ranges, yaw as roll and pitch.
pub const DEFAULT_RANGES: [f64; 6] = [50.0, 50.0, 40.0, 20.0, 20.0, 20.0];

/// How each axis value is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// Unsigned decimal digits, `0..2^bits-1`.
    Decimal { bits: u8 },
    /// Unsigned hexadecimal digits (either case), `0..2^bits-1`.
    Hex { bits: u8 },
    /// `ceil(bits / 8)` raw bytes, most significant first, `0..2^bits-1`.
    Binary { bits: u8 },
    /// A signed decimal fraction of the axis's range, `-1..1`, written with `places` decimals.
    Fraction { places: u8 },
}

impl Encoding {
    /// The largest fixed-point value, or `None` for a fraction.
    fn max(self) -> Option<u64> {
        match self {
            Encoding::Decimal { bits } | Encoding::Hex { bits } | Encoding::Binary { bits } => Some((1 << bits) - 1),
            Encoding::Fraction { .. } => None,
        }
    }

    /// Whether a byte could continue a value written as text (so that a literal starting with it would be read as
    /// part of the value).
    fn continues(self, b: u8) -> bool {
        match self {
            Encoding::Decimal { .. } => b.is_ascii_digit(),
            Encoding::Hex { .. } => b.is_ascii_hexdigit(),
            Encoding::Fraction { .. } => b.is_ascii_digit() || b == b'.',
            Encoding::Binary { .. } => false,
        }
    }
}

/// A piece of a template.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Piece {
    /// Bytes sent as they are: markers and separators.
    Literal(Vec<u8>),
    /// The value of a pose axis (index in `x y z alpha beta gamma`).
    Axis(usize),
}

/// A pose string's template, read from `ENCODING:STRING` or a preset's name.
#[derive(Debug, Clone, PartialEq)]
pub struct Template {
    pieces: Vec<Piece>,
    encoding: Encoding,
    /// Each axis's full-scale offset either way from neutral (m; rad).
    ranges: [f64; 6],
}

/// Why a template was refused: where (the character, counted from 1) and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TemplateError {
    /// The character of the template, counted from 1.
    pub position: usize,
    /// What is wrong there.
    pub reason: String,
}

impl fmt::Display for TemplateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "pose format, character {}: {}", self.position, self.reason)
    }
}

impl std::error::Error for TemplateError {}

/// The front ends' presets: the name, the template, and what to set in the front end (the book's table).
pub const PRESETS: [(&str, &str); 3] = [
    // SimTools: Interface Output `<Axis1a>~<Axis2a>~<Axis3a>~<Axis4a>~<Axis5a>~<Axis6a>~`, Output Bit Range 16,
    // Output Type Decimal; `~` the separator of the SimTools examples on xsimulator.net.
    (
        "simtools",
        "dec16:<Axis1a>~<Axis2a>~<Axis3a>~<Axis4a>~<Axis5a>~<Axis6a>~",
    ),
    // FlyPT Mover: a binary output string, 16-bit axes between a start marker and an end marker, in the layout
    // of the Mover strings of docs.motion4sim.com.
    (
        "flypt",
        "bin16:<255><255><Axis1a><Axis2a><Axis3a><Axis4a><Axis5a><Axis6a><10><13>",
    ),
    // SimHub: generic serial controller, 6 axes, Hex (string), 16 bits: `<Axis1>` placeholders.
    ("simhub", "hex16:P<Axis1>;<Axis2>;<Axis3>;<Axis4>;<Axis5>;<Axis6><10>"),
];

/// The names of the presets, for messages.
pub fn preset_names() -> String {
    PRESETS.map(|(name, _)| name).join(", ")
}

/// The encoding of a template's `ENCODING` part (`dec16`, `hex12`, `bin24`, `frac3`).
fn encoding(text: &str) -> Result<Encoding, String> {
    let split = text.find(|c: char| c.is_ascii_digit()).unwrap_or(text.len());
    let (kind, number) = text.split_at(split);
    let n: Option<u8> = number.parse().ok();
    let bits = |make: fn(u8) -> Encoding| match n {
        Some(bits @ 2..=32) => Ok(make(bits)),
        _ => Err(format!("the bit range of `{text}` must be 2 to 32 bits")),
    };
    match kind {
        "dec" => bits(|bits| Encoding::Decimal { bits }),
        "hex" => bits(|bits| Encoding::Hex { bits }),
        "bin" => bits(|bits| Encoding::Binary { bits }),
        "frac" => match n {
            Some(places @ 0..=9) => Ok(Encoding::Fraction { places }),
            _ => Err(format!("the decimal places of `{text}` must be 0 to 9")),
        },
        _ => Err(format!(
            "`{text}` is not an encoding: dec, hex or bin with a bit range (dec16), or frac with decimal places (frac3)"
        )),
    }
}

/// The axis a placeholder names: one of [`AXES`], or a front end's numbered axis (`Axis1a`, `Axis1`, `A1`: its
/// last digit, before an optional letter, counting surge, sway, heave, roll, pitch, yaw from 1).
fn axis(name: &str) -> Result<usize, String> {
    if let Some(k) = AXES.iter().position(|a| a.eq_ignore_ascii_case(name)) {
        return Ok(k);
    }
    let stem = name.strip_suffix(|c: char| c.is_ascii_alphabetic()).unwrap_or(name);
    let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let prefix = &stem[..stem.len() - digits];
    if digits == 0 || prefix.is_empty() || !prefix.chars().all(|c| c.is_ascii_alphabetic()) {
        return Err(format!(
            "`<{name}>` is neither a byte (<0> to <255>) nor an axis: {} or a numbered axis such as <Axis1a>",
            AXES.join(", ")
        ));
    }
    match stem[stem.len() - digits..].parse::<usize>() {
        Ok(n @ 1..=6) => Ok(n - 1),
        _ => Err(format!(
            "`<{name}>` names axis {}: the axes are 1 to 6",
            &stem[stem.len() - digits..]
        )),
    }
}

impl Template {
    /// Reads `--pose-format`: a preset's name, or `ENCODING:STRING`, with each axis's full scale `ranges` (mm and
    /// degrees, as `--pose-range` gives them).
    pub fn parse(text: &str, ranges: [f64; 6]) -> Result<Self, TemplateError> {
        let at = |position: usize, reason: String| TemplateError { position, reason };
        if let Some((_, preset)) = PRESETS.iter().find(|(name, _)| name.eq_ignore_ascii_case(text)) {
            return Self::parse(preset, ranges);
        }
        let Some(colon) = text.find(':') else {
            return Err(at(
                1,
                format!(
                    "`{text}` is neither a preset ({}) nor ENCODING:STRING (dec16:<Axis1a>~<Axis2a>~)",
                    preset_names()
                ),
            ));
        };
        let encoding = encoding(&text[..colon]).map_err(|e| at(1, e))?;
        let pieces = pieces(&text[colon + 1..], encoding).map_err(|e| at(colon + 1 + e.position, e.reason))?;
        let ranges = ranges_si(ranges);
        Ok(Self {
            pieces,
            encoding,
            ranges,
        })
    }

    /// The same template with each axis's full scale `ranges` (mm and degrees, as `--pose-range` gives them).
    pub fn with_ranges(self, ranges: [f64; 6]) -> Self {
        Self {
            ranges: ranges_si(ranges),
            ..self
        }
    }

    /// The smallest change of each axis the string can carry (m; rad): a fixed-point step, or a last decimal.
    #[cfg(test)]
    pub fn quantum(&self) -> [f64; 6] {
        let step = match (self.encoding.max(), self.encoding) {
            (Some(max), _) => 2.0 / max as f64,
            (None, Encoding::Fraction { places }) => 10f64.powi(-i32::from(places)),
            (None, _) => 0.0,
        };
        self.ranges.map(|r| r * step)
    }

    /// The offsets from neutral (m; rad, in `x y z alpha beta gamma`) a string carries; axes it does not name stay
    /// at 0. Refused with the byte (counted from 1) where it departs from the template.
    pub fn read(&self, bytes: &[u8]) -> Result<[f64; 6], String> {
        let mut at = 0;
        let mut offsets = [0.0; 6];
        for piece in &self.pieces {
            let rest = &bytes[at..];
            match piece {
                Piece::Literal(literal) => {
                    if !rest.starts_with(literal) {
                        return Err(format!("byte {}: expected {}", at + 1, shown(literal)));
                    }
                    at += literal.len();
                }
                Piece::Axis(k) => {
                    let (fraction, used) = self
                        .value(rest)
                        .map_err(|e| format!("byte {}: {} value {e}", at + 1, AXES[*k]))?;
                    offsets[*k] = fraction * self.ranges[*k];
                    at += used;
                }
            }
        }
        if at != bytes.len() {
            return Err(format!(
                "byte {}: {} bytes after the string's end",
                at + 1,
                bytes.len() - at
            ));
        }
        Ok(offsets)
    }

    /// One axis value at the start of `rest`: its fraction of the range (-1..1) and the bytes it took.
    fn value(&self, rest: &[u8]) -> Result<(f64, usize), String> {
        let max = self.encoding.max();
        let run = rest.iter().take_while(|b| self.encoding.continues(**b)).count();
        let (value, used) = match self.encoding {
            Encoding::Binary { bits } => {
                let n = usize::from(bits).div_ceil(8);
                let Some(field) = rest.get(..n) else {
                    return Err(format!("needs {n} bytes, the string has {} left", rest.len()));
                };
                (field.iter().fold(0u64, |v, b| v << 8 | u64::from(*b)), n)
            }
            Encoding::Decimal { .. } | Encoding::Hex { .. } if run == 0 => return Err("has no digits".into()),
            Encoding::Decimal { .. } => (digits(&rest[..run], 10)?, run),
            Encoding::Hex { .. } => (digits(&rest[..run], 16)?, run),
            Encoding::Fraction { .. } => {
                let sign = usize::from(matches!(rest.first(), Some(b'-' | b'+')));
                let run = sign + rest[sign..].iter().take_while(|b| self.encoding.continues(**b)).count();
                let text = std::str::from_utf8(&rest[..run]).unwrap_or_default();
                let x: f64 = text
                    .parse()
                    .map_err(|_| format!("`{text}` is not a decimal fraction"))?;
                if x.abs() > 1.0 {
                    return Err(format!("{text} is beyond -1..1"));
                }
                return Ok((x, run));
            }
        };
        let max = max.unwrap_or(0);
        if value > max {
            return Err(format!("{value} is beyond the bit range's {max}"));
        }
        Ok(((2.0 * value as f64 - max as f64) / max as f64, used))
    }

    /// The string a front end sends for `offsets` (m; rad): each axis's fraction of its range, limited to -1..1
    /// (the tests' front end).
    #[cfg(test)]
    pub fn write(&self, offsets: [f64; 6]) -> Vec<u8> {
        let mut out = Vec::new();
        for piece in &self.pieces {
            match piece {
                Piece::Literal(literal) => out.extend(literal),
                Piece::Axis(k) => {
                    let fraction = (offsets[*k] / self.ranges[*k]).clamp(-1.0, 1.0);
                    let max = self.encoding.max().unwrap_or(0);
                    let v = ((fraction + 1.0) * max as f64 / 2.0).round() as u64;
                    match self.encoding {
                        Encoding::Decimal { .. } => out.extend(v.to_string().bytes()),
                        Encoding::Hex { .. } => out.extend(format!("{v:X}").bytes()),
                        Encoding::Binary { bits } => {
                            out.extend(&v.to_be_bytes()[8 - usize::from(bits).div_ceil(8)..]);
                        }
                        Encoding::Fraction { places } => {
                            out.extend(format!("{fraction:.*}", usize::from(places)).bytes())
                        }
                    }
                }
            }
        }
        out
    }
}

/// A value of digits in `radix` (at most 32 bits' worth).
fn digits(run: &[u8], radix: u32) -> Result<u64, String> {
    let text = std::str::from_utf8(run).unwrap_or_default();
    u64::from_str_radix(text, radix)
        .ok()
        .filter(|v| *v <= u64::from(u32::MAX))
        .ok_or_else(|| format!("`{text}` is beyond 32 bits"))
}

/// Literal bytes as a reader sees them: printable text quoted, others as `<N>`.
fn shown(bytes: &[u8]) -> String {
    let mut s = String::from("\"");
    for b in bytes {
        match b {
            b' '..=b'~' if *b != b'<' && *b != b'>' => s.push(char::from(*b)),
            _ => s += &format!("<{b}>"),
        }
    }
    s + "\""
}

/// `--pose-range`'s mm and degrees in m and rad.
fn ranges_si(ranges: [f64; 6]) -> [f64; 6] {
    core::array::from_fn(|i| {
        if i < 3 {
            ranges[i] / 1000.0
        } else {
            ranges[i].to_radians()
        }
    })
}

/// Reads `--pose-range`: six full-scale offsets `surge,sway,heave,roll,pitch,yaw` (mm; degrees), each above 0.
pub fn parse_ranges(text: &str) -> Result<[f64; 6], String> {
    let v = crate::games::numbers(text.as_bytes())?;
    let ranges: [f64; 6] = v.try_into().map_err(|v: Vec<f64>| {
        format!(
            "expected 6 ranges (surge,sway,heave mm; roll,pitch,yaw degrees), got {}",
            v.len()
        )
    })?;
    if let Some(i) = ranges.iter().position(|r| !(r.is_finite() && *r > 0.0 && *r <= 1000.0)) {
        return Err(format!(
            "the {} range must be above 0 and at most 1000, not {}",
            AXES[i], ranges[i]
        ));
    }
    Ok(ranges)
}

/// The pieces of a template's STRING; an error's position counts characters of STRING from 1.
fn pieces(text: &str, encoding: Encoding) -> Result<Vec<Piece>, TemplateError> {
    let at = |position: usize, reason: String| TemplateError { position, reason };
    let mut pieces: Vec<Piece> = Vec::new();
    let mut literal = Vec::new();
    // A literal byte: refused where it would be read as part of the axis value before it.
    let push = |literal: &mut Vec<u8>, pieces: &[Piece], byte: u8, n: usize, shown: &str| {
        if literal.is_empty() && matches!(pieces.last(), Some(Piece::Axis(_))) && encoding.continues(byte) {
            return Err(at(
                n,
                format!("{shown} right after an axis would be read as part of its value"),
            ));
        }
        literal.push(byte);
        Ok(())
    };
    let mut chars = text.char_indices().enumerate();
    while let Some((n, (i, c))) = chars.next() {
        let n = n + 1;
        match c {
            '>' => {
                return Err(at(
                    n,
                    "`>` without its `<` (both are reserved for bytes and axes)".into(),
                ))
            }
            '<' => {
                let close = text[i..].find('>').ok_or_else(|| at(n, "`<` without its `>`".into()))?;
                let name = &text[i + 1..i + close];
                if name.is_empty() || name.contains('<') {
                    return Err(at(n, "`<` must close with `>` around a byte or an axis name".into()));
                }
                chars.nth(name.chars().count());
                if name.bytes().all(|b| b.is_ascii_digit()) {
                    let byte = name
                        .parse::<u8>()
                        .map_err(|_| at(n, format!("<{name}> is beyond a byte (0 to 255)")))?;
                    push(&mut literal, &pieces, byte, n, &format!("<{name}>"))?;
                    continue;
                }
                let k = axis(name).map_err(|e| at(n, e))?;
                if pieces.contains(&Piece::Axis(k)) {
                    return Err(at(n, format!("the {} axis is already in the string", AXES[k])));
                }
                if !literal.is_empty() {
                    pieces.push(Piece::Literal(std::mem::take(&mut literal)));
                } else if matches!(pieces.last(), Some(Piece::Axis(_))) && !matches!(encoding, Encoding::Binary { .. })
                {
                    return Err(at(n, "two axes written as text need a separator between them".into()));
                }
                pieces.push(Piece::Axis(k));
            }
            _ => {
                let mut buf = [0; 4];
                for b in c.encode_utf8(&mut buf).bytes() {
                    push(&mut literal, &pieces, b, n, &format!("`{c}`"))?;
                }
            }
        }
    }
    if !literal.is_empty() {
        pieces.push(Piece::Literal(literal));
    }
    if !pieces.iter().any(|p| matches!(p, Piece::Axis(_))) {
        return Err(at(
            text.chars().count().max(1),
            "the string has no axis placeholder".into(),
        ));
    }
    Ok(pieces)
}

#[cfg(test)]
mod tests;
