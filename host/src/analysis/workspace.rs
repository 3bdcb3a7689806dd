//! `ringpod workspace`: the reachable region of a ring platform, scanned with every check.

use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use ringpod_core::kinematics::geometry::DEG;
use ringpod_core::kinematics::presets::{Preset, PresetGeometry};
use ringpod_core::kinematics::{Check, Mechanism, Pose, RingGeometry, RingPlatform};

use crate::out::plot::{self, Picture};

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

pub(crate) fn classify(m: &RingPlatform<f64>, pose: &Pose<f64>) -> Cell {
    match m.inverse_checked(pose) {
        Err(_) => Cell::Unreachable,
        Ok((_, r)) => match r.first_failure() {
            Some(c) => Cell::Fails(c),
            None => Cell::Inside(r.singularity_index),
        },
    }
}

fn colour(cell: Cell) -> RGBColor {
    match cell {
        Cell::Unreachable => RGBColor(235, 235, 235),
        Cell::Fails(Check::Reach) => RGBColor(200, 200, 200),
        Cell::Fails(Check::CarriageSpacing) => RGBColor(240, 180, 120),
        Cell::Fails(Check::RodCrossing) => RGBColor(220, 120, 120),
        Cell::Fails(Check::JointCones) => RGBColor(180, 150, 220),
        Cell::Fails(Check::Singularity) => RGBColor(90, 90, 90),
        Cell::Fails(Check::Stability) => RGBColor(230, 210, 120),
        // Inside: from light green (index near the threshold) to dark green (well-conditioned).
        Cell::Inside(i) => {
            let t = (i / 0.3).clamp(0.0, 1.0);
            RGBColor(
                (150.0 - 120.0 * t) as u8,
                (220.0 - 90.0 * t) as u8,
                (150.0 - 110.0 * t) as u8,
            )
        }
    }
}

/// The plane of a workspace section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Section {
    /// Horizontal, at height --z.
    Xy,
    /// Vertical through the ring axis (y = 0).
    Xz,
}

/// What `workspace` is asked to do.
pub struct Options<'a> {
    /// The platform: a preset by name (a ring platform)...
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

