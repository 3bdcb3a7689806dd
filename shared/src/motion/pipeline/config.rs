//! The pipeline's settings: its period, its timeouts and windows, the envelope's margins and the limits.

use super::super::envelope::EnvelopeMargins;
use super::super::limits::MotionLimits;
use super::super::spare::{SpareAxisSettings, SPARE_AXES};

/// How the reference moves toward a new setpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FollowMode {
    /// Linearly over the setpoint's own interval: a smooth path, one interval behind the source.
    Interpolate,
    /// At once: the trackers head for the newest setpoint under the limits (no interval of delay; the path of a
    /// slow source is followed in steps).
    Direct,
}

/// Pipeline settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PipelineConfig {
    /// Control period (us); 1,000 for the default 1 kHz.
    pub tick_us: u32,
    /// No valid setpoint for this long while streaming is a stream loss (us).
    pub stream_timeout_us: u32,
    /// The longest interval interpolated over; a longer gap is treated as this long (us).
    pub max_interval_us: u32,
    /// A setpoint further from the previous one than any axis travels at its velocity limit in this window is a
    /// gross jump (refused); anything nearer is followed at the limits (us).
    pub gross_jump_us: u32,
    /// Room that a limited setpoint leaves inside each check.
    pub margins: EnvelopeMargins,
    /// IK + check evaluations the envelope search may spend on one setpoint (resolution `2^-(n-1)` of the segment).
    pub limit_evaluations: u8,
    /// How the reference moves toward a new setpoint.
    pub follow: FollowMode,
    /// Velocity and acceleration limits.
    pub limits: MotionLimits,
    /// The spare axes 7 and 8 (none fitted by default).
    #[serde(default = "no_spare_axes")]
    pub spare: [SpareAxisSettings; SPARE_AXES],
}

fn no_spare_axes() -> [SpareAxisSettings; SPARE_AXES] {
    [SpareAxisSettings::NONE; SPARE_AXES]
}

impl Default for PipelineConfig {
    fn default() -> Self {
        Self {
            tick_us: 1_000,
            stream_timeout_us: 100_000,
            max_interval_us: 50_000,
            gross_jump_us: 500_000,
            margins: EnvelopeMargins::default(),
            limit_evaluations: 8,
            follow: FollowMode::Interpolate,
            limits: MotionLimits::TRAINER_MODEL,
            spare: no_spare_axes(),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn the_default_windows_nest() {
        // A stream at the slowest interpolated rate must not time out between two setpoints, and a gap as long as
        // the longest interval must not turn an ordinary step into a gross jump: tick < interval < timeout, and
        // the jump window is wider than the interval.
        let c = PipelineConfig::default();
        assert_eq!(c.tick_us, 1_000, "1 kHz");
        assert!(c.tick_us < c.max_interval_us);
        assert!(c.max_interval_us < c.stream_timeout_us);
        assert!(c.max_interval_us < c.gross_jump_us);
        assert_eq!(c.follow, FollowMode::Interpolate);
        assert!(
            c.limit_evaluations >= 2,
            "the envelope search needs both ends of the segment"
        );
    }

    #[test]
    fn follow_modes_are_named_in_lowercase() {
        // The settings protocol (and `ringpod settings set`) spell the mode as a lowercase word.
        assert_eq!(serde_json::to_string(&FollowMode::Direct).unwrap(), "\"direct\"");
        assert_eq!(
            serde_json::to_string(&FollowMode::Interpolate).unwrap(),
            "\"interpolate\""
        );
        let back: FollowMode = serde_json::from_str("\"direct\"").unwrap();
        assert_eq!(back, FollowMode::Direct);
        assert!(serde_json::from_str::<FollowMode>("\"Direct\"").is_err());
    }

    #[test]
    fn a_configuration_survives_a_round_trip() {
        let c = PipelineConfig {
            follow: FollowMode::Direct,
            tick_us: 500,
            ..PipelineConfig::default()
        };
        let text = serde_json::to_string(&c).unwrap();
        let back: PipelineConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, c);
    }
}
