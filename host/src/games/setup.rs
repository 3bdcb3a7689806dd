//! The games by name, as a rig builder looks for them: which format reads each, the port it sends to by default
//! (none when the game leaves it to you), the profile of a cueing file its sessions take, and what to set in the
//! game (the book's Game telemetry chapter says more, with its sources).

use serde::Serialize;

/// One game (or family of games sending one packet).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
pub struct Game {
    /// The name people know it by.
    pub name: &'static str,
    /// The `--telemetry-format` that reads it.
    pub format: &'static str,
    /// The port the game sends to unless told otherwise; none when it has no default (choose one).
    pub port: Option<u16>,
    /// The profile (`[profiles.NAME]` of a cueing file) a session of this game takes.
    pub profile: &'static str,
    /// What to set in the game.
    pub set: &'static str,
}

/// Every game with a format of its own, in the order of the book's table.
pub const GAMES: [Game; 8] = [
    Game {
        name: "Live for Speed",
        format: "outsim2",
        port: None,
        profile: "lfs",
        set: "cfg.txt: OutSim Mode 1, OutSim Delay 1, OutSim IP (this machine), OutSim Port, OutSim Opts 1ff",
    },
    Game {
        name: "BeamNG.drive",
        format: "beamng",
        port: Some(4444),
        profile: "beamng",
        set: "Options > Other > Protocols: MotionSim on, IP (this machine), port",
    },
    Game {
        name: "DiRT Rally 2.0, DiRT Rally, DiRT 4, GRID",
        format: "codemasters",
        port: Some(20777),
        profile: "dirt",
        set: "hardware_settings_config.xml: <udp enabled=\"true\" extradata=\"3\" ip=\"...\" port=\"20777\" delay=\"1\" />",
    },
    Game {
        name: "F1 23, F1 24, F1 25",
        format: "f1",
        port: Some(20777),
        profile: "f1",
        set: "Settings > Telemetry Settings: UDP Telemetry On, Broadcast Mode Off, IP (this machine), Port, \
              Send Rate 60 Hz, UDP Format the game's year",
    },
    Game {
        name: "Forza Motorsport (2023), Forza Motorsport 7",
        format: "forza",
        port: None,
        profile: "forza",
        set: "Settings > Gameplay & HUD > UDP Race Telemetry: Data Out On, IP Address (this machine), IP Port, \
              Packet Format Sled or Dash",
    },
    Game {
        name: "Forza Horizon 4, Forza Horizon 5",
        format: "forza",
        port: None,
        profile: "forza-horizon",
        set: "Settings > HUD and Gameplay: Data Out On, IP Address (this machine), IP Port (not 5200-5300)",
    },
    Game {
        name: "X-Plane 10, 11, 12",
        format: "xplane",
        port: None,
        profile: "xplane",
        set: "Settings > Data Output: Network via UDP for rows 4 and 16 (and 1), send to this machine's IP and \
              port (not 49000, X-Plane's own)",
    },
    Game {
        name: "Another game or front end (detected)",
        format: "auto",
        port: None,
        profile: "",
        set: "the game's own telemetry settings: this machine's IP and the port below",
    },
];

#[cfg(test)]
mod tests {
    use super::GAMES;

    /// Each game's format is one the command line reads, and a profile name is one a page may save.
    #[test]
    fn every_game_names_a_known_format_and_a_profile_a_page_may_save() {
        for g in GAMES {
            let format: Result<crate::games::TelemetryFormat, _> = clap::ValueEnum::from_str(g.format, true);
            assert!(format.is_ok(), "{g:?}");
            if !g.profile.is_empty() {
                crate::ui::profiles::profile_name(g.profile).unwrap();
            }
        }
        // The games' own defaults (the book's games chapter): F1 and the Codemasters games 20777, BeamNG 4444.
        let port = |f: &str| GAMES.iter().find(|g| g.format == f).and_then(|g| g.port);
        assert_eq!(
            (port("f1"), port("codemasters"), port("beamng")),
            (Some(20777), Some(20777), Some(4444))
        );
    }
}
