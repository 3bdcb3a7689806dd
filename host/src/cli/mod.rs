//! Command-line interface definition.

pub mod requests;

pub use requests::platform;

use clap::{Args, Parser, Subcommand};

/// ringpod: kinematics and control of parallel platforms whose carriages run on a circular guide.
#[derive(Debug, Parser)]
#[command(name = "ringpod", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Lists the built-in geometries, or writes one as a rig file (`--export NAME > my-rig.toml`) to start your own.
    Presets {
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Print this preset (a ring platform) as a rig file (TOML).
        #[arg(long, value_name = "NAME")]
        export: Option<String>,
    },
    /// Rig files: your own ring platform in TOML (`ringpod presets --export trainer-model` writes one to start from).
    Rig {
        #[command(subcommand)]
        action: RigAction,
    },
    /// Inverse kinematics: the six actuator values for a pose, with every workspace check and its margin.
    /// Exits 0 whenever the pose has a solution (failing checks are reported), 1 when it has none.
    Ik(PoseArgs),
    /// Workspace checks of a pose. Exits 0 when all pass, 3 when any fails, 1 when the pose has no solution.
    /// With --tip-over: a payload over the carriages' polygon under a lateral acceleration (3 when it tips).
    Check(CheckArgs),
    /// Forward kinematics: the pose for six actuator values, by Newton iteration from a guess.
    Fk(FkArgs),
    /// The velocity problem at a pose (A p' = -B q', chapter 4): the actuator rates for --pose-rates, or the pose
    /// rates and the platform's angular velocity for --actuator-rates; A, B and the condition number of each.
    Rates(RatesArgs),
    /// Structural analysis (chapters 2 and 5.1): mobility by the structural formula, every joint's unit screw at a
    /// pose, the wrenches each chain transmits, each chain's determinant and the mechanism's wrench determinant;
    /// or one of the source's chains of figs. 5.1-5.3 with --chain.
    Structure(StructureArgs),
    /// A labelled isometric drawing of a mechanism at a pose (ring, carriages, chains, platform, axes; the tool
    /// carrier's guide, dyads, frame and tool), every point from its inverse kinematics, as SVG or PNG.
    Draw(DrawArgs),
    /// Streams poses to the controller (a board on --port, or the simulated controller with --sim): connects,
    /// powers up and homes if needed, streams (poses outside the envelope limited into it), then stops and waits for
    /// rest. Exit codes: 0 every pose followed (limited ones included), 1 the stream could not start, 3 input
    /// lines that could not be read, 4 setpoints the device refused, 5 the device stopped streaming or faulted,
    /// 6 the link was lost, 7 the --record or --capture file could not be written, 128 + the signal when stopped by one (130 Ctrl-C, 143 SIGTERM).
    Stream(Box<StreamArgs>),
    /// Draws a run record (`stream --record`): commanded vs followed per pose axis, the actuator positions, and
    /// the events (limits, refusals, state changes), labelled, as PNG or SVG; or with --derivatives the velocity
    /// and acceleration of each pose axis.
    Plot {
        /// The run record (CSV).
        record: std::path::PathBuf,
        /// The picture: .png or .svg.
        #[arg(long)]
        out: std::path::PathBuf,
        /// Draw the velocity and acceleration of each pose axis instead (numerically: a least-squares quadratic
        /// over --window around each sample).
        #[arg(long)]
        derivatives: bool,
        /// With --derivatives: the window of the fit (s).
        #[arg(long, default_value_t = 0.05, requires = "derivatives")]
        window: f64,
        /// With --derivatives: draw and measure from this device time on (s); the fit still uses the samples
        /// around it, so a stretch of a fast oscillation shows its waveform.
        #[arg(long, requires = "derivatives")]
        from: Option<f64>,
        /// With --derivatives: draw and measure up to this device time (s).
        #[arg(long, requires = "derivatives")]
        to: Option<f64>,
    },
    /// A live terminal view of the device from its telemetry: state, supplies and outputs, every input, each
    /// axis's position and switches, the counters and the tick cost. q, Esc or Ctrl-C ends it.
    Monitor {
        /// The board's serial port.
        #[arg(long, conflicts_with = "sim")]
        port: Option<String>,
        /// A fresh simulated controller (ticking in real time).
        #[arg(long)]
        sim: bool,
        /// End after this many redraws (ten a second), for scripts and tests.
        #[arg(long)]
        frames: Option<u64>,
    },
    /// One command to the controller (--port, or a fresh simulated controller with --sim).
    Device(DeviceArgs),
    /// The workbench in a browser: the platform live in 3D, the controls with the supervisor's gating, cueing on a
    /// replayed drive, the rig file checked as you type, run records. Prints the URL to open (with its per-run
    /// token); runs until interrupted.
    Ui(UiArgs),
    /// Lists the serial ports (a board shows up as a USB CDC port, /dev/ttyACM* on Linux).
    Ports,
    /// Static drive loads for a payload at a pose (ring platforms): carriage torques and actuator forces.
    Loads(LoadsArgs),
    /// Loads of a tool wrench on the five-DOF tool carrier (paper 003's projection method): drive forces and
    /// torques, the X guide's bearing load, the frame pivots' forces and the constraint couple.
    Reactions(ReactionsArgs),
    /// Paper 003's figs. 3-5: the Gram determinants of its three-DOF translational mechanism's wrenches (constraint,
    /// actuation, all) over a slice of its workspace, drawn as four maps (with the sign of det M_C) and written as
    /// a markdown table.
    Gram {
        /// The slice's height (m).
        #[arg(long, default_value_t = ringpod_core::screws::translational::SLICE_Z, allow_hyphen_values = true)]
        z: f64,
        /// The grid's step (m).
        #[arg(long, default_value_t = 0.002)]
        step: f64,
        /// The picture: .png or .svg.
        #[arg(long)]
        out: std::path::PathBuf,
        /// Also write the statistics and a table of values every 50 mm (markdown).
        #[arg(long, value_name = "FILE.md")]
        table: Option<std::path::PathBuf>,
    },
    /// Scans the workspace of a ring platform or the tool carrier with all its checks (in parallel), draws a section
    /// (positions, or the two tilts) coloured by the limiting check, and prints the cells inside, the reachable
    /// ranges, the volume, each axis's range at home, and whether the spec ranges are inside.
    Workspace(WorkspaceArgs),
    /// Motion cueing: vehicle telemetry (specific force, angular rates) to platform poses by the classical washout
    /// (translation high-passed, sustained force by tilt coordination, yaw by heading), every pose limited into the
    /// envelope; writes the pose CSV that `stream --input` reads. Exits 0, or 3 when rows could not be used.
    Cue(CueArgs),
    /// Serves the simulated controller on a pseudo-terminal and prints its path, so that the serial transport
    /// (and any other program) can talk to it as to a board. Runs until interrupted.
    Simulate {
        /// Serve on a pseudo-terminal (the only transport for now).
        #[arg(long, required = true)]
        pty: bool,
        /// Simulate this rig file's platform (with the trainer model's drives and switches) instead of the trainer
        /// model.
        #[arg(long, value_name = "RIG.toml")]
        geometry: Option<std::path::PathBuf>,
        /// Simulate this preset's ring platform (`ringpod presets`), as --geometry does with its exported rig file.
        #[arg(long, value_name = "PRESET", conflicts_with = "geometry")]
        mechanism: Option<String>,
    },
}

