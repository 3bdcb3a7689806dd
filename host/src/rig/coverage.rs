//! How much of a rig's spec ranges is inside every check: each axis alone, and all of them at once.

use ringpod_core::kinematics::geometry::DEG;
use ringpod_core::kinematics::{Mechanism, Pose, RingPlatform};

/// How much of the spec ranges is inside every check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    /// Each axis over its range alone (41 steps at 36 yaws): poses inside, poses tried.
    pub per_axis: [(usize, usize); 5],
    /// All axes at once: the box's 32 corners at 8 yaws and 4,000 random poses at any yaw.
    pub combined: (usize, usize),
}

/// Measures the spec coverage of a rig (the table of the book's trainer-model geometry).
pub fn coverage(m: &RingPlatform<f64>, home: &Pose<f64>, ranges: &[f64; 5]) -> Coverage {
    let inside = |offsets: [f64; 5], yaw: f64| {
        let h = home.to_array();
        let p = Pose::new(
            h[0] + offsets[0],
            h[1] + offsets[1],
            h[2] + offsets[2],
            h[3] + offsets[3],
            h[4] + offsets[4],
            h[5] + yaw,
        );
        m.inverse_checked(&p).map(|(_, r)| r.all_pass()).unwrap_or(false)
    };
    let mut per_axis = [(0, 0); 5];
    for (axis, count) in per_axis.iter_mut().enumerate() {
        for k in 0..=40 {
            for y in 0..36 {
                let mut o = [0.0; 5];
                o[axis] = ranges[axis] * (-1.0 + k as f64 / 20.0);
                count.0 += usize::from(inside(o, y as f64 * 10.0 * DEG));
                count.1 += 1;
            }
        }
    }
    let mut combined = (0, 0);
    for corner in 0..32u32 {
        let o = core::array::from_fn(|i| if corner & (1 << i) == 0 { -ranges[i] } else { ranges[i] });
        for y in 0..8 {
            combined.0 += usize::from(inside(o, y as f64 * 45.0 * DEG));
            combined.1 += 1;
        }
    }
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for _ in 0..4_000 {
        let o = core::array::from_fn(|i| ranges[i] * uniform());
        combined.0 += usize::from(inside(o, uniform() * std::f64::consts::PI));
        combined.1 += 1;
    }
    Coverage { per_axis, combined }
}
