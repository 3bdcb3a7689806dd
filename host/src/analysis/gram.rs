//! `ringpod gram`: paper 003's figs. 3-5, the Gram determinants of its three-DOF translational mechanism's wrenches
//! over a slice of the workspace (`ringpod_core::screws::translational`), as a picture and a markdown table.
//!
//! The slice is the paper's: `z = -0.18` m on a 2 mm grid, over `x, y` in `[-0.4, 0]` m (where every chain's
//! `cos(alpha)` is in range). Each cell gets `det G_C`, `det G_A`, `det G` of the unit wrenches and the sign of
//! `det M_C` (the paper's fig. 3 colours it: violet negative, pink positive). A determinant is "near zero" below
//! `1e-4`; such a cell is "on the constraint singularity" when `det M_C` changes sign within 6 mm of it.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector3;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use ringpod_core::screws::translational::{gram, GramDeterminants, MIXED};

use crate::error::CliError;
use crate::input::numbers::BadNumber;

use crate::out::plot::{self, Picture};

mod reactions;

/// What `gram` is asked to do.
pub struct Options<'a> {
    /// The slice's height (m).
    pub z: f64,
    /// The grid's step (m).
    pub step: f64,
    /// The picture (SVG or PNG).
    pub out: &'a Path,
    /// The markdown table, if asked.
    pub table: Option<&'a Path>,
    /// Figs. 3 and 5 (the largest constraint reaction, unprojected and projected), if asked.
    pub reactions: Option<&'a Path>,
}

/// Below this a determinant counts as near zero.
const NEAR_ZERO: f64 = 1e-4;
/// A cell this near (m) to a sign change of `det M_C` is on the constraint singularity.
const BOUNDARY: f64 = 0.006;
/// The scanned square, `x` and `y` (m).
pub(super) const SPAN: (f64, f64) = (-0.4, 0.0);

/// The slice: cells row by row (`y` up), `None` where a chain cannot reach.
struct Slice {
    n: usize,
    step: f64,
    z: f64,
    cells: Vec<Option<GramDeterminants>>,
}

impl Slice {
    fn centre(&self, i: usize) -> f64 {
        SPAN.0 + (i as f64 + 0.5) * self.step
    }

    fn at(&self, i: usize, j: usize) -> Option<&GramDeterminants> {
        self.cells.get(j * self.n + i).and_then(|c| c.as_ref())
    }

    /// `det M_C` changes sign within [`BOUNDARY`] of `(i, j)` (in cells along each axis).
    fn on_boundary(&self, i: usize, j: usize) -> bool {
        let Some(here) = self.at(i, j) else { return false };
        let r = (BOUNDARY / self.step).ceil() as usize;
        let (lo_i, lo_j) = (i.saturating_sub(r), j.saturating_sub(r));
        (lo_j..=(j + r).min(self.n - 1)).any(|b| {
            (lo_i..=(i + r).min(self.n - 1))
                .any(|a| self.at(a, b).is_some_and(|g| g.det_mc.signum() != here.det_mc.signum()))
        })
    }
}

fn scan(z: f64, step: f64) -> Slice {
    let n = ((SPAN.1 - SPAN.0) / step).round() as usize;
    let at = |k: usize| SPAN.0 + (k as f64 + 0.5) * step;
    let cells = (0..n * n)
        .into_par_iter()
        .map(|k| gram(&Vector3::new(at(k % n), at(k / n), z), MIXED).ok())
        .collect();
    Slice { n, step, z, cells }
}

/// One determinant's statistics over the reachable cells.
struct Stats {
    min: f64,
    median: f64,
    max: f64,
    near_zero: usize,
    near_zero_on_boundary: usize,
}

fn stats(slice: &Slice, pick: Pick) -> Stats {
    let mut values: Vec<f64> = slice.cells.iter().flatten().map(pick).collect();
    values.sort_by(f64::total_cmp);
    let (mut near_zero, mut on_boundary) = (0, 0);
    for j in 0..slice.n {
        for i in 0..slice.n {
            if slice.at(i, j).is_some_and(|g| pick(g) < NEAR_ZERO) {
                near_zero += 1;
                on_boundary += usize::from(slice.on_boundary(i, j));
            }
        }
    }
    Stats {
        min: values.first().copied().unwrap_or(f64::NAN),
        median: values.get(values.len() / 2).copied().unwrap_or(f64::NAN),
        max: values.last().copied().unwrap_or(f64::NAN),
        near_zero,
        near_zero_on_boundary: on_boundary,
    }
}

/// One determinant of a cell.
type Pick = fn(&GramDeterminants) -> f64;

/// Each determinant's name, what it is of, and how to take it from a cell.
const PICKS: [(&str, &str, Pick); 3] = [
    ("det G_C", "constraint wrenches", |g| g.constraints),
    ("det G_A", "actuation wrenches", |g| g.actuation),
    ("det G", "all six", |g| g.all),
];

