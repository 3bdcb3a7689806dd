//! `ringpod workspace`: the reachable region of a mechanism (a ring platform, or the tool carrier), scanned on a
//! plane of positions or of its two tilts with every check it has, printed and drawn (`picture`).

mod picture;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use ringpod_core::kinematics::geometry::DEG;
use ringpod_core::kinematics::{Check, Mechanism, Pose, RingPlatform};

use crate::analysis::mechanism::AnyMechanism;
use crate::error::CliError;
use crate::input::numbers::BadNumber;

/// What limits a grid point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Cell {
    /// No IK solution.
    Unreachable,
    /// The first check that fails.
    Fails(Check),
    /// Inside, with its singularity index.
    Inside(f64),
}

pub(crate) fn classify<M: Mechanism<f64>>(m: &M, pose: &Pose<f64>) -> Cell {
    match m.inverse_checked(pose) {
        Err(_) => Cell::Unreachable,
        Ok((_, r)) => match r.first_failure() {
            Some(c) => Cell::Fails(c),
            None => Cell::Inside(r.singularity_index),
        },
    }
}

/// The plane of a workspace section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Section {
    /// Horizontal, at height --z.
    Xy,
    /// Vertical through the ring axis (y = 0).
    Xz,
    /// Vertical across it, at the home pose's x (the tool carrier's dyad plane).
    Yz,
    /// The two tilts, alpha (about X) and beta (about Y), each -90 to 90 deg, at the home position.
    Rotations,
}

/// What `workspace` is asked to do.
pub struct Options<'a> {
    /// The mechanism: a preset by name (a ring platform or the tool carrier)...
    pub mechanism: &'a str,
    /// ...or a rig file.
    pub geometry: Option<&'a std::path::Path>,
    /// The plane.
    pub section: Section,
    /// Height of the xy section (m); the home pose's height without.
    pub z: Option<f64>,
    /// Cells along each side of the section.
    pub cells: usize,
    /// The picture (SVG or PNG).
    pub out: &'a std::path::Path,
    /// No progress bar.
    pub quiet: bool,
}

/// The mechanism scanned, its home pose, its spec ranges (ring platforms with a spec table) and the box of
/// positions its scans cover (`[min, max]` of x, y, z, m).
struct Scanned {
    name: String,
    m: AnyMechanism,
    home: [f64; 6],
    ranges: Option<[f64; 5]>,
    bounds: [(f64, f64); 3],
}

/// A rig file's ring platform or a preset's mechanism.
fn scanned(args: &Options) -> Result<Scanned, crate::error::CliError> {
    if let Some(path) = args.geometry {
        let rig = crate::rig::load_platform(path)?;
        let m = RingPlatform::new(&rig.geometry);
        return Ok(Scanned {
            name: rig.geometry.name.to_owned(),
            bounds: ring_bounds(&m),
            m: AnyMechanism::Ring(Box::new(m)),
            home: rig.home.to_array(),
            ranges: rig.ranges,
        });
    }
    let (preset, m) = AnyMechanism::by_name(args.mechanism)?;
    let bounds = match &m {
        AnyMechanism::Ring(r) => ring_bounds(r),
        AnyMechanism::Tool(t) => tool_bounds(t.geometry()),
    };
    Ok(Scanned {
        name: preset.name().to_owned(),
        m,
        home: preset.home(),
        ranges: preset.spec_ranges(),
        bounds,
    })
}

/// A ring platform's platform stays over its ring and below twice its rods (or its radius).
fn ring_bounds(m: &RingPlatform<f64>) -> [(f64, f64); 3] {
    let g = m.geometry();
    let r = g.ring_radius;
    [(-r, r), (-r, r), (0.0, 2.0 * g.rod_length.max(r))]
}

/// The tool carrier's tool: x where the carriage's stroke puts it (`q1 = x + L1 sin(beta)`, so up to `L1` beyond
/// at a tilt), y and z where the dyads (`L2 + L3` from their pivots, the frame pivots `b/2` aside and `L1` above
/// the tool at zero tilt) can hold it; a tenth more on each side so the edge shows.
fn tool_bounds(g: &ringpod_core::kinematics::geometry::ToolGeometry) -> [(f64, f64); 3] {
    let reach = g.l2 + g.l3;
    let widen = |(lo, hi): (f64, f64)| {
        let pad = 0.1 * (hi - lo);
        (lo - pad, hi + pad)
    };
    let ys = [g.pivot_b[1] - g.b / 2.0, g.pivot_d[1] + g.b / 2.0];
    let z = g.pivot_b[2].max(g.pivot_d[2]) - g.l1;
    [
        widen((g.stroke[0] - g.l1, g.stroke[1] + g.l1)),
        widen((ys[0].min(ys[1]) - reach, ys[0].max(ys[1]) + reach)),
        widen((g.pivot_b[2].min(g.pivot_d[2]) - g.l1 - reach, z + reach)),
    ]
}

