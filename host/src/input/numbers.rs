//! Numbers on the command line and in what the CLI writes: lists of six, ranges, and the device's `f32` values.

/// A float that is exactly an `f32` is one of the device's values: its shortest `f32` decimal (0.05, not
/// 0.05000000074505806), so that files and JSON show the number as written; any other float as it is.
pub fn as_written(f: f64) -> f64 {
    if f64::from(f as f32) == f {
        (f as f32).to_string().parse().unwrap_or(f)
    } else {
        f
    }
}

/// Parses `a,b,c,d,e,f` into six finite numbers.
pub fn six(what: &'static str, text: &str) -> Result<[f64; 6], BadNumber> {
    let bad = |reason: String| BadNumber::new(what, reason);
    let values: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>().map_err(|e| bad(format!("`{}`: {e}", s.trim()))))
        .collect::<Result<_, _>>()?;
    let values: [f64; 6] = values
        .try_into()
        .map_err(|v: Vec<f64>| bad(format!("expected 6 numbers, got {}", v.len())))?;
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("value {} is not a finite number", i + 1)));
    }
    Ok(values)
}

/// Tilt (roll, pitch) beyond a whole turn either way is a mistake, not an orientation.
pub const MAX_TILT: f64 = std::f64::consts::TAU;
/// Yaw and ring-carriage angles up to 10,000 rad (about 1,600 turns): far beyond any session, and where an `f32`
/// angle on the controller still resolves its steps. Beyond is a broken number (1e308 came back as 300 digits).
pub const MAX_TURNING: f64 = 1e4;
/// A value given on the command line that cannot be used: the option (and the value, when the words put it
/// beside the option) and why. Every command's "option out of range" takes this one shape.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--{what}{}: {reason}", given.as_ref().map_or(String::new(), |g| format!(" {g}")))]
pub struct BadNumber {
    /// The option.
    pub what: &'static str,
    /// The value as given, said right after the option (`--step 0.1: ...`); none when `reason` says it.
    pub given: Option<String>,
    /// What is wrong.
    pub reason: String,
}

impl BadNumber {
    /// `--what: reason`.
    pub fn new(what: &'static str, reason: impl Into<String>) -> Self {
        Self {
            what,
            given: None,
            reason: reason.into(),
        }
    }

    /// `--what given: reason`, the number as a person reads it ([`readable`]: 1e-308 as `1e-308`, not 300 digits).
    pub fn given(what: &'static str, given: f64, reason: impl Into<String>) -> Self {
        Self::given_text(what, readable(given), reason)
    }

    /// `--what given: reason`, with words given beside the option (not a number alone).
    pub fn given_text(what: &'static str, given: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            what,
            given: Some(given.into()),
            reason: reason.into(),
        }
    }
}

/// Lengths up to 100 times the mechanism's characteristic length (its ring radius).
pub const MAX_LENGTHS: f64 = 100.0;