#[derive(Debug, Subcommand)]
pub enum RigAction {
    /// Checks a rig file (every key, the home pose inside every check) and measures its spec coverage: each axis
    /// over its range alone, and the share of the combined box inside. Exits 0 when the rig is valid and its spec
    /// ranges (if given) are covered axis by axis, 3 when they are not, 1 when the file is invalid.
    Check {
        /// The rig file.
        file: std::path::PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Searches dimensions (ring radius, rod length, home height, every platform joint, every elbow chain's arm) for
    /// a template rig's chains, joint limits and [spec] ranges, and prints the best as a rig file with its coverage.
    /// Exits 0 when it covers the spec, 3 when the best found does not.
    Design {
        /// The template rig file (its [spec] ranges are the target).
        file: std::path::PathBuf,
        /// Cover all spec axes at once (the combined box), not each axis over its range alone.
        #[arg(long)]
        combined: bool,
        /// Move only the elbow chains' arms (shoulder radius and height, upper arm, forearm); keep the ring, rods,
        /// platform joints and home as the template has them.
        #[arg(long)]
        arms_only: bool,
        /// Random starts of the hill climb.
        #[arg(long, default_value_t = 40, value_parser = clap::value_parser!(u32).range(1..=10_000))]
        starts: u32,
        /// Steps from each start.
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..=100_000))]
        steps: u32,
        /// Seed of the search (the same seed gives the same design).
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Debug, Args)]
pub struct LoadsArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// Payload mass (kg), at the geometry's centre of mass: with --input, the whole moving mass.
    #[arg(long)]
    pub mass: f64,
    /// A motion (pose CSV as `stream --input` reads: t,x,y,z,alpha,beta,gamma): report the peak drive demand of each
    /// axis along it (inverse dynamics: gravity and the payload's inertia; the chains massless).
    #[arg(long, conflicts_with = "pose")]
    pub input: Option<std::path::PathBuf>,
    /// Payload inertia about its centre of mass, platform frame: Ixx,Iyy,Izz (kg m^2). Default: none (a point mass).
    #[arg(long, allow_hyphen_values = true, requires = "input")]
    pub inertia: Option<String>,
    /// With --input: draw each axis's demand against what its drive gives at that speed (.svg or .png).
    #[arg(long, requires = "input", value_name = "FILE")]
    pub plot: Option<std::path::PathBuf>,
}

