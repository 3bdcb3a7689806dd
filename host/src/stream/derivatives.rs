//! `ringpod plot RECORD --derivatives --out FILE`: the velocity and acceleration of each pose axis of a run record
//! (the pose the device followed, angles unwrapped), as chapter 5.2's oscillograms show them.
//!
//! How: a record's samples are positions, so each derivative is numerical, and differencing them twice would
//! amplify their quantisation. Each sample gets a least-squares quadratic through the samples within `window / 2`
//! of it, on their own times (Savitzky-Golay, for uneven spacing too): its slope there is the velocity, twice its
//! curvature the acceleration. A quadratic is followed exactly. A sine of frequency `f` is attenuated by the window
//! `w`: with `x = pi w f`, the velocity reads `1 - x^2 / 10` of its amplitude and the acceleration `1 - x^2 / 14`
//! (a window of many samples; measured in the tests). The velocity is within 1 % up to `f = 0.1 / w`: 2 Hz for the
//! default 50 ms, 20 Hz for 5 ms (a record at 1 kHz). Near the ends the window is one-sided; where it holds fewer
//! than three samples there is no value.

use std::fmt::Write as _;
use std::path::Path;

use plotters::style::colors::{BLUE, GREEN, RED};

use crate::input::numbers::{readable, BadNumber};

use super::record::{self, PlotCommandError};
use crate::out::plot::{self, Panel, Series, TimePlot};

/// Velocity and acceleration at each sample of `y(t)` from a local quadratic over `window` seconds centred on it;
/// `NaN` where the window holds fewer than three distinct times. `t` must not decrease.
pub fn local_quadratic(t: &[f64], y: &[f64], window: f64) -> Vec<(f64, f64)> {
    let half = window / 2.0;
    let mut first = 0;
    let mut out = Vec::with_capacity(t.len());
    for (i, &ti) in t.iter().enumerate() {
        while first < i && t[first] < ti - half {
            first += 1;
        }
        // Moments of s = (t - ti) / half, for conditioning, and of y against them.
        let (mut m, mut r) = ([0.0f64; 5], [0.0f64; 3]);
        for (tj, yj) in t[first..]
            .iter()
            .zip(&y[first..])
            .take_while(|(tj, _)| **tj <= ti + half)
        {
            let s = (tj - ti) / half;
            let mut p = 1.0;
            for k in 0..5 {
                m[k] += p;
                if k < 3 {
                    r[k] += p * yj;
                }
                p *= s;
            }
        }
        let n = nalgebra::Matrix3::new(m[0], m[1], m[2], m[1], m[2], m[3], m[2], m[3], m[4]);
        let c = if m[0] >= 3.0 && n.determinant().abs() > 1e-12 * m[0].powi(3) {
            n.lu().solve(&nalgebra::Vector3::new(r[0], r[1], r[2]))
        } else {
            None
        };
        out.push(c.map_or((f64::NAN, f64::NAN), |c| (c[1] / half, 2.0 * c[2] / (half * half))));
    }
    out
}

/// The derivatives over the span asked: its samples' times, and per axis (velocity, acceleration) at each.
struct Measured {
    t: Vec<f64>,
    derivatives: Vec<Vec<(f64, f64)>>,
}

const AXES: [&str; 6] = ["surge x", "sway y", "heave z", "roll alpha", "pitch beta", "yaw gamma"];

/// The span of device times asked (`--from`, `--to`, s): either end may be left open.
pub type Span = (Option<f64>, Option<f64>);

/// A span that cannot be used, said with the options that were given (and only those).
fn bad_span(span: Span, reason: String) -> BadNumber {
    match span {
        (Some(from), Some(to)) => {
            BadNumber::given_text("from", format!("{} --to {}", readable(from), readable(to)), reason)
        }
        (None, Some(to)) => BadNumber::given("to", to, reason),
        (Some(from), None) => BadNumber::given("from", from, reason),
        (None, None) => BadNumber::new("from/--to", reason),
    }
}