/// A number as a person reads it: plain when modest, in exponent form when huge or tiny.
pub fn readable(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e6 || v.abs() < 1e-4) {
        format!("{v:e}")
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

/// Checks a pose given on the command line (SI units) against sane ranges for a mechanism of characteristic
/// length `length`.
pub fn pose_in_range(what: &'static str, pose: &[f64; 6], length: f64) -> Result<(), BadNumber> {
    let bad = |reason: String| Err(BadNumber::new(what, reason));
    let names = ["x", "y", "z", "alpha", "beta", "gamma"];
    for (i, v) in pose.iter().enumerate() {
        let (limit, unit) = match i {
            0..=2 => (MAX_LENGTHS * length, "m"),
            3 | 4 => (MAX_TILT, "rad"),
            _ => (MAX_TURNING, "rad"),
        };
        if !v.is_finite() || v.abs() > limit {
            return bad(format!(
                "{} = {} {unit} is out of range (at most {} {unit} either way)",
                names[i],
                readable(*v),
                readable(limit)
            ));
        }
    }
    Ok(())
}

/// Why a timed pose read from a motion file (`loads --input`, `dynamics --input`) cannot be one: a coordinate that
/// is not a finite number, or beyond [`MAX_TURNING`] either way (no translation in metres or angle is; 1e300 gave
/// 300-digit forces). `None` when it can.
pub fn motion_row_refused(pose: &[f64; 6]) -> Option<String> {
    let names = ["x", "y", "z", "alpha", "beta", "gamma"];
    let i = pose.iter().position(|c| !(c.is_finite() && c.abs() <= MAX_TURNING))?;
    Some(if pose[i].is_finite() {
        format!(
            "{} = {} is out of range (at most {} either way)",
            names[i],
            readable(pose[i]),
            readable(MAX_TURNING)
        )
    } else {
        format!("{} is not a finite number", names[i])
    })
}

/// Checks rates given on the command line (SI: m/s, and rad/s where `angular`) against sane ranges for a mechanism
/// of characteristic length `length`: a hundred times that length a second, and [`MAX_TURNING`] rad/s. The rates
/// are linear in them, so a larger one says nothing more; it is a mistake (1e300 came back as 300 digits).
pub fn rates_in_range(
    what: &'static str,
    rates: &[f64; 6],
    angular: impl Fn(usize) -> bool,
    length: f64,
) -> Result<(), BadNumber> {
    for (i, v) in rates.iter().enumerate() {
        let (limit, unit) = if angular(i) {
            (MAX_TURNING, "rad/s")
        } else {
            (MAX_LENGTHS * length, "m/s")
        };
        if !v.is_finite() || v.abs() > limit {
            return Err(BadNumber::new(
                what,
                format!(
                    "value {} = {} {unit} is out of range (at most {} {unit} either way)",
                    i + 1,
                    readable(*v),
                    readable(limit)
                ),
            ));
        }
    }
    Ok(())
}

/// Checks one length or height given on the command line (m).
pub fn length_in_range(what: &'static str, value: f64, length: f64) -> Result<(), BadNumber> {
    let limit = MAX_LENGTHS * length;
    if value.is_finite() && value.abs() <= limit {
        Ok(())
    } else {
        Err(BadNumber::new(
            what,
            format!(
                "{} m is out of range (a finite number, at most {} m either way)",
                readable(value),
                readable(limit)
            ),
        ))
    }
}

/// A payload mass (kg): up to a thousand tonnes; beyond that the number is a mistake, not a simulator.
pub fn mass(kg: f64) -> Result<f64, BadNumber> {
    if kg.is_finite() && (0.0..=1e6).contains(&kg) {
        Ok(kg)
    } else {
        Err(BadNumber::new(
            "mass",
            format!("{} kg is out of range (0 to 1e6 kg)", readable(kg)),
        ))
    }
}

/// `--inertia=Ixx,Iyy,Izz` (kg m^2, each 0 to 1e6); none is a point mass.
pub fn inertia(text: Option<&str>) -> Result<[f64; 3], BadNumber> {
    let Some(text) = text else { return Ok([0.0; 3]) };
    let bad = |reason: String| BadNumber::new("inertia", reason);
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| bad(e.to_string()))?;
    match v[..] {
        [a, b, c] if v.iter().all(|x| x.is_finite() && (0.0..=1e6).contains(x)) => Ok([a, b, c]),
        _ => Err(bad("three numbers Ixx,Iyy,Izz, each 0 to 1e6 kg m^2".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_six_numbers() {
        assert_eq!(
            six("pose", "0, 0,0.2,-1e-3,0,3").unwrap(),
            [0.0, 0.0, 0.2, -1e-3, 0.0, 3.0]
        );
    }

    #[test]
    fn rejects_bad_lists() {
        for text in [
            "1,2,3",
            "1,2,3,4,5,6,7",
            "1,2,x,4,5,6",
            "1,2,3,4,5,NaN",
            "1,2,3,4,5,inf",
            "",
        ] {
            assert!(matches!(six("pose", text), Err(BadNumber { .. })), "{text}");
        }
    }

    #[test]
    fn rejects_numbers_out_of_range() {
        let fine = [0.01, -0.02, 0.2, 0.1, -0.1, 123.0];
        assert!(pose_in_range("pose", &fine, 0.3).is_ok());
        for (i, v) in [(5, 1e308), (5, -2e4), (3, 7.0), (4, -1e9), (0, 31.0), (2, -1e6)] {
            let mut p = fine;
            p[i] = v;
            assert!(matches!(pose_in_range("pose", &p, 0.3), Err(BadNumber { .. })), "{p:?}");
        }
        assert!(length_in_range("z", 0.2, 0.3).is_ok());
        for v in [f64::NAN, f64::INFINITY, 31.0, -1e300] {
            assert!(length_in_range("z", v, 0.3).is_err(), "{v}");
        }
    }

    #[test]
    fn numbers_in_messages_have_a_bounded_width() {
        for (v, want) in [
            (1e-308, "1e-308"),
            (-1e300, "-1e300"),
            (0.25, "0.25"),
            (0.0, "0"),
            (1.0 / 3.0, "0.333333"),
        ] {
            assert_eq!(readable(v), want);
        }
        let e = BadNumber::given("frequency", 1e-308, "too low");
        assert_eq!(e.to_string(), "--frequency 1e-308: too low");
    }
}