/// Every cell of an `n` x `n` grid classified at its centre, rows in parallel, with a bar of rows.
fn scan(n: usize, quiet: bool, cell: &(dyn Fn(usize, usize) -> Cell + Sync)) -> Vec<Vec<Cell>> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(n as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("scanning {bar:40} {pos}/{len} rows")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let grid = (0..n)
        .into_par_iter()
        .map(|j| {
            let row = (0..n).map(|i| cell(i, j)).collect();
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();
    grid
}

/// A section's plane: the ranges of its two coordinates, their names and units, and the pose at a point of it.
struct Plane {
    u: (f64, f64),
    v: (f64, f64),
    names: (&'static str, &'static str),
    unit: &'static str,
    title: String,
}

impl Plane {
    fn of(section: Section, s: &Scanned, z0: f64) -> Self {
        let [x, y, z] = s.bounds;
        let deg = (-90.0, 90.0);
        let (u, v, names, unit, title) = match section {
            Section::Xy => (x, y, ("x", "y"), "m", format!("xy at z = {z0}")),
            Section::Xz => (x, z, ("x", "z"), "m", "xz".into()),
            Section::Yz => (y, z, ("y", "z"), "m", format!("yz at x = {}", s.home[0])),
            Section::Rotations => (
                deg,
                deg,
                ("alpha", "beta"),
                "deg",
                "alpha-beta at the home position".into(),
            ),
        };
        Plane {
            u,
            v,
            names,
            unit,
            title,
        }
    }

    fn pose(&self, section: Section, home: [f64; 6], z0: f64, u: f64, v: f64) -> Pose<f64> {
        let [hx, _, hz, ..] = home;
        match section {
            Section::Xy => Pose::new(u, v, z0, 0.0, 0.0, 0.0),
            Section::Xz => Pose::new(u, 0.0, v, 0.0, 0.0, 0.0),
            Section::Yz => Pose::new(hx, u, v, 0.0, 0.0, 0.0),
            Section::Rotations => Pose::new(hx, home[1], hz, u * DEG, v * DEG, 0.0),
        }
    }
}

pub fn run(args: &Options) -> Result<String, CliError> {
    let s = scanned(args)?;
    let length = s.m.characteristic_length();
    let n = args.cells;
    if args.z.is_some() && args.section != Section::Xy {
        return Err(CliError::SectionHeight);
    }
    let z0 = args.z.unwrap_or(s.home[2]);
    crate::input::numbers::length_in_range("z", z0, length)?;
    if !(10..=2000).contains(&args.cells) {
        return Err(BadNumber::new("cells", format!("{} is out of range (10 to 2000)", args.cells)).into());
    }
    let plane = Plane::of(args.section, &s, z0);
    let (u, v) = (plane.u, plane.v);
    let du = (u.1 - u.0) / n as f64;
    let dv = (v.1 - v.0) / n as f64;
    let centre = |i: usize, j: usize| (u.0 + (i as f64 + 0.5) * du, v.0 + (j as f64 + 0.5) * dv);
    let grid = scan(n, args.quiet, &|i, j| {
        let (a, b) = centre(i, j);
        classify(&s.m, &plane.pose(args.section, s.home, z0, a, b))
    });
    let applies = applying_checks(&s);
    // The picture, then what it shows in words.
    picture::draw(
        args.out,
        &picture::Section {
            grid: &grid,
            u,
            v,
            name: &s.name,
            title: &plane.title,
            axes: (
                format!("{} ({})", plane.names.0, plane.unit),
                format!("{} ({})", plane.names.1, plane.unit),
            ),
            applies: &applies,
        },
    )?;
    let inside: Vec<(f64, f64)> = grid
        .iter()
        .enumerate()
        .flat_map(|(j, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, c)| matches!(c, Cell::Inside(_)))
                .map(move |(i, _)| (i, j))
        })
        .map(|(i, j)| centre(i, j))
        .collect();
    let (un, vn) = plane.names;
    let unit = plane.unit;
    let mut text = format!(
        "{} section of {} ({n} x {n} cells): {} cells inside every check, {:.5} {unit}^2\n",
        plane.title,
        s.name,
        inside.len(),
        inside.len() as f64 * du * dv
    );
    if let (Some(umin), Some(umax), Some(vmin), Some(vmax)) = (
        inside.iter().map(|p| p.0).reduce(f64::min),
        inside.iter().map(|p| p.0).reduce(f64::max),
        inside.iter().map(|p| p.1).reduce(f64::min),
        inside.iter().map(|p| p.1).reduce(f64::max),
    ) {
        text += &format!("  reachable {un} in [{umin:.4}, {umax:.4}] {unit}, {vn} in [{vmin:.4}, {vmax:.4}] {unit}\n");
    }
    text += &mechanism_summary(&s, length);
    text += &format!("picture: {}\n", args.out.display());
    Ok(text)
}