pub fn run(args: &Options) -> Result<String, CliError> {
    if !(args.step.is_finite() && (0.0005..=0.05).contains(&args.step)) {
        return Err(BadNumber::given("step", args.step, "the grid's step is 0.0005 to 0.05 m").into());
    }
    if !(args.z.is_finite() && (-0.4..=0.0).contains(&args.z)) {
        return Err(BadNumber::given("z", args.z, "the mechanism reaches heights from -0.4 to 0 m").into());
    }
    let outputs: Vec<&std::path::Path> = [Some(args.out), args.table].into_iter().flatten().collect();
    crate::out::file::check_outputs(&outputs, &[]).map_err(|(out, e)| CliError::file(out, e))?;
    let slice = scan(args.z, args.step);
    plot::save(args.out, (1200, 1060), &SlicePicture { slice: &slice })?;
    let reachable = slice.cells.iter().flatten().count();
    let mut text = format!(
        "paper 003's translational mechanism, slice z = {} m, {} x {} cells of {} mm: {reachable} reachable\n",
        slice.z,
        slice.n,
        slice.n,
        slice.step * 1e3
    );
    let all_stats: Vec<Stats> = PICKS.iter().map(|(_, _, pick)| stats(&slice, *pick)).collect();
    let _ = writeln!(
        text,
        "{:<8} {:>11} {:>11} {:>11}  cells below {NEAR_ZERO:e} (on the det M_C sign boundary)",
        "", "min", "median", "max"
    );
    for ((name, _, _), s) in PICKS.iter().zip(&all_stats) {
        let _ = writeln!(
            text,
            "{name:<8} {:>11.3e} {:>11.3e} {:>11.3e}  {} ({})",
            s.min, s.median, s.max, s.near_zero, s.near_zero_on_boundary
        );
    }
    let _ = writeln!(text, "picture: {}", args.out.display());
    if let Some(path) = args.reactions {
        text += &reactions::draw(args.z, args.step, path)?;
    }
    if let Some(path) = args.table {
        crate::out::file::write(path, table(&slice, &all_stats).as_bytes()).map_err(|e| CliError::file(path, e))?;
        let _ = writeln!(text, "table: {}", path.display());
    }
    Ok(text)
}

/// The markdown table: how it was made, the statistics, and the values every 50 mm.
fn table(slice: &Slice, all_stats: &[Stats]) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "# Paper 003: Gram determinants over the slice z = {} m\n", slice.z);
    let _ = writeln!(
        t,
        "Generated by `ringpod gram --z {} --step {} --out ... --table ...` (`host/src/analysis/gram.rs`, the \
         mechanism in `shared/src/screws/translational.rs`). Unit wrenches about F, SI units; the chains assembled \
         as in the specification's test pose (SCREWS.md 4, T5; the paper prints no pose): every elbow \
         `sin(alpha) < 0`, the third chain on the other side. {} x {} \
         cells of {} mm over x, y in [-0.4, 0] m, {} reachable. \"Near zero\": below {NEAR_ZERO:e}; \"on the \
         boundary\": `det M_C` changes sign within 6 mm.\n",
        slice.z,
        slice.step,
        slice.n,
        slice.n,
        slice.step * 1e3,
        slice.cells.iter().flatten().count()
    );
    let _ = writeln!(
        t,
        "| determinant | of | min | median | max | cells near zero | of them on the boundary |"
    );
    let _ = writeln!(t, "|---|---|---|---|---|---|---|");
    for ((name, of, _), s) in PICKS.iter().zip(all_stats) {
        let _ = writeln!(
            t,
            "| {name} | {of} | {:.3e} | {:.3e} | {:.3e} | {} | {} |",
            s.min, s.median, s.max, s.near_zero, s.near_zero_on_boundary
        );
    }
    if let Ok(g) = gram(&Vector3::new(-0.25, -0.12, slice.z), MIXED) {
        let _ = writeln!(
            t,
            "\nAt x = -0.25, y = -0.12 m (the specification's test pose T5, SCREWS.md 4, on this \
             slice; the paper prints no values), F = (-0.25, \
             -0.12, {}): det M_C = {:.5}, det G_C = {:.5} (= det M_C^2), det G_A = {:.5}, det G = {:.5}.",
            slice.z, g.det_mc, g.constraints, g.actuation, g.all
        );
    }
    let _ = writeln!(t, "\nValues every 50 mm (x, y in m; angles in degrees):\n");
    let _ = writeln!(
        t,
        "| x | y | theta1 | theta2 | theta3 | det M_C | det G_C | det G_A | det G |"
    );
    let _ = writeln!(t, "|---|---|---|---|---|---|---|---|---|");
    for k in 1..8 {
        for l in 1..8 {
            let (x, y) = (-0.4 + 0.05 * l as f64, -0.4 + 0.05 * k as f64);
            match gram(&Vector3::new(x, y, slice.z), MIXED) {
                Ok(g) => {
                    let th = g.theta.map(|a| a.to_degrees());
                    let _ = writeln!(
                        t,
                        "| {x:.2} | {y:.2} | {:.2} | {:.2} | {:.2} | {:.5} | {:.5} | {:.5} | {:.3e} |",
                        th[0], th[1], th[2], g.det_mc, g.constraints, g.actuation, g.all
                    );
                }
                Err(e) => {
                    let _ = writeln!(t, "| {x:.2} | {y:.2} | {e} | | | | | | |");
                }
            }
        }
    }
    t
}

