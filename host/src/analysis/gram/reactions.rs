//! Paper 003's figs. 3 and 5: the largest constraint reaction `r_max = max |r_Ci|` over the slice, without and with
//! the actuation wrenches projected onto the complement of the constraints' span. The paper gives the load as 1 N and
//! not its direction; ringpod's is [`FIG_LOAD`] (1 N down at `F` and a couple of 0.1 N m about each axis: a pure force
//! would leave fig. 5 blank, its projected constraint reactions being zero).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Vector3, Vector6};
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use ringpod_core::screws::translational::{gram, max_reactions, MaxReactions, FIG_LOAD, MIXED};

use super::{slice_map, SPAN};
use crate::error::CliError;
use crate::out::plot::{self, Picture};

/// Far from the constraint singularity: `|det M_C|` above this.
const FAR: f64 = 0.05;

/// One cell: its reactions and `det M_C`, or `None` where a chain cannot reach or the wrenches are dependent.
type Cell = Option<(MaxReactions, f64)>;

/// The slice's cells row by row (`y` up).
pub(super) struct Map {
    n: usize,
    step: f64,
    z: f64,
    cells: Vec<Cell>,
}

/// Every cell of the slice at height `z` on a grid of `step` (the same cells as the determinants' maps).
pub(super) fn scan(z: f64, step: f64) -> Map {
    let n = ((SPAN.1 - SPAN.0) / step).round() as usize;
    let at = |k: usize| SPAN.0 + (k as f64 + 0.5) * step;
    let load = Vector6::from(FIG_LOAD);
    let cells = (0..n * n)
        .into_par_iter()
        .map(|k| {
            let f = Vector3::new(at(k % n), at(k / n), z);
            Some((max_reactions(&f, MIXED, &load).ok()?, gram(&f, MIXED).ok()?.det_mc))
        })
        .collect();
    Map { n, step, z, cells }
}

/// What the maps show, in numbers: each `r_max`'s median, and its largest away from the constraint singularity.
pub(super) struct Summary {
    pub median: [f64; 2],
    pub largest_far: [f64; 2],
}

pub(super) fn summary(map: &Map) -> Summary {
    let pick = |k: usize, far: bool| -> Vec<f64> {
        let mut v: Vec<f64> = map
            .cells
            .iter()
            .flatten()
            .filter(|(_, d)| !far || d.abs() > FAR)
            .map(|(r, _)| if k == 0 { r.unprojected } else { r.projected })
            .collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let median = |v: Vec<f64>| v.get(v.len() / 2).copied().unwrap_or(f64::NAN);
    let largest = |v: Vec<f64>| v.last().copied().unwrap_or(f64::NAN);
    Summary {
        median: [median(pick(0, false)), median(pick(1, false))],
        largest_far: [largest(pick(0, true)), largest(pick(1, true))],
    }
}

/// Draws figs. 3 and 5 and says what they show.
pub(super) fn draw(z: f64, step: f64, out: &Path) -> Result<String, CliError> {
    let map = scan(z, step);
    plot::save(out, (1200, 640), &ReactionsPicture { map: &map })?;
    let s = summary(&map);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "r_max (N m) for the load {FIG_LOAD:?}: median {:.3} unprojected, {:.3} projected; largest where |det M_C| > \
         {FAR}: {:.3e} unprojected (actuation singularities), {:.3} projected",
        s.median[0], s.median[1], s.largest_far[0], s.largest_far[1]
    );
    let _ = writeln!(text, "reactions picture: {}", out.display());
    Ok(text)
}

/// Light where `r_max` is small, dark red where it is large: `log10` from -2 to 2 (N m).
fn shade(r: f64) -> RGBColor {
    let t = ((r.max(1e-12).log10() + 2.0) / 4.0).clamp(0.0, 1.0);
    RGBColor(
        (250.0 - 110.0 * t) as u8,
        (245.0 - 225.0 * t) as u8,
        (230.0 - 200.0 * t) as u8,
    )
}

struct ReactionsPicture<'a> {
    map: &'a Map,
}

impl Picture for ReactionsPicture<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let title = format!(
            "paper 003: largest constraint reaction over z = {} m, load {FIG_LOAD:?} (dark: large, log 1e-2..1e2 N m)",
            self.map.z
        );
        let body = plot::titled(root, &title, 17, out)?;
        let panels = body.split_evenly((1, 2));
        let captions = ["fig. 3: r_max, unprojected", "fig. 5: r_max, projected"];
        for (k, (area, caption)) in panels.iter().zip(captions).enumerate() {
            let m = self.map;
            let half = m.step / 2.0;
            let centre = |i: usize| SPAN.0 + (i as f64 + 0.5) * m.step;
            let map = slice_map(caption);
            map.draw(
                area,
                out,
                (0..m.n * m.n).map(|c| {
                    let (x, y) = (centre(c % m.n), centre(c / m.n));
                    let colour = m.cells[c].map_or(RGBColor(235, 235, 235), |(r, _)| {
                        shade(if k == 0 { r.unprojected } else { r.projected })
                    });
                    ([(x - half, y - half), (x + half, y + half)], colour)
                }),
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use ringpod_core::screws::translational::SLICE_Z;

    use super::*;

    /// What the paper reads from figs. 3 and 5: unprojected, `r_max` also grows near the actuation singularities,
    /// away from the constraint singularity; projected, it stays bounded there.
    #[test]
    fn projection_keeps_r_max_bounded_away_from_the_constraint_singularity() {
        let s = summary(&scan(SLICE_Z, 0.004));
        assert!(s.largest_far[0] > 100.0 * s.largest_far[1], "{:?}", s.largest_far);
        assert!(s.largest_far[1] < 10.0, "{:?}", s.largest_far);
        assert!(s.median[0] > 0.0 && s.median[1] > 0.0);
    }
}