#[derive(Debug, Args)]
pub struct ReactionsArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees; gamma 0). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// Wrench on the tool at its point, base frame: fx,fy,fz (N),mx,my,mz (N m).
    #[arg(long, allow_hyphen_values = true)]
    pub wrench: String,
}

/// Device commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DeviceAction {
    /// Print the status as JSON.
    Status,
    /// Power up (logic, then power).
    Enable,
    /// Shut down (drivers, power, logic).
    Disable,
    /// Home all axes (waits until done).
    Home,
    /// Start taking setpoints.
    Start,
    /// Ramp to rest.
    Stop,
    /// Clear a latched fault.
    Clear,
    /// Settings sections: `config` lists them all, `config get SECTION[.PATH]`, `config set SECTION.PATH VALUE`
    /// (`stream.timeout_ms 250`, `axes.2.reverse true`; stored in the board's flash).
    Config,
    /// Every input: its electrical level and its debounced state (with --watch: each change as it happens).
    Inputs,
    /// `jog AXIS DISTANCE`: move one axis (1-6) by degrees (carriage) or mm (linear actuator) at its slow homing
    /// speed, stopping at its switch. Powered (`enable`), or Ready; home again afterwards.
    Jog,
    /// `buzz AXIS`: ten short moves back and forth of one axis (1-6): a motor that hums without turning shows.
    Buzz,
    /// `rig load RIG.toml`: check a rig file and store it on the device for its next start (supplies off);
    /// `rig show`: the rig it runs, as a rig file.
    Rig,
    /// Restart the controller (supplies off) once it has stored everything: a loaded rig or setting runs.
    Restart,
    /// `aux N on|off`: switch auxiliary output N (1 or 2: AUX1 on PC15, AUX2 on PC13). On only while homed and
    /// holding or streaming (Ready, Running); a fault, an e-stop, a disable, homing or a jog switches both off.
    Aux,
}

#[derive(Debug, Args)]
pub struct DeviceArgs {
    /// What to do.
    #[arg(value_enum)]
    pub action: DeviceAction,
    /// For `config`: nothing (every section), `get SECTION[.PATH]` or `set SECTION.PATH VALUE` (VALUE in JSON).
    /// Sections: stream (timeout_ms, gross_jump_ms, follow, margins.N, telemetry_hz), control (tick_hz), motion
    /// (pose_velocity.N, pose_acceleration.N, actuator_velocity.N, actuator_acceleration.N), inputs (active_low,
    /// debounce_ms), axes.N (steps_per_unit, reverse),
    /// homing, supervisor; N counts from 0, e.g. `set axes.4.reverse true`, `set stream.timeout_ms 200`. For
    /// `jog`: AXIS DISTANCE; for `buzz`: AXIS; for `rig`: `load RIG.toml` or `show`; for `aux`: N on|off.
    #[arg(allow_negative_numbers = true)]
    pub config: Vec<String>,
    /// Serial port of the board (USB CDC).
    #[arg(long, conflicts_with = "sim")]
    pub port: Option<String>,
    /// A fresh in-process simulated controller.
    #[arg(long)]
    pub sim: bool,
    /// With `inputs`: keep reading (every 20 ms) and print a line for each change, until Ctrl-C.
    #[arg(long)]
    pub watch: bool,
}

