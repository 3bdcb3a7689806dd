//! A multi-lap drive for the bench, made from the one lap of `docs/drives/lap-mix.csv`: the laps a driver
//! repeats, each a little different (its braking points earlier or later, its forces larger or smaller, its pace,
//! noise in proportion to each channel, and on one lap an excursion off the track), with the lap distance as a column: what a game's telemetry
//! gives and a lap preview aligns by. Deterministic: the noise is a seeded generator of its own, so the shipped
//! file is this code's output, byte for byte (the test below holds it so).
//!
//! Each lap runs a *progress* `p` through the base lap's 60 s: its rate is the lap's pace (and slower off the
//! track). The lap distance is the base lap's distance at `p` (its speeds: 25 m/s before 20 s, 40 m/s to 40 s,
//! 22 m/s after, ramped over a second), so the track is the same on every lap; the forces are the base lap's
//! at a warped time, so that each braking starts at another progress, that is at another distance, as a braking
//! point does.

use std::fmt::Write as _;

/// The base lap's length (s) and its sample interval (s).
pub const BASE_LAP_S: f64 = 60.0;
const BASE_DT: f64 = 0.01;

/// The base lap's braking onsets (s): the hard braking and the trail braking.
pub const BRAKING_ONSETS: [f64; 2] = [10.0, 40.0];

/// The drive's columns: the telemetry's and the lap distance (m).
pub const COLUMNS: &str = "t,ax,ay,az,wx,wy,wz,lap_distance";

/// One lap's differences from the base lap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LapSpec {
    /// Pace: the progress's rate (1 = the base lap's time).
    pub pace: f64,
    /// Each braking starts this much later (s of progress; negative: earlier).
    pub brake_shift: f64,
    /// The forces' scale (and the rates').
    pub scale: f64,
    /// An excursion off the track: its progress interval (s), during the long left corner.
    pub excursion: Option<(f64, f64)>,
}

/// The shipped drive's laps: the first as the base, then braking 0.2 s earlier and later, forces 0.9-1.1 times,
/// an excursion, and a lap after it.
pub const SHIPPED: [LapSpec; 5] = [
    LapSpec {
        pace: 1.0,
        brake_shift: 0.0,
        scale: 1.0,
        excursion: None,
    },
    LapSpec {
        pace: 1.01,
        brake_shift: -0.2,
        scale: 1.06,
        excursion: None,
    },
    LapSpec {
        pace: 0.99,
        brake_shift: 0.2,
        scale: 0.92,
        excursion: None,
    },
    LapSpec {
        pace: 1.0,
        brake_shift: -0.1,
        scale: 1.0,
        excursion: Some((26.0, 28.5)),
    },
    LapSpec {
        pace: 1.005,
        brake_shift: 0.1,
        scale: 1.1,
        excursion: None,
    },
];

/// The shipped drive's noise seed.
pub const SEED: u64 = 0x6c61_7073;

/// Noise: a share of each channel (of the force less g on z), standard deviation. In proportion, so that a
/// channel at rest stays at rest: noise added to a zero channel flips its sign sample by sample, and the bench
/// would count every platform cue above threshold against that sign as a false cue the cueing did not make.
const NOISE: f64 = 0.05;

/// The base lap's speed (m/s) at its time `p` (s): the segments' speeds, ramped linearly over a second.
fn base_speed(p: f64) -> f64 {
    let ramp = |at: f64, from: f64, to: f64, v: f64| {
        if p < at - 0.5 {
            v
        } else if p > at + 0.5 {
            to
        } else {
            from + (to - from) * (p - at + 0.5)
        }
    };
    if p < 30.0 {
        ramp(20.0, 25.0, 40.0, 25.0)
    } else {
        ramp(40.0, 40.0, 22.0, 40.0)
    }
}

/// The base lap's distance at each of `n` progress steps of `h` (a table, integrated by the trapezoid).
fn distance_table(h: f64, n: usize) -> Vec<f64> {
    let mut s = Vec::with_capacity(n + 1);
    let mut d = 0.0;
    s.push(0.0);
    for k in 0..n {
        let (a, b) = (k as f64 * h, (k + 1) as f64 * h);
        d += 0.5 * h * (base_speed(a) + base_speed(b));
        s.push(d);
    }
    s
}

