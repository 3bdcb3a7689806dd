//! Reading lists of six numbers from the command line.

use crate::error::CliError;

/// Parses `a,b,c,d,e,f` into six finite numbers.
pub fn six(what: &'static str, text: &str) -> Result<[f64; 6], CliError> {
    let bad = |reason: String| CliError::BadNumbers { what, reason };
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
            assert!(matches!(six("pose", text), Err(CliError::BadNumbers { .. })), "{text}");
        }
    }
}