/// Draws the derivatives of a record's followed pose over the device times `span` (the whole record when neither
/// end is given; the fit takes the samples around its ends too); returns the summary to print.
pub fn plot_command(input: &Path, out: &Path, window: f64, span: Span) -> Result<String, PlotCommandError> {
    if !(window.is_finite() && window > 0.0 && window <= 10.0) {
        return Err(BadNumber::new(
            "window",
            format!("{} s; a window is more than 0 and at most 10 s", readable(window)),
        )
        .into());
    }
    let bounds = (span.0.unwrap_or(f64::NEG_INFINITY), span.1.unwrap_or(f64::INFINITY));
    if bounds.0.is_nan() || bounds.1.is_nan() || bounds.0 >= bounds.1 {
        return Err(bad_span(span, "the span is empty".into()).into());
    }
    let whole = record::read(input)?;
    let measured = measure(input, &whole, window, (span, bounds))?;
    let name = input
        .file_name()
        .map_or(String::new(), |f| f.to_string_lossy().into_owned());
    plot::save(out, (1100, 1200), &picture(&name, window, &measured))?;
    Ok(summary(&whole.t, &measured, window, out))
}

/// Fits the whole record (so that the span's ends have their neighbours) and keeps the samples inside the span
/// (as asked, and its bounds with the open ends infinite).
fn measure(
    input: &Path,
    whole: &record::Run,
    window: f64,
    (span, bounds): (Span, (f64, f64)),
) -> Result<Measured, PlotCommandError> {
    let all: Vec<Vec<(f64, f64)>> = (0..6)
        .map(|k| {
            let y: Vec<f64> = whole.target.iter().map(|p| p[k]).collect();
            local_quadratic(&whole.t, &y, window)
        })
        .collect();
    // The samples inside the span: drawn and measured.
    let inside: Vec<usize> = (0..whole.t.len())
        .filter(|&i| whole.t[i] >= bounds.0 && whole.t[i] <= bounds.1)
        .collect();
    if inside.len() < 2 {
        return Err(match (span, whole.t.first(), whole.t.last()) {
            ((None, None), _, _) | (_, None, _) | (_, _, None) => PlotCommandError::TooShort {
                path: input.to_path_buf(),
                samples: whole.t.len(),
            },
            (_, Some(first), Some(last)) => bad_span(
                span,
                format!(
                    "{} of the record's samples (device time {first:.3} to {last:.3} s) are in the span",
                    inside.len()
                ),
            )
            .into(),
        });
    }
    Ok(Measured {
        t: inside.iter().map(|&i| whole.t[i]).collect(),
        derivatives: all.iter().map(|d| inside.iter().map(|&i| d[i]).collect()).collect(),
    })
}

/// Four panels: velocity and acceleration, translation and rotation, three axes each.
fn picture(name: &str, window: f64, m: &Measured) -> TimePlot {
    let colours = [BLUE, RED, GREEN];
    let series = |axes: std::ops::Range<usize>, second: bool| -> Vec<Series> {
        axes.enumerate()
            .map(|(n, k)| {
                let points =
                    m.t.iter()
                        .zip(&m.derivatives[k])
                        .map(|(t, (v, a))| (*t, if second { *a } else { *v }))
                        .collect();
                Series::new(AXES[k], points, colours[n % 3])
            })
            .collect()
    };
    let panel = |title: &str, unit: &str, series: Vec<Series>| Panel {
        title: title.into(),
        unit: unit.into(),
        series,
        events: Vec::new(),
    };
    TimePlot {
        title: format!(
            "ringpod run {name}: velocity and acceleration of the followed pose (local quadratic over {:.0} ms)",
            window * 1e3
        ),
        panels: vec![
            panel("velocity: translation", "m/s", series(0..3, false)),
            panel("velocity: rotation", "rad/s", series(3..6, false)),
            panel("acceleration: translation", "m/s^2", series(0..3, true)),
            panel("acceleration: rotation", "rad/s^2", series(3..6, true)),
        ],
    }
}