/// A map of the slice's cells, `x` and `y` over [`SPAN`], with its caption.
fn slice_map(caption: &str) -> plot::CellMap<'_> {
    plot::CellMap {
        caption: (caption, 15),
        margin: 12,
        label_areas: (36, 56),
        axes: ("x (m)", "y (m)", 11),
        u: SPAN,
        v: SPAN,
    }
}

/// Dark where a determinant is small (the wrenches dependent), light where it is near 1; `log10` from -6 to 0.
fn shade(d: f64) -> RGBColor {
    let t = ((d.max(1e-12).log10() + 6.0) / 6.0).clamp(0.0, 1.0);
    RGBColor(
        (20.0 + 235.0 * t) as u8,
        (20.0 + 215.0 * t) as u8,
        (60.0 + 150.0 * t) as u8,
    )
}

/// Four maps of the slice: the sign of `det M_C` (fig. 3's colours) and the three determinants (fig. 4).
struct SlicePicture<'a> {
    slice: &'a Slice,
}

impl Picture for SlicePicture<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let title = format!(
            "paper 003: Gram determinants over the slice z = {} m ({} mm grid; dark: near 0, log scale 1e-6..1)",
            self.slice.z,
            self.slice.step * 1e3
        );
        let body = plot::titled(root, &title, 18, out)?;
        let panels = body.split_evenly((2, 2));
        let sign = |g: &GramDeterminants| {
            if g.det_mc < 0.0 {
                RGBColor(120, 70, 170)
            } else {
                RGBColor(240, 160, 200)
            }
        };
        type Colour<'c> = Box<dyn Fn(&GramDeterminants) -> RGBColor + 'c>;
        let maps: [(&str, Colour); 4] = [
            ("sign of det M_C (violet < 0, pink > 0)", Box::new(sign)),
            (
                "a: det G_C, constraint wrenches",
                Box::new(|g: &GramDeterminants| shade(g.constraints)),
            ),
            (
                "b: det G_A, actuation wrenches",
                Box::new(|g: &GramDeterminants| shade(g.actuation)),
            ),
            ("c: det G, all six", Box::new(|g: &GramDeterminants| shade(g.all))),
        ];
        for (area, (caption, colour)) in panels.iter().zip(maps) {
            self.map(area, caption, &*colour, out)?;
        }
        Ok(())
    }
}

impl SlicePicture<'_> {
    fn map<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        caption: &str,
        colour: &dyn Fn(&GramDeterminants) -> RGBColor,
        out: &Path,
    ) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let s = self.slice;
        let half = s.step / 2.0;
        let map = slice_map(caption);
        map.draw(
            area,
            out,
            (0..s.n * s.n).map(|k| {
                let (x, y) = (s.centre(k % s.n), s.centre(k / s.n));
                let c = s.at(k % s.n, k / s.n).map_or(RGBColor(235, 235, 235), colour);
                ([(x - half, y - half), (x + half, y + half)], c)
            }),
        )
    }
}

#[cfg(test)]
mod tests {
    use ringpod_core::screws::translational::SLICE_Z;

    use super::*;

    /// The slice's statistics say what the paper's fig. 4 shows: `det G_C` near zero only on the sign boundary of
    /// `det M_C`; `det G` near zero there and elsewhere too (the actuation singularities); and never below `det G_C`
    /// times `det G_A` would allow.
    #[test]
    fn the_paper_slice_says_what_fig_4_shows() {
        let slice = scan(SLICE_Z, 0.004);
        let [c, a, g] = PICKS.map(|(_, _, pick)| stats(&slice, pick));
        assert!(
            c.near_zero > 0 && c.near_zero == c.near_zero_on_boundary,
            "{} {}",
            c.near_zero,
            c.near_zero_on_boundary
        );
        assert!(g.near_zero > c.near_zero && g.near_zero_on_boundary < g.near_zero);
        assert!(a.near_zero < g.near_zero);
        assert!(c.max <= 1.0 && g.min >= -1e-12);
    }
}