/// A seeded generator (SplitMix64) and normal deviates by Box-Muller: the same numbers on every machine.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        // 53 bits in (0, 1].
        ((z >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.next(), self.next());
        (-2.0 * u.ln()).sqrt() * (core::f64::consts::TAU * v).cos()
    }
}

/// The base time of the forces at progress `p` on a lap whose braking starts `shift` later: piecewise linear,
/// each onset moved and the time about it stretched to meet the base lap 2 s before and 3 s after.
fn warped(p: f64, shift: f64) -> f64 {
    for onset in BRAKING_ONSETS {
        let (a, m, b) = (onset - 2.0, onset + shift, onset + 3.0);
        if p > a && p < m {
            return a + (p - a) * (onset - a) / (m - a);
        }
        if p >= m && p < b {
            return onset + (p - m) * (b - onset) / (b - m);
        }
    }
    p
}

/// The base lap's sample at time `t` (s), linearly between its rows (`t, ax, ay, az, wx, wy, wz`).
fn base_at(base: &[[f64; 7]], t: f64) -> [f64; 7] {
    let x = (t / BASE_DT).clamp(0.0, (base.len() - 1) as f64);
    let i = (x.floor() as usize).min(base.len() - 2);
    let f = x - i as f64;
    core::array::from_fn(|j| base[i][j] + (base[i + 1][j] - base[i][j]) * f)
}

/// A raised-cosine window: 0 outside `[a, b]`, 1 inside it but for ramps of `r` at both ends.
fn window(p: f64, a: f64, b: f64, r: f64) -> f64 {
    let up = ((p - a) / r).clamp(0.0, 1.0);
    let down = ((b - p) / r).clamp(0.0, 1.0);
    let s = up.min(down);
    0.5 - 0.5 * (core::f64::consts::PI * s).cos()
}

/// The drive of `laps` made from `base` (the base lap's rows, at 100 Hz), sampled every 0.01 s: rows of
/// `t, ax, ay, az, wx, wy, wz, lap_distance`, the noise from `seed`.
pub fn generate(base: &[[f64; 7]], laps: &[LapSpec], seed: u64) -> Vec<[f64; 8]> {
    let g = ringpod_core::cueing::G;
    // The distance table at a fine step: the lap distance is read from it.
    let fine = 0.001;
    let steps = (BASE_LAP_S / fine).round() as usize;
    let table = distance_table(fine, steps);
    let distance = |p: f64| {
        let x = (p / fine).clamp(0.0, steps as f64);
        let i = (x.floor() as usize).min(steps - 1);
        table[i] + (table[i + 1] - table[i]) * (x - i as f64)
    };
    let mut noise = Noise(seed);
    let mut rows = Vec::new();
    let mut t = 0.0f64;
    let mut k = 0u64;
    for lap in laps {
        let mut p = 0.0f64;
        while p < BASE_LAP_S {
            let off = lap.excursion.map_or(0.0, |(a, b)| window(p, a, b, 0.3));
            let b = base_at(base, warped(p, lap.brake_shift));
            let mut v: [f64; 7] = core::array::from_fn(|j| b[j]);
            for j in [1, 2, 4, 5, 6] {
                v[j] *= lap.scale;
            }
            v[3] = g + (v[3] - g) * lap.scale;
            if off > 0.0 {
                // Off the track: the lateral force lost to the grass, its drag, its bumps and a slide's yaw.
                let bump = 2.5 * (2.0 * core::f64::consts::PI * 9.0 * p).sin();
                let off_track = [-4.0, 3.0, g + bump, 0.08 * bump, 0.0, 0.35 * (1.7 * p).sin()];
                for j in 0..6 {
                    v[j + 1] += off * (off_track[j] - v[j + 1]);
                }
            }
            v[3] -= g;
            for x in &mut v[1..7] {
                *x *= 1.0 + NOISE * noise.normal().clamp(-3.0, 3.0);
            }
            v[3] += g;
            rows.push([t, v[1], v[2], v[3], v[4], v[5], v[6], distance(p)]);
            // The progress over the next sample: the pace, and slower off the track.
            let rate = lap.pace * (1.0 - 0.4 * off);
            p += rate * BASE_DT;
            k += 1;
            t = k as f64 * BASE_DT;
        }
    }
    rows
}