/// What was drawn: the record's rate, the fit's window and what it attenuates, the span, each axis's peaks.
fn summary(all_t: &[f64], m: &Measured, window: f64, out: &Path) -> String {
    let (first, last) = (all_t[0], all_t[all_t.len() - 1]);
    let per = (all_t.len() as f64 - 1.0) / (last - first).max(f64::MIN_POSITIVE);
    let mut text = format!(
        "{} rows over {:.3} s of device time ({:.1} a second); derivatives of the followed pose by a least-squares \
         quadratic over {:.0} ms around each sample (about {:.0} samples); picture: {}\n",
        all_t.len(),
        last - first,
        per,
        window * 1e3,
        2.0 * (per * window / 2.0 + 1e-9).floor() + 1.0,
        out.display()
    );
    let _ = writeln!(
        text,
        "a sine of f Hz reads its velocity times 1 - (pi w f)^2/10, its acceleration 1 - (pi w f)^2/14 (w the \
         window): the velocity within 1 % up to {:.1} Hz",
        0.1 / window
    );
    if m.t.len() < all_t.len() {
        let _ = writeln!(
            text,
            "drawn and measured from {:.3} to {:.3} s ({} samples)",
            m.t[0],
            m.t[m.t.len() - 1],
            m.t.len()
        );
    }
    let _ = writeln!(text, "axis        peak |velocity|  peak |acceleration|");
    for (k, d) in m.derivatives.iter().enumerate() {
        let peak = |f: fn(&(f64, f64)) -> f64| {
            d.iter()
                .map(f)
                .filter(|v| v.is_finite())
                .fold(0.0, |m: f64, v| m.max(v.abs()))
        };
        let unit = if k < 3 { ("m/s", "m/s^2") } else { ("rad/s", "rad/s^2") };
        let _ = writeln!(
            text,
            "{:<11} {:>10.6} {:<7} {:>10.5} {}",
            AXES[k],
            peak(|p| p.0),
            unit.0,
            peak(|p| p.1),
            unit.1
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_is_followed_exactly_on_uneven_samples() {
        let t: Vec<f64> = (0..200)
            .map(|i| i as f64 * 0.01 + 0.003 * ((i * 7) % 3) as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|t| 0.5 - 0.2 * t + 1.5 * t * t).collect();
        let d = local_quadratic(&t, &y, 0.05);
        // The first sample's one-sided window holds two: no value there.
        assert!(d[0].0.is_nan());
        for (t, (v, a)) in t.iter().zip(d).skip(1) {
            assert!((v - (-0.2 + 3.0 * t)).abs() < 1e-9, "{t}: {v}");
            assert!((a - 3.0).abs() < 1e-7, "{t}: {a}");
        }
    }

    /// The attenuation the module's documentation states: measured on sines, against `1 - x^2 / 10` and
    /// `1 - x^2 / 14` (`x = pi w f`) with many samples in the window, and the default window on a 100 Hz record.
    #[test]
    fn a_sine_is_read_within_the_stated_attenuation() {
        let gains = |f: f64, window: f64, dt: f64| -> (f64, f64) {
            let w = std::f64::consts::TAU * f;
            let t: Vec<f64> = (0..(2.0 / dt) as usize).map(|i| i as f64 * dt).collect();
            let y: Vec<f64> = t.iter().map(|t| (w * t).sin()).collect();
            let d = local_quadratic(&t, &y, window);
            let skip = (window / dt) as usize + 1;
            let inner = &d[skip..d.len() - skip];
            let peak = |f: fn(&(f64, f64)) -> f64| inner.iter().map(f).fold(0.0, |m: f64, v| m.max(v.abs()));
            (peak(|p| p.0) / w, peak(|p| p.1) / (w * w))
        };
        for (f, window, dt) in [(18.8, 0.02, 0.0005), (25.0, 0.01, 0.0002), (5.0, 0.05, 0.001)] {
            let x = std::f64::consts::PI * window * f;
            let (v, a) = gains(f, window, dt);
            assert!(
                (v - (1.0 - x * x / 10.0)).abs() < 0.01,
                "{f} Hz over {window} s: velocity gain {v}"
            );
            assert!(
                (a - (1.0 - x * x / 14.0)).abs() < 0.01,
                "{f} Hz over {window} s: acceleration gain {a}"
            );
        }
        let (v, a) = gains(2.0, 0.05, 0.01);
        assert!(
            (v - 1.0).abs() < 0.01 && (a - 1.0).abs() < 0.01,
            "2 Hz at 100 Hz: {v} {a}"
        );
        // Fewer than three samples: no value.
        let d = local_quadratic(&[0.0, 1.0, 2.0], &[0.0, 1.0, 4.0], 0.5);
        assert!(d.iter().all(|(v, a)| v.is_nan() && a.is_nan()));
    }
}