/// What holds whatever the section: the volume at zero orientation, each axis's range from home, the spec ranges'
/// coverage (a ring platform's, when given) and a tool carrier's checks.
fn mechanism_summary(s: &Scanned, length: f64) -> String {
    let mut text = String::new();
    text += &format!(
        "volume at zero orientation: {:.6} m^3 (60^3 grid)\n",
        volume(&s.m, s.bounds)
    );
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let range = line_range(&s.m, s.home, axis, length);
        text += &format!("  {name} at home within [{:.4}, {:.4}] m\n", range.0, range.1);
    }
    for (axis, name) in ["roll", "pitch"].iter().enumerate() {
        let range = angle_range(&s.m, s.home, 3 + axis);
        text += &format!(
            "  {name} at home within [{:.1}, {:.1}] deg\n",
            range.0 / DEG,
            range.1 / DEG
        );
    }
    if let (Some(ranges), AnyMechanism::Ring(ring)) = (s.ranges, &s.m) {
        let coverage = crate::rig::coverage(ring, &Pose::from_array(s.home), &ranges);
        let (inside, total) = coverage.per_axis.iter().fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        text +=
            &format!(
            "{} spec ranges (each axis over its range, every 10 deg of yaw): {inside} of {total} poses inside: {}\n",
            s.name,
            if inside == total { "all inside" } else { "NOT all inside" }
        );
    }
    if let AnyMechanism::Tool(t) = &s.m {
        let g = t.geometry();
        text += &format!(
            "checks: reach (dyads closing, the carriage within its stroke q1 in [{}, {}] m, assumed) and singularity \
             (index {}); dyads on branches {}, {}\n",
            g.stroke[0],
            g.stroke[1],
            g.min_singularity_index,
            crate::analysis::branches::name(g.branch_b),
            crate::analysis::branches::name(g.branch_d)
        );
    }
    text
}

/// The checks that have a margin for this mechanism (the others do not apply), from its home pose.
fn applying_checks(s: &Scanned) -> Vec<Check> {
    match s.m.inverse_checked(&Pose::from_array(s.home)) {
        Ok((_, report)) => report.iter().filter(|(_, m)| m.is_some()).map(|(c, _)| c).collect(),
        Err(_) => Check::ALL.to_vec(),
    }
}

/// Reachable volume at zero orientation on a 60^3 grid over the scan box (m^3).
fn volume(m: &AnyMechanism, bounds: [(f64, f64); 3]) -> f64 {
    let n = 60;
    let step = bounds.map(|(lo, hi)| (hi - lo) / n as f64);
    let at = |axis: usize, k: usize| bounds[axis].0 + (k as f64 + 0.5) * step[axis];
    let count: usize = (0..n)
        .into_par_iter()
        .map(|k| {
            let mut c = 0;
            for j in 0..n {
                for i in 0..n {
                    let p = Pose::new(at(0, i), at(1, j), at(2, k), 0.0, 0.0, 0.0);
                    if m.inverse_checked(&p).is_ok_and(|(_, r)| r.all_pass()) {
                        c += 1;
                    }
                }
            }
            c
        })
        .sum();
    count as f64 * step[0] * step[1] * step[2]
}

/// The contiguous range around `home` along one coordinate that passes every check, in `step` steps up to `limit`.
fn contiguous(m: &AnyMechanism, home: [f64; 6], axis: usize, step: f64, limit: f64) -> (f64, f64) {
    let ok = |d: f64| {
        let mut p = home;
        p[axis] += d;
        m.inverse_checked(&Pose::from_array(p)).is_ok_and(|(_, r)| r.all_pass())
    };
    let mut hi = 0.0;
    while hi + step <= limit && ok(hi + step) {
        hi += step;
    }
    let mut lo = 0.0;
    while lo - step >= -limit && ok(lo - step) {
        lo -= step;
    }
    (home[axis] + lo, home[axis] + hi)
}