/// Runs the command; returns the text to print.
/// The ring platform scanned: a rig file's (any valid mechanism) or a preset's, its home pose and spec ranges.
fn platform(args: &Options) -> anyhow::Result<(RingGeometry, [f64; 6], Option<[f64; 5]>)> {
    Ok(match &args.geometry {
        Some(path) => {
            let rig = crate::rig::load_platform(path)?;
            (rig.geometry, rig.home.to_array(), rig.ranges)
        }
        None => {
            let preset = Preset::from_name(args.mechanism)
                .ok_or_else(|| anyhow::anyhow!("unknown mechanism `{}`", args.mechanism))?;
            let PresetGeometry::Ring(g) = preset.geometry() else {
                anyhow::bail!("the workspace scan is for ring platforms")
            };
            let ranges = preset.spec_ranges();
            (*g, preset.home(), ranges)
        }
    })
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

pub fn run(args: &Options) -> anyhow::Result<String> {
    let (geometry, home, ranges) = platform(args)?;
    let g = &geometry;
    let m = RingPlatform::<f64>::new(g);
    let r = g.ring_radius;
    let n = args.cells;
    if args.z.is_some() && args.section != Section::Xy {
        anyhow::bail!("--z is the height of the xy section; the xz section is vertical and spans every height");
    }
    let z0 = args.z.unwrap_or(home[2]);
    crate::input::numbers::length_in_range("z", z0, r)?;
    if !(10..=2000).contains(&args.cells) {
        anyhow::bail!("--cells {} is out of range (10 to 2000)", args.cells);
    }
    // Plane coordinates (u, v) -> pose.
    let (u_range, v_range) = match args.section {
        Section::Xy => ((-r, r), (-r, r)),
        Section::Xz => ((-r, r), (0.0, 2.0 * g.rod_length.max(r))),
    };
    let pose_at = |u: f64, v: f64| match args.section {
        Section::Xy => Pose::new(u, v, z0, 0.0, 0.0, 0.0),
        Section::Xz => Pose::new(u, 0.0, v, 0.0, 0.0, 0.0),
    };
    let du = (u_range.1 - u_range.0) / n as f64;
    let dv = (v_range.1 - v_range.0) / n as f64;
    let grid = scan(n, args.quiet, &|i, j| {
        let (u, v) = (u_range.0 + (i as f64 + 0.5) * du, v_range.0 + (j as f64 + 0.5) * dv);
        classify(&m, &pose_at(u, v))
    });
    draw(args.out, &grid, u_range, v_range, args.section, g.name)?;

    let mut text = String::new();
    let inside: Vec<(f64, f64)> = grid
        .iter()
        .enumerate()
        .flat_map(|(j, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, c)| matches!(c, Cell::Inside(_)))
                .map(move |(i, _)| (i, j))
        })
        .map(|(i, j)| (u_range.0 + (i as f64 + 0.5) * du, v_range.0 + (j as f64 + 0.5) * dv))
        .collect();
    let (un, vn) = match args.section {
        Section::Xy => ("x", "y"),
        Section::Xz => ("x", "z"),
    };
    text += &format!(
        "{} section of {} ({n} x {n} cells): {:.5} m^2 inside every check\n",
        if args.section == Section::Xy {
            format!("xy at z = {z0}")
        } else {
            "xz".into()
        },
        g.name,
        inside.len() as f64 * du * dv
    );
    if let (Some(umin), Some(umax), Some(vmin), Some(vmax)) = (
        inside.iter().map(|p| p.0).reduce(f64::min),
        inside.iter().map(|p| p.0).reduce(f64::max),
        inside.iter().map(|p| p.1).reduce(f64::min),
        inside.iter().map(|p| p.1).reduce(f64::max),
    ) {
        text += &format!("  reachable {un} in [{umin:.4}, {umax:.4}] m, {vn} in [{vmin:.4}, {vmax:.4}] m\n");
    }
    text += &format!(
        "volume at zero orientation: {:.6} m^3 (60^3 grid)\n",
        volume(&m, r, g.rod_length)
    );
    for (axis, name) in ["roll", "pitch"].iter().enumerate() {
        let range = angle_range(&m, home, 3 + axis);
        text += &format!(
            "  {name} at home within [{:.1}, {:.1}] deg\n",
            range.0 / DEG,
            range.1 / DEG
        );
    }
    if let Some(ranges) = ranges {
        let coverage = crate::rig::coverage(&m, &Pose::from_array(home), &ranges);
        let (inside, total) = coverage.per_axis.iter().fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        text +=
            &format!(
            "{} spec ranges (each axis over its range, every 10 deg of yaw): {inside} of {total} poses inside: {}\n",
            g.name,
            if inside == total { "all inside" } else { "NOT all inside" }
        );
    }
    text += &format!("picture: {}\n", args.out.display());
    Ok(text)
}

/// Reachable volume at zero orientation on a 60^3 grid (m^3).
fn volume(m: &RingPlatform<f64>, r: f64, rod: f64) -> f64 {
    let n = 60;
    let (x0, z1) = (-r, 2.0 * rod.max(r));
    let d = 2.0 * r / n as f64;
    let dz = z1 / n as f64;
    let count: usize = (0..n)
        .into_par_iter()
        .map(|k| {
            let z = (k as f64 + 0.5) * dz;
            let mut c = 0;
            for j in 0..n {
                for i in 0..n {
                    let p = Pose::new(x0 + (i as f64 + 0.5) * d, x0 + (j as f64 + 0.5) * d, z, 0.0, 0.0, 0.0);
                    if m.inverse_checked(&p).is_ok_and(|(_, r)| r.all_pass()) {
                        c += 1;
                    }
                }
            }
            c
        })
        .sum();
    count as f64 * d * d * dz
}

