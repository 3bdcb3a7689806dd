//! The bench's picture: per drive, the perceived longitudinal and lateral specific force, the vehicle's and each
//! algorithm's on the platform, over time.

use std::path::Path;

use plotters::style::colors::{BLACK, BLUE, GREEN, RED};

use super::score::Trace;
use super::Report;
use crate::out::plot::{self, Panel, PlotError, Series, TimePlot};

/// Draws `traces` (per entry, per drive) of `report` to `path` (SVG or PNG).
pub fn draw(path: &Path, report: &Report, traces: &[Vec<Vec<Trace>>]) -> Result<(), PlotError> {
    let colours = [BLUE, RED, GREEN];
    let mut panels = Vec::new();
    for (d, drive) in report.drives.iter().enumerate() {
        for (axis, what) in ["longitudinal (x)", "lateral (y)"].iter().enumerate() {
            let Some(vehicle) = traces.first().and_then(|t| t.get(d)) else {
                continue;
            };
            let mut series = vec![Series::new(
                "vehicle, perceived",
                vehicle.iter().map(|p| (p.t, p.vehicle[axis])).collect(),
                BLACK,
            )];
            for (e, (entry, colour)) in report.entries.iter().zip(colours).enumerate() {
                series.push(Series::new(
                    format!("{}, perceived on the platform", entry.name),
                    traces[e][d].iter().map(|p| (p.t, p.platform[axis])).collect(),
                    colour,
                ));
            }
            panels.push(Panel {
                title: format!("{drive}: perceived {what} specific force"),
                unit: "m/s^2".into(),
                series,
                events: Vec::new(),
            });
        }
    }
    let plot = TimePlot {
        title: format!(
            "ringpod cue --compare on {}: perceived specific force",
            report.mechanism
        ),
        panels,
    };
    let height = 250 * u32::try_from(plot.panels.len().max(1)).unwrap_or(8).min(8) + 100;
    plot::save(path, (1200, height), &plot)
}