/// Each axis's contiguous range about home, as offsets from it: x, y, z (m), roll and pitch (rad), found one axis
/// at a time as the summary reports them. The optimal cueing plans in these (a share of them).
pub fn ranges_about_home(m: &AnyMechanism, home: [f64; 6]) -> [(f64, f64); 5] {
    let length = m.characteristic_length();
    core::array::from_fn(|i| {
        let (lo, hi) = if i < 3 {
            line_range(m, home, i, length)
        } else {
            angle_range(m, home, i)
        };
        (lo - home[i], hi - home[i])
    })
}

/// The contiguous range of one angle around `home` that passes every check (rad), in 0.5 degree steps.
fn angle_range(m: &AnyMechanism, home: [f64; 6], axis: usize) -> (f64, f64) {
    contiguous(m, home, axis, 0.5 * DEG, 90.0 * DEG)
}

/// The contiguous range of one position coordinate around `home` that passes every check (m), in steps of a
/// thousandth of the mechanism's length, up to three lengths.
fn line_range(m: &AnyMechanism, home: [f64; 6], axis: usize, length: f64) -> (f64, f64) {
    contiguous(m, home, axis, length / 1000.0, 3.0 * length)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tool() -> AnyMechanism {
        AnyMechanism::by_name("tool5-ex").unwrap().1
    }

    /// The tool carrier at its home pose is inside; past its carriage's stroke (0.5 m, or 0.45 m tilted 30 deg:
    /// `q1 = x + L1 sin(beta)`) the reach check fails; above its dyads' reach there is no solution.
    #[test]
    fn the_tool_carriers_cells() {
        let m = tool();
        assert!(matches!(
            classify(&m, &Pose::new(0.0, 0.0, 0.4, 0.0, 0.0, 0.0)),
            Cell::Inside(_)
        ));
        assert!(matches!(
            classify(&m, &Pose::new(0.45, 0.0, 0.4, 0.0, 0.0, 0.0)),
            Cell::Inside(_)
        ));
        assert_eq!(
            classify(&m, &Pose::new(0.55, 0.0, 0.4, 0.0, 0.0, 0.0)),
            Cell::Fails(Check::Reach)
        );
        assert_eq!(
            classify(&m, &Pose::new(0.45, 0.0, 0.4, 0.0, 30.0 * DEG, 0.0)),
            Cell::Fails(Check::Reach)
        );
        assert_eq!(
            classify(&m, &Pose::new(0.0, 0.0, 1.5, 0.0, 0.0, 0.0)),
            Cell::Unreachable
        );
    }

    /// Chapter 5.1 says fig. 3.10's scheme (chapter 3.2's four chains) gives "the largest volume"; with chapter 3.2's
    /// own parameters it does not: its actuators' 0.95..1.05 hold the heave to 0.948..0.997, and the rotopod's volume
    /// at zero orientation is about twenty times the four chains' (the numbers of the book's comparison table).
    #[test]
    fn chapter_3_2s_four_chains_do_not_give_the_largest_volume_with_their_own_parameters() {
        let volume_of = |name: &str| {
            let m = AnyMechanism::by_name(name).unwrap().1;
            let AnyMechanism::Ring(r) = &m else {
                unreachable!("{name} is a ring platform")
            };
            volume(&m, ring_bounds(r))
        };
        let (rotopod, four) = (volume_of("rotopod-ch4"), volume_of("trainer-ch3"));
        assert_eq!(format!("{rotopod:.3} {four:.4}"), "0.139 0.0071");
        assert!(rotopod > 15.0 * four, "{rotopod} {four}");
    }

    /// Along x at home the carriage's stroke is the limit: [-0.5, 0.5] m to the step.
    #[test]
    fn the_tool_carriers_x_range_is_its_stroke() {
        let m = tool();
        let (lo, hi) = line_range(&m, [0.0, 0.0, 0.4, 0.0, 0.0, 0.0], 0, m.characteristic_length());
        let step = m.characteristic_length() / 1000.0;
        assert!((lo + 0.5).abs() <= step && (hi - 0.5).abs() <= step, "{lo} {hi}");
    }
}