#[derive(Debug, Args)]
pub struct StreamArgs {
    /// The controller.
    #[command(flatten)]
    pub controller: ControllerArgs,
    /// With --sim: run as fast as possible instead of in real time.
    #[arg(long, requires = "sim")]
    pub fast: bool,
    /// Built-in motion.
    #[arg(long, value_enum, conflicts_with = "input")]
    pub motion: Option<crate::stream::Motion>,
    /// Length of a built-in motion (s).
    #[arg(long, default_value_t = 20.0)]
    pub duration: f64,
    /// With --motion sine: the pose axis.
    #[arg(long, value_enum)]
    pub axis: Option<crate::stream::Axis>,
    /// With --motion sine: the frequency (Hz).
    #[arg(long)]
    pub frequency: Option<f64>,
    /// With --motion sine: the velocity amplitude (m/s; rad/s for roll, pitch and yaw).
    #[arg(long, conflicts_with = "amplitude")]
    pub velocity_amplitude: Option<f64>,
    /// With --motion sine: the position amplitude (m; rad for roll, pitch and yaw).
    #[arg(long)]
    pub amplitude: Option<f64>,
    /// CSV file with header t,x,y,z,alpha,beta,gamma (s, m, rad unless --degrees).
    #[arg(long, conflicts_with = "udp")]
    pub input: Option<std::path::PathBuf>,
    /// Receive poses from motion-simulator software: one datagram = one text line of six numbers
    /// `x y z alpha beta gamma` (spaces, commas or semicolons; m and rad unless --degrees), sent as they arrive.
    #[arg(long, conflicts_with = "motion")]
    pub udp: Option<std::net::SocketAddr>,
    /// Receive vehicle telemetry from simulator software and cue it with the classical washout (as `ringpod cue`
    /// does with a file): one datagram per sample, in --telemetry-format.
    #[arg(long, conflicts_with_all = ["udp", "input", "motion"])]
    pub telemetry_udp: Option<std::net::SocketAddr>,
    /// With --telemetry-udp: `text` (`[t] ax ay az wx wy wz`, the units of `ringpod cue`), a game's own format
    /// (`outsim`, `outsim2`, `beamng`, `codemasters`, `f1`, `forza`, `xplane`: the README's games table), or `auto`
    /// (the first datagram a game's format recognises names it, said on stderr).
    #[arg(long, value_enum, default_value = "text")]
    pub telemetry_format: crate::stream::datagram::TelemetryFormat,
    /// With --telemetry-udp: washout parameters (TOML, as for `ringpod cue --config`). The file is watched while
    /// the stream runs: a changed, valid file takes over within a second, blended in; an invalid one is refused.
    #[arg(long, requires = "telemetry_udp", conflicts_with_all = ["udp", "input", "motion"])]
    pub cue_config: Option<std::path::PathBuf>,
    /// With --cue-config: a profile of the cueing file (its `[profiles.NAME]` table overrides the base keys).
    #[arg(long, requires = "cue_config")]
    pub profile: Option<String>,
    /// With --udp or --telemetry-udp: take datagrams from this sender only (others are counted and ignored).
    #[arg(long, conflicts_with_all = ["input", "motion"])]
    pub udp_from: Option<std::net::IpAddr>,
    /// With --udp or --telemetry-udp: end the stream after this many seconds without a readable datagram (a source
    /// that sends only what cannot be read is as good as none).
    #[arg(long, default_value_t = 2.0)]
    pub udp_idle: f64,
    /// Angles of --input or --udp in degrees.
    #[arg(long)]
    pub degrees: bool,
    /// Setpoints per second for built-in motions.
    #[arg(long, default_value_t = 1000.0)]
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
    /// Record the run: a CSV row per telemetry sample (every 10 ms at the default 100 Hz): host and device time,
    /// the pose commanded, the pose followed (after limiting), the actuator steps, the state and the flags
    /// (limited, refused, held). `ringpod plot FILE` draws it.
    #[arg(long, value_name = "FILE.csv")]
    pub record: Option<std::path::PathBuf>,
    /// With --record: the device's telemetry rate for the run (1 to 2000 Hz, at most its control rate; 1000 is a
    /// sample every tick of the model), set back to its own afterwards. A board stores the setting both times.
    #[arg(long, requires = "record", value_parser = clap::value_parser!(u16).range(1..=2000))]
    pub record_hz: Option<u16>,
    /// With --udp or --telemetry-udp: capture every datagram that arrives on the socket (from any sender, readable
    /// or not) to a pcap file, as tcpdump writes one, with its arrival time; `ringpod cue --input FILE.pcap` cues it
    /// again, Wireshark shows it.
    #[arg(long, value_name = "FILE.pcap", conflicts_with_all = ["input", "motion"])]
    pub capture: Option<std::path::PathBuf>,
    /// Before moving, predict the drive demand of the file's or motion's poses (inverse dynamics) on the platform
    /// the device runs, against its drives (the --geometry file's `[[drives]]`, or the preset's motor data) for a
    /// payload of --mass kg; where it exceeds the motors, say where and do not stream (exit 1).
    #[arg(long, requires = "mass", conflicts_with_all = ["udp", "telemetry_udp"])]
    pub check_loads: bool,
    /// With --check-loads: the moving mass (kg) at the platform's centre of mass.
    #[arg(long, requires = "check_loads")]
    pub mass: Option<f64>,
    /// With --check-loads: its inertia Ixx,Iyy,Izz (kg m^2) about the centre of mass.
    #[arg(long, allow_hyphen_values = true, requires = "check_loads")]
    pub inertia: Option<String>,
}

