//! A workspace section as a picture: each cell coloured by the first check that fails there (or how well
//! conditioned it is inside), with a legend of the checks the mechanism has.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use ringpod_core::kinematics::Check;

use super::Cell;
use crate::out::plot::{self, Picture};

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

/// A workspace section, coloured by the first failing check, with its legend.
pub(super) struct Section<'a> {
    /// Rows of cells, `v` upwards, each `u` rightwards.
    pub grid: &'a [Vec<Cell>],
    /// The plane's ranges.
    pub u: (f64, f64),
    pub v: (f64, f64),
    /// The mechanism's name and the section's, for the caption.
    pub name: &'a str,
    pub title: &'a str,
    /// The axes' labels with units.
    pub axes: (String, String),
    /// The checks the mechanism has (only these are in the legend).
    pub applies: &'a [Check],
}

/// Draws the section (SVG or PNG).
pub(super) fn draw(out: &Path, section: &Section) -> Result<(), plot::PlotError> {
    plot::save(out, (860, 640), section)
}

impl Picture for Section<'_> {
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
        let caption = format!("{}: workspace, {} (first failing check)", self.name, self.title);
        let map = plot::CellMap {
            caption: (&caption, 18),
            margin: 20,
            label_areas: (40, 64),
            axes: (self.axes.0.as_str(), self.axes.1.as_str(), 12),
            u,
            v,
        };
        map.draw(
            &area,
            out,
            grid.iter().enumerate().flat_map(|(j, row)| {
                row.iter().enumerate().map(move |(i, c)| {
                    let (x0, y0) = (u.0 + i as f64 * du, v.0 + j as f64 * dv);
                    ([(x0, y0), (x0 + du, y0 + dv)], colour(*c))
                })
            }),
        )?;
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
        let shown = legend.into_iter().filter(|(cell, _)| match cell {
            Cell::Fails(check) => self.applies.contains(check),
            _ => true,
        });
        for (k, (cell, label)) in shown.enumerate() {
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
