//! What the lap preview did, and its state: for `cue`'s summary and the bench's table.

use serde::Serialize;

/// What the preview did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Counts {
    /// Laps completed (lap distance wrapped).
    pub laps: usize,
    /// Of them, kept as references (whole, without a departure).
    pub kept: usize,
    /// Departures from the matched lap (each fades the preview out).
    pub departures: usize,
    /// Samples whose lap distance was not finite, went backwards or jumped.
    pub bad_distance: usize,
    /// Time the preview had a share of the reference (s).
    pub previewed_s: f64,
    /// Time spent departed (s).
    pub departed_s: f64,
    /// The state at the last sample.
    pub state: Option<State>,
}

impl Counts {
    /// The counts as lines of text (`cue`'s summary).
    pub fn describe(&self) -> String {
        let mut s = format!(
            "lap preview: {} laps ({} kept as references), {} departures ({:.1} s departed), previewed {:.1} s, {} \
             samples without a usable lap distance\n",
            self.laps, self.kept, self.departures, self.departed_s, self.previewed_s, self.bad_distance
        );
        if let Some(last) = self.state {
            s += &format!(
                "lap preview at the end: lap {}, matched to lap {}, share {:.2}, alignment error {:.2} m/s^2\n",
                last.lap + 1,
                last.matched.map_or("none".into(), |m| (m + 1).to_string()),
                last.confidence,
                last.error
            );
        }
        s
    }
}

/// The preview's present state, for a report or a panel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct State {
    /// The lap being driven (0: the first).
    pub lap: usize,
    /// The earlier lap it is matched to.
    pub matched: Option<usize>,
    /// The preview's share of the reference (0 to 1).
    pub confidence: f64,
    /// The alignment's RMS specific-force error (m/s^2).
    pub error: f64,
}