/// The drive as CSV text (the header [`COLUMNS`]): times to 0.01 s, forces and rates to 4 decimals, the
/// distance to 3.
pub fn csv(rows: &[[f64; 8]]) -> String {
    let mut s = String::with_capacity(rows.len() * 64);
    s += COLUMNS;
    s.push('\n');
    for r in rows {
        let _ = writeln!(
            s,
            "{:.2},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.3}",
            r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7]
        );
    }
    s
}

/// The base lap's rows from its CSV (`t, ax, ay, az, wx, wy, wz`).
pub fn base_lap(text: &str) -> Result<Vec<[f64; 7]>, String> {
    let (rows, errors) = crate::input::table::read(text, &crate::cueing::offline::TELEMETRY_COLUMNS)?;
    if let Some(e) = errors.first() {
        return Err(format!("line {}: {}", e.line, e.reason));
    }
    Ok(rows.iter().map(|(_, v)| core::array::from_fn(|j| v[j])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn docs() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/drives")
    }

    fn shipped() -> Vec<[f64; 8]> {
        let base = base_lap(&std::fs::read_to_string(docs().join("lap-mix.csv")).unwrap()).unwrap();
        generate(&base, &SHIPPED, SEED)
    }

    /// The shipped multi-lap drive is this generator's output, byte for byte (`RINGPOD_WRITE_DRIVES=1` writes
    /// it), and two runs give the same bytes.
    #[test]
    fn the_shipped_laps_are_the_generators_output() {
        let text = csv(&shipped());
        assert_eq!(text, csv(&shipped()));
        let path = docs().join("laps.csv");
        if std::env::var_os("RINGPOD_WRITE_DRIVES").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let on_disk = std::fs::read_to_string(&path).unwrap();
        assert!(on_disk == text, "docs/drives/laps.csv is not the generator's output");
    }

    /// The first braking's onset (ax below -6 m/s^2) by lap: at the lap distance the lap's shift moves it
    /// (25 m/s there: 0.2 s is 5 m), at the forces the lap's scale gives; the lap distance wraps once a lap
    /// and never goes backwards within one; the excursion's lap is the longest.
    #[test]
    fn each_lap_brakes_where_its_shift_says_with_its_scale() {
        let rows = shipped();
        let mut laps: Vec<Vec<[f64; 8]>> = vec![Vec::new()];
        for r in &rows {
            if let Some(last) = laps.last().unwrap().last() {
                if r[7] < last[7] - 100.0 {
                    laps.push(Vec::new());
                } else {
                    assert!(r[7] >= last[7], "{r:?} after {last:?}");
                }
            }
            laps.last_mut().unwrap().push(*r);
        }
        assert_eq!(laps.len(), SHIPPED.len());
        let onset = |lap: &[[f64; 8]]| lap.iter().find(|r| r[1] < -6.0).unwrap()[7];
        let first = onset(&laps[0]);
        assert!((first - 250.0).abs() < 3.0, "{first}");
        for (lap, spec) in laps.iter().zip(&SHIPPED) {
            let moved = onset(lap) - first;
            assert!((moved - spec.brake_shift * 25.0).abs() < 1.0, "{moved} for {spec:?}");
            // The hard braking's plateau, past its onset: -12 m/s^2 times the scale, within the noise (5 %: its
            // mean over 50 samples within 0.3 m/s^2).
            let at = lap.iter().position(|r| r[1] < -6.0).unwrap() + 100;
            let plateau: f64 = lap[at..at + 50].iter().map(|r| r[1]).sum::<f64>() / 50.0;
            assert!((plateau + 12.0 * spec.scale).abs() < 0.3, "{plateau} for {spec:?}");
        }
        let longest = (0..laps.len()).max_by_key(|&i| laps[i].len()).unwrap();
        assert!(SHIPPED[longest].excursion.is_some());
        let length = laps[0].last().unwrap()[7];
        assert!((length - 1740.0).abs() < 1.0, "{length}");
    }
}