#[derive(Debug, Args)]
pub struct Common {
    /// Geometry: trainer-model, trainer-elbow, trainer-ch5, rotopod-ch4, tool5-ex (see `ringpod presets`).
    #[arg(long, short, default_value = "trainer-model")]
    pub mechanism: String,
    /// Your own ring platform: a rig file (TOML; see `ringpod rig check`), instead of --mechanism.
    #[arg(long, value_name = "RIG.toml")]
    pub geometry: Option<std::path::PathBuf>,
    /// Angles in degrees, on input and output (default radians).
    #[arg(long)]
    pub degrees: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct RatesArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// x',y',z',alpha',beta',gamma' (m/s; rad/s, or deg/s with --degrees): print the actuator rates.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "actuator_rates")]
    pub pose_rates: Option<String>,
    /// Six actuator rates (rad/s or m/s; deg/s for angles with --degrees): print the pose rates.
    #[arg(long, allow_hyphen_values = true, conflicts_with = "pose_rates")]
    pub actuator_rates: Option<String>,
}

#[derive(Debug, Args)]
pub struct StructureArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// One of the source's single chains at its coordinates, instead of a mechanism.
    #[arg(long, value_enum, conflicts_with_all = ["pose", "geometry", "mechanism"])]
    pub chain: Option<crate::analysis::structure::SourceChain>,
}

#[derive(Debug, Args)]
pub struct DrawArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// The picture: .svg or .png.
    #[arg(long)]
    pub out: std::path::PathBuf,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// Tip-over instead of the workspace checks (ring platforms): the largest lateral acceleration in each
    /// direction before the payload's centre of mass, projected along g - a onto the ring plane, leaves the
    /// carriages' polygon, and the weakest over all directions.
    #[arg(long)]
    pub tip_over: bool,
    /// With --tip-over: the payload's centre of mass X,Y,Z in the platform frame (m). Default: the geometry's.
    #[arg(long, allow_hyphen_values = true, requires = "tip_over", value_name = "X,Y,Z")]
    pub payload_com: Option<String>,
    /// With --tip-over: a lateral acceleration AX,AY of the platform (m/s^2, base frame): does it tip, by what
    /// margin.
    #[arg(long, allow_hyphen_values = true, requires = "tip_over", value_name = "AX,AY")]
    pub accel: Option<String>,
}

#[derive(Debug, Args)]
pub struct PoseArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// The tool carrier's dyad assemblies: `minus` (q2, q4 = theta - kappa, the preset's) or `plus` (theta + kappa)
    /// for both dyads, `B,D` for each (`minus,plus`), or `all` to print the four.
    #[arg(long, value_parser = crate::analysis::branches::parse, value_name = "minus|plus|B,D|all")]
    pub branch: Option<crate::analysis::branches::Assembly>,
}

#[derive(Debug, Args)]
pub struct FkArgs {
    #[command(flatten)]
    pub common: Common,
    /// Six actuator values in the mechanism's order (see `ringpod ik`): angles in radians unless --degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub actuators: String,
    /// Starting pose x,y,z,alpha,beta,gamma for the iteration (the platform's last known pose): the answer must be
    /// within half a ring radius and half a radian of it. Default: the preset's home pose turned by the yaw the
    /// carriages show, and the answer within a ring radius and a radian of that.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
    /// Maximum Newton iterations (1 to 255).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u8).range(1..))]
    pub max_iterations: u8,
    /// Also answer with a pose outside the workspace checks (the math alone; by default such a pose is an error
    /// naming the check it fails).
    #[arg(long)]
    pub anywhere: bool,
    /// The tool carrier's dyad assemblies the actuators were solved on (`ik --branch`): `minus`, `plus` or `B,D`.
    /// The answer must take them (IK at it gives the actuators back).
    #[arg(long, value_parser = crate::analysis::branches::parse, value_name = "minus|plus|B,D")]
    pub branch: Option<crate::analysis::branches::Assembly>,
}

