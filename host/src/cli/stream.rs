//! Arguments of `ringpod stream`: the source, the device, the checks and the report.

use clap::Args;

use super::ControllerArgs;
use crate::stream::datagram::template::{self, Template};

/// The sources other than a built-in motion (`--duration`, `--rate` and the sine's options are the motion's).
const NOT_MOTION: [&str; 4] = ["input", "udp", "telemetry_udp", "telemetry_shm"];
/// The sources other than vehicle telemetry (its format, its Live for Speed options, its cueing file and profile).
const NOT_TELEMETRY: [&str; 3] = ["input", "motion", "udp"];
/// The sources that are not live datagrams (`--udp-from`, `--udp-idle`, `--capture` are theirs).
const NOT_LIVE: [&str; 2] = ["input", "motion"];

/// The source is required: no default motion, so that a script whose arguments came out empty, or a command typed
/// without one, never moves a platform.
///
/// An option that only one kind of source reads names the others it conflicts with, so that clap refuses it with
/// them (exit 2, naming both) rather than it doing nothing. `requires` alone is not enough there: clap counts a
/// requirement as met when the required option conflicts with one given (`--profile` requires `--cue-config`,
/// which conflicts with `--input`, so `--input F --profile P` passed), hence the explicit conflicts beside it.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["input", "motion", "udp", "telemetry_udp", "telemetry_shm"])))]
#[command(group(clap::ArgGroup::new("telemetry").args(["telemetry_udp", "telemetry_shm"])))]
pub struct StreamArgs {
    /// The controller.
    #[command(flatten)]
    pub controller: ControllerArgs,
    /// With --sim: run as fast as possible instead of in real time.
    #[arg(long, requires = "sim", conflicts_with = "port")]
    pub fast: bool,
    /// A built-in motion (one source is required: --input, --motion, --udp, --telemetry-udp or --telemetry-shm).
    #[arg(long, value_enum, conflicts_with = "input")]
    pub motion: Option<crate::stream::Motion>,
    /// Length of a built-in motion (s).
    #[arg(long, default_value_t = 20.0, conflicts_with_all = NOT_MOTION)]
    pub duration: f64,
    /// With --motion sine: the pose axis.
    #[arg(long, value_enum, conflicts_with_all = NOT_MOTION)]
    pub axis: Option<crate::stream::Axis>,
    /// With --motion sine: the frequency (Hz).
    #[arg(long, conflicts_with_all = NOT_MOTION)]
    pub frequency: Option<f64>,
    /// With --motion sine: the velocity amplitude (m/s; rad/s for roll, pitch and yaw).
    #[arg(long, conflicts_with = "amplitude", conflicts_with_all = NOT_MOTION)]
    pub velocity_amplitude: Option<f64>,
    /// With --motion sine: the position amplitude (m; rad for roll, pitch and yaw).
    #[arg(long, conflicts_with_all = NOT_MOTION)]
    pub amplitude: Option<f64>,
    /// CSV file with header t,x,y,z,alpha,beta,gamma (s, m, rad unless --degrees).
    #[arg(long, conflicts_with = "udp")]
    pub input: Option<std::path::PathBuf>,
    /// Receive poses from motion-simulator software: one datagram = one text line of six numbers
    /// `x y z alpha beta gamma` (spaces, commas or semicolons; m and rad unless --degrees), or with --pose-format a
    /// motion front end's output string; sent as they arrive.
    #[arg(long, conflicts_with = "motion")]
    pub udp: Option<std::net::SocketAddr>,
    /// With --udp: read each datagram as a motion front end's pose string (FlyPT Mover, SimTools, SimHub): a
    /// preset (`flypt`, `simtools`, `simhub`) or `ENCODING:STRING`, ENCODING `decBITS`, `hexBITS`, `binBITS`
    /// (fixed-point, 0..2^BITS-1 with neutral half-way) or `fracPLACES` (-1..1), STRING the front end's output
    /// string: `<Axis1a>`..`<Axis6a>` (or `<Axis1>`, `<surge>`..`<yaw>`) the axes surge, sway, heave, roll, pitch,
    /// yaw, `<N>` the byte N, other characters as they are. Each axis is an offset from the platform's neutral,
    /// its full scale --pose-range. The book's streaming chapter gives each front end's settings.
    #[arg(long, value_name = "TEMPLATE", requires = "udp", conflicts_with = "degrees")]
    // `requires` alone lets it pass beside another source (clap takes the source group as satisfying it): named.
    #[arg(conflicts_with_all = ["input", "motion", "telemetry_udp", "telemetry_shm"])]
    #[arg(value_parser = pose_format)]
    pub pose_format: Option<Template>,
    /// With --pose-format: the offset each axis reaches at the end of its range, either way from neutral:
    /// `surge,sway,heave,roll,pitch,yaw` in mm and degrees.
    #[arg(long, value_name = "MM,MM,MM,DEG,DEG,DEG", requires = "pose_format")]
    #[arg(value_parser = template::parse_ranges, default_value = "50,50,40,20,20,20")]
    pub pose_range: [f64; 6],
    /// Receive vehicle telemetry from simulator software and cue it with the classical washout (as `ringpod cue`
    /// does with a file): one datagram per sample, in --telemetry-format.
    #[arg(long, conflicts_with_all = ["udp", "input", "motion"])]
    pub telemetry_udp: Option<std::net::SocketAddr>,
    /// Read vehicle telemetry from a game's shared memory (Windows) and cue it with the classical washout: `ac`
    /// (Assetto Corsa), `acc` (Assetto Corsa Competizione), `iracing`, `rf2` (rFactor 2) or `lmu` (Le Mans
    /// Ultimate; both through the rF2SharedMemoryMapPlugin), `ams2` (Automobilista 2 and Project CARS 2) or `ets2`
    /// (Euro Truck Simulator 2 and American Truck Simulator, through the scs-sdk-plugin). A sample is taken each
    /// time the game's own counter moves; the book's games table gives each game's fields, signs and rate. The
    /// game may start after the stream: it is waited for as a paused UDP source is (--udp-idle).
    #[cfg_attr(windows, arg(long, value_enum, value_name = "GAME"))]
    #[cfg_attr(not(windows), arg(long, value_name = "GAME", value_parser = refuse_shm))]
    #[arg(conflicts_with_all = ["udp", "input", "motion", "telemetry_udp"])]
    pub telemetry_shm: Option<crate::games::shm::Game>,
    /// With --telemetry-udp: `text` (`[t] ax ay az wx wy wz`, the units of `ringpod cue`), a game's own format
    /// (`outsim`, `outsim2`, `beamng`, `codemasters`, `f1`, `forza`, `xplane`: the book's games table), or `auto`
    /// (the first datagram a game's format recognises names it, said on stderr).
    #[arg(long, value_enum, default_value = "text", conflicts_with_all = NOT_TELEMETRY, conflicts_with = "telemetry_shm")]
    pub telemetry_format: crate::games::TelemetryFormat,
    /// With --telemetry-udp: Live for Speed's `OutSim Opts` (hexadecimal, as in its cfg.txt), which an `outsim2`
    /// packet's size alone does not always tell.
    #[arg(long, value_name = "HEX", requires = "telemetry_udp", value_parser = crate::games::outsim2::Opts::parse_hex)]
    #[arg(conflicts_with_all = NOT_TELEMETRY, conflicts_with = "telemetry_shm")]
    pub outsim_opts: Option<crate::games::outsim2::Opts>,
    /// With --telemetry-udp or --telemetry-shm: washout parameters (TOML, as for `ringpod cue --config`). The file is
    /// watched while the stream runs: a changed, valid file takes over within a second, blended in; an invalid one
    /// is refused.
    #[arg(long, requires = "telemetry", conflicts_with_all = NOT_TELEMETRY)]
    pub cue_config: Option<std::path::PathBuf>,
    /// With --telemetry-udp or --telemetry-shm: the lap preview (`on`, the default, or `off`). Where the game's
    /// format carries the car's lap position (the book's games table), the laps driven are kept and the optimal
    /// cueing's reference over its horizon is the best matching earlier lap's next seconds; a lap that departs from
    /// it fades the preview out. The classical washout has no horizon and is not changed.
    #[arg(long, value_name = "ON|OFF", default_value = "on", value_parser = on_off, action = clap::ArgAction::Set)]
    #[arg(requires = "telemetry")]
    #[arg(conflicts_with_all = NOT_TELEMETRY)]
    pub lap_preview: bool,
    /// With --cue-config: a profile of the cueing file (its `[profiles.NAME]` table overrides the base keys).
    #[arg(long, requires = "cue_config", conflicts_with_all = NOT_TELEMETRY)]
    pub profile: Option<String>,
    /// With --udp or --telemetry-udp: take datagrams from this sender only (others are counted and ignored).
    #[arg(long, conflicts_with_all = NOT_LIVE, conflicts_with = "telemetry_shm")]
    pub udp_from: Option<std::net::IpAddr>,
    /// With --udp, --telemetry-udp or --telemetry-shm: end the stream after this many seconds without a readable
    /// datagram or new sample (a source that sends only what cannot be read is as good as none; a game paused or
    /// closed for longer ends the stream: raise it to wait through pauses).
    #[arg(long, default_value_t = 2.0, conflicts_with_all = NOT_LIVE)]
    pub udp_idle: f64,
    /// Angles of --input or --udp in degrees.
    #[arg(long, conflicts_with_all = ["motion", "telemetry_udp", "telemetry_shm"])]
    pub degrees: bool,
    /// Setpoints per second for built-in motions.
    #[arg(long, default_value_t = 1000.0, conflicts_with_all = NOT_MOTION)]
    pub rate: f64,
    /// Home even if the device is homed.
    #[arg(long)]
    pub home: bool,
    /// Send poses as they come, without limiting them into the envelope on the host first: the device limits them
    /// (it always does; this shows it doing all of it, as a board streamed by other software would).
    #[arg(long)]
    pub device_limits_only: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON report at the end.
    #[arg(long)]
    pub report_json: bool,
    /// VR motion compensation (Windows): write the pose the seat followed, at the telemetry rate, where
    /// OpenXR-MotionCompensation's virtual tracker of this type reads it (`flypt`: `Local\motionRigPose`; `srs`:
    /// `Local\SimRacingStudioMotionRigPose`), about the rig file's `[motion_compensation] centre_of_rotation`.
    #[arg(long, value_enum, value_name = "TRACKER")]
    pub motion_compensation: Option<crate::vr::Tracker>,
    /// Record the run: a CSV row per telemetry sample (every 10 ms at the default 100 Hz): host and device time,
    /// the pose commanded, the pose followed (where the device's counted steps put the platform, by forward
    /// kinematics), the actuator steps, the state and the flags
    /// (limited, refused, held). `ringpod plot FILE` draws it.
    #[arg(long, value_name = "FILE.csv")]
    pub record: Option<std::path::PathBuf>,
    /// With --record: the device's telemetry rate for the run (1 to 2000 Hz, at most its control rate; 1000 is a
    /// sample every tick of the model), set back to its own afterwards. A board stores the setting both times.
    #[arg(long, requires = "record", value_parser = clap::value_parser!(u16).range(1..=2000))]
    pub record_hz: Option<u16>,
    /// With --udp or --telemetry-udp: capture every datagram that arrives on the socket (from any sender, readable
    /// or not) to a pcap file, as tcpdump writes one, with its arrival time; `ringpod cue --input FILE.pcap` cues it
    /// again, Wireshark shows it. With --telemetry-shm: each new sample as a UDP datagram (from and to 127.0.0.1,
    /// port 0) holding its `text` telemetry line `[t] ax ay az wx wy wz`, which `ringpod cue --input FILE.pcap
    /// --telemetry-format text` cues again.
    #[arg(long, value_name = "FILE.pcap", conflicts_with_all = NOT_LIVE)]
    pub capture: Option<std::path::PathBuf>,
    /// Before moving, predict the drive demand of the file's or motion's poses (inverse dynamics) on the platform
    /// the device runs, against its drives (the --geometry file's `[[drives]]`, or the preset's motor data) for a
    /// payload of --mass kg; where it exceeds the motors, say where and do not stream (exit 1).
    #[arg(long, requires = "mass", conflicts_with_all = ["udp", "telemetry_udp", "telemetry_shm"])]
    pub check_loads: bool,
    /// With --check-loads: the moving mass (kg) at the platform's centre of mass.
    #[arg(long, requires = "check_loads", conflicts_with_all = ["udp", "telemetry_udp", "telemetry_shm"])]
    pub mass: Option<f64>,
    /// With --check-loads: its inertia Ixx,Iyy,Izz (kg m^2) about the centre of mass.
    #[arg(long, allow_hyphen_values = true, requires = "check_loads", conflicts_with_all = ["udp", "telemetry_udp", "telemetry_shm"])]
    pub inertia: Option<String>,
}

/// `--pose-format`: checked whole before anything starts (a usage error naming the character), at the default
/// ranges until `--pose-range` is applied.
fn pose_format(text: &str) -> Result<Template, template::TemplateError> {
    Template::parse(text, template::DEFAULT_RANGES)
}

/// `--telemetry-shm` on a system without Windows' named file mappings: refused by name, a usage error (exit 2).
#[cfg(not(windows))]
fn refuse_shm(_: &str) -> Result<crate::games::shm::Game, String> {
    Err(format!(
        "--telemetry-shm reads a game's shared memory, which is Windows' (named file mappings): not available on {}; \
         use the game's UDP telemetry (--telemetry-udp) where it has one",
        std::env::consts::OS
    ))
}

#[cfg(test)]
mod tests;

/// `on` or `off`.
fn on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        other => Err(format!("`{other}`: on or off")),
    }
}