/// The contiguous range of one angle around `home` that passes every check (rad), in 0.5 degree steps.
fn angle_range(m: &RingPlatform<f64>, home: [f64; 6], axis: usize) -> (f64, f64) {
    let ok = |a: f64| {
        let mut p = home;
        p[axis] = a;
        m.inverse_checked(&Pose::from_array(p)).is_ok_and(|(_, r)| r.all_pass())
    };
    let step = 0.5 * DEG;
    let mut hi = 0.0;
    while hi < 90.0 * DEG && ok(hi + step) {
        hi += step;
    }
    let mut lo = 0.0;
    while lo > -90.0 * DEG && ok(lo - step) {
        lo -= step;
    }
    (lo, hi)
}

/// Draws the section, coloured by the first failing check, with a legend (SVG or PNG).
fn draw(
    out: &Path,
    grid: &[Vec<Cell>],
    u: (f64, f64),
    v: (f64, f64),
    section: Section,
    name: &str,
) -> anyhow::Result<()> {
    let plane = match section {
        Section::Xy => ("x (m)", "y (m)"),
        Section::Xz => ("x (m)", "z (m)"),
    };
    let picture = SectionPicture {
        grid,
        u,
        v,
        name,
        plane,
    };
    Ok(plot::save(out, (860, 640), &picture)?)
}

/// A workspace section, coloured by the first failing check, with its legend.
struct SectionPicture<'a> {
    grid: &'a [Vec<Cell>],
    u: (f64, f64),
    v: (f64, f64),
    name: &'a str,
    plane: (&'a str, &'a str),
}

impl Picture for SectionPicture<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let fail = plot::failed(out);
        let (grid, u, v) = (self.grid, self.u, self.v);
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let n = grid.len().max(1);
        let (du, dv) = ((u.1 - u.0) / n as f64, (v.1 - v.0) / n as f64);
        let (area, side) = root.split_horizontally(root.dim_in_pixel().0.saturating_sub(200));
        let mut chart = ChartBuilder::on(&area)
            .margin(20)
            .caption(
                format!("{}: workspace section (first failing check)", self.name),
                (plot::FONT, 18),
            )
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(u.0..u.1, v.0..v.1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc(self.plane.0)
            .y_desc(self.plane.1)
            .label_style((plot::FONT, 12))
            .disable_mesh()
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(grid.iter().enumerate().flat_map(|(j, row)| {
                row.iter().enumerate().map(move |(i, c)| {
                    let (x0, y0) = (u.0 + i as f64 * du, v.0 + j as f64 * dv);
                    Rectangle::new([(x0, y0), (x0 + du, y0 + dv)], colour(*c).filled())
                })
            }))
            .map_err(|e| fail(&e))?;
        // The legend beside the section, one entry per colour.
        let legend = [
            (Cell::Inside(0.3), "inside, index 0.3+"),
            (Cell::Inside(0.0), "inside, index near limit"),
            (Cell::Fails(Check::CarriageSpacing), "carriage spacing fails"),
            (Cell::Fails(Check::RodCrossing), "rods cross"),
            (Cell::Fails(Check::JointCones), "a joint cone fails"),
            (Cell::Fails(Check::Singularity), "near a singularity"),
            (Cell::Fails(Check::Stability), "not stable"),
            (Cell::Fails(Check::Reach), "reach or stroke fails"),
            (Cell::Unreachable, "no IK solution"),
        ];
        for (k, (cell, label)) in legend.into_iter().enumerate() {
            let y = 70 + 24 * k as i32;
            side.draw(&Rectangle::new([(4, y), (20, y + 16)], colour(cell).filled()))
                .map_err(|e| fail(&e))?;
            side.draw(&Rectangle::new([(4, y), (20, y + 16)], BLACK.stroke_width(1)))
                .map_err(|e| fail(&e))?;
            side.draw(&Text::new(label, (28, y + 2), (plot::FONT, 13)))
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    }
}