#[derive(Debug, Args)]
pub struct WorkspaceArgs {
    /// Geometry: a ring platform or the tool carrier (tool5-ex).
    #[arg(long, short, default_value = "trainer-model")]
    pub mechanism: String,
    /// Your own ring platform: a rig file (TOML), instead of --mechanism.
    #[arg(long, value_name = "RIG.toml")]
    pub geometry: Option<std::path::PathBuf>,
    /// The plane.
    #[arg(long, value_enum, default_value = "xy")]
    pub section: crate::analysis::workspace::Section,
    /// Height of the xy section (m). Default: the preset's home height.
    #[arg(long)]
    pub z: Option<f64>,
    /// Grid cells along each side of the section.
    #[arg(long, default_value_t = 240)]
    pub cells: usize,
    /// Output picture: .svg (with labels) or .png.
    #[arg(long)]
    pub out: std::path::PathBuf,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct CueArgs {
    /// Telemetry CSV with the header t,ax,ay,az,wx,wy,wz (s; specific force in m/s^2 in the vehicle frame, x
    /// forward, y left, z up, +9.81 on z at rest; angular rates in rad/s), or a packet capture (pcap, pcapng) of a
    /// game's telemetry datagrams (see --telemetry-format).
    #[arg(long)]
    pub input: std::path::PathBuf,
    /// Output pose CSV (t,x,y,z,alpha,beta,gamma in s, m, rad).
    #[arg(long)]
    pub out: std::path::PathBuf,
    /// Washout parameters (TOML; every key optional, see the README).
    #[arg(long)]
    pub config: Option<std::path::PathBuf>,
    /// A profile of the --config file (its `[profiles.NAME]` table overrides the base keys).
    #[arg(long, requires = "config")]
    pub profile: Option<String>,
    /// A plot of the cues (SVG): per axis the specific force asked and delivered, and the angular rates.
    #[arg(long)]
    pub plot: Option<std::path::PathBuf>,
    /// The platform cued for (a ring platform): its home is the neutral pose, its envelope limits the cues.
    #[arg(long, short, default_value = "trainer-model")]
    pub mechanism: String,
    /// Your own ring platform: a rig file (TOML), instead of --mechanism.
    #[arg(long, value_name = "RIG.toml")]
    pub geometry: Option<std::path::PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// With a packet capture as --input (pcap or pcapng, from `stream --capture`, tcpdump or Wireshark): the
    /// datagrams' format, as for `stream --telemetry-format`; `auto` without.
    #[arg(long, value_enum)]
    pub telemetry_format: Option<crate::stream::datagram::TelemetryFormat>,
    /// With a packet capture as --input: its UDP datagrams to this port only (a capture of several flows).
    #[arg(long)]
    pub udp_port: Option<u16>,
}

#[derive(Debug, clap::Args)]
pub struct UiArgs {
    /// The controller.
    #[command(flatten)]
    pub controller: ControllerArgs,
    /// Where to serve the page. Another address than loopback lets other machines move the platform: the
    /// token in the printed URL is all that keeps them out.
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub listen: std::net::SocketAddr,
}

/// Which controller a command drives: a board on a serial port, or the simulated controller in this process (of the
/// trainer model, or of a rig file's or a preset's platform).
#[derive(Debug, Args)]
pub struct ControllerArgs {
    /// Serial port of the board (USB CDC).
    #[arg(long, conflicts_with = "sim")]
    pub port: Option<String>,
    /// The in-process simulated controller (same core as the firmware, real framed bytes).
    #[arg(long)]
    pub sim: bool,
    /// With --sim: simulate this rig file's platform (with the trainer model's drives and switches) instead of the
    /// trainer model.
    #[arg(long, value_name = "RIG.toml", requires = "sim")]
    pub geometry: Option<std::path::PathBuf>,
    /// With --sim: simulate this preset's ring platform (`ringpod presets`) with the trainer model's drives and
    /// switches, as --geometry does with its exported rig file.
    #[arg(long, value_name = "PRESET", requires = "sim", conflicts_with = "geometry")]
    pub mechanism: Option<String>,
}
