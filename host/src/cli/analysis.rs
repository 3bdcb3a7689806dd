//! Arguments of the commands that compute on a platform: `rig`, `ik`, `fk`, `check`, `loads`, `reactions`,
//! `rates`, `structure`, `draw`, `workspace`, `cue`, `dynamics`, `stability`.

use clap::{Args, Subcommand};

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
    #[arg(long, allow_hyphen_values = true, requires = "input", conflicts_with = "pose")]
    pub inertia: Option<String>,
    /// With --input: draw each axis's demand against what its drive gives at that speed (.svg or .png).
    #[arg(long, requires = "input", conflicts_with = "pose", value_name = "FILE")]
    pub plot: Option<std::path::PathBuf>,
}

#[derive(Debug, Args)]
pub struct DynamicsArgs {
    /// Geometry: trainer-ch5, rotopod-ch4 or another preset of rod and radial chains (see `ringpod presets`).
    #[arg(long, short, default_value = "rotopod-ch4")]
    pub mechanism: String,
    /// Your own ring platform: a rig file (TOML; see `ringpod rig check`), instead of --mechanism.
    #[arg(long, value_name = "RIG.toml")]
    pub geometry: Option<std::path::PathBuf>,
    /// Payload mass (kg), at the geometry's centre of mass.
    #[arg(long, default_value_t = 3.5)]
    pub mass: f64,
    /// Payload principal inertia about its centre of mass, platform frame: Ixx,Iyy,Izz (kg m^2).
    #[arg(long, default_value = "0.3,0.42,0.55", allow_hyphen_values = true)]
    pub inertia: String,
    /// The built-in motion's amplitude (length units on x, y, z; radians on the angles), each coordinate at its own
    /// frequency about the home pose.
    #[arg(long, default_value_t = 0.05)]
    pub amplitude: f64,
    /// Duration (s).
    #[arg(long, default_value_t = 2.0)]
    pub duration: f64,
    /// Sample step (s).
    #[arg(long, default_value_t = 0.01)]
    pub step: f64,
    /// Write the table (positions, rates, accelerations, forces, energies, power) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub table: Option<std::path::PathBuf>,
    /// Draw the drive forces and the energy balance (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<std::path::PathBuf>,
    /// A mechanism file in paper 002's terms (pairs, loops, bodies, springs, the drives' motion; see the book's
    /// "Paper 002" chapter), instead of a ring platform.
    #[arg(long, value_name = "MECHANISM.toml", conflicts_with_all = ["geometry", "mass", "inertia", "amplitude", "duration", "step"])]
    pub file: Option<std::path::PathBuf>,
    /// A motion file: timed poses `t,x,y,z,alpha,beta,gamma` (s, m, rad), as `loads --input` and `stream --input`
    /// read them, instead of the built-in motion (rates and accelerations by differences of the samples).
    #[arg(long, value_name = "MOTION.csv", conflicts_with_all = ["file", "amplitude", "duration", "step"])]
    pub input: Option<std::path::PathBuf>,
    /// With --file: forward dynamics instead of the drives' swing: the mechanism let go at rest from its sketch under
    /// constant drive forces (--force), the equation of motion integrated with the loop equations over the file's
    /// duration and step.
    #[arg(long, requires = "file")]
    pub forward: bool,
    /// With --forward: the drives' constant forces or torques `F1,F2,...` (N, N m; default zeros).
    #[arg(long, requires = "forward", allow_hyphen_values = true, value_name = "F1,F2,...")]
    pub force: Option<String>,
    /// With --file: follow a point of a link along the motion (paper 002's eqs. 5 and 6): `LINK:X,Y,Z`, the link
    /// by its pair's name and the point in the base at the sketch (m). Repeat for more points.
    #[arg(long, requires = "file", allow_hyphen_values = true, value_name = "LINK:X,Y,Z")]
    pub point: Vec<String>,
    /// With --point: write the points' positions, velocities and accelerations (CSV) ...
    #[arg(long, requires = "point", value_name = "FILE.csv")]
    pub paths: Option<std::path::PathBuf>,
    /// ... and draw them (.png or .svg).
    #[arg(long, requires = "point", value_name = "FILE")]
    pub paths_plot: Option<std::path::PathBuf>,
}

#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// Track (m): between the wheels' contact centres across.
    #[arg(long, allow_hyphen_values = true)]
    pub track: f64,
    /// Wheelbase (m).
    #[arg(long, allow_hyphen_values = true)]
    pub wheelbase: f64,
    /// Height of the centre of gravity above the ground (m).
    #[arg(long, allow_hyphen_values = true)]
    pub cg_height: f64,
    /// Distance of the centre of gravity ahead of the rear axle (m). Default: half the wheelbase.
    #[arg(long, allow_hyphen_values = true)]
    pub cg_from_rear: Option<f64>,
    /// The suspension's roll stiffness, both axles (N m/rad): the body rolls about its roll axis. Default: rigid.
    #[arg(long, allow_hyphen_values = true, requires_all = ["mass", "roll_centre_height"])]
    pub roll_stiffness: Option<f64>,
    /// With --roll-stiffness: the sprung mass (kg).
    #[arg(long, allow_hyphen_values = true, requires = "roll_stiffness")]
    pub mass: Option<f64>,
    /// With --roll-stiffness: the roll axis's height above the ground (m).
    #[arg(long, allow_hyphen_values = true, requires = "roll_stiffness")]
    pub roll_centre_height: Option<f64>,
    /// The turn's radius for the critical speed (m).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub turn_radius: f64,
    /// Run each test on the simulated trainer model (incline, slope, turn), writing each motion and run record into
    /// this directory; exit 3 when a record does not show the tip-over where computed.
    #[arg(long, value_name = "DIR")]
    pub experiment: Option<std::path::PathBuf>,
    /// With --experiment: the platform's tilt rate (deg/s).
    #[arg(long, default_value_t = 2.0, requires = "experiment", allow_hyphen_values = true)]
    pub rate: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
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

#[derive(Debug, Args)]
pub struct Common {
    /// Geometry: trainer-model, trainer-elbow, trainer-ch5, rotopod-ch4, tool5-ex, trainer-ch3, trainer-ch4 (see
    /// `ringpod presets`).
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
    /// game's telemetry datagrams (see --telemetry-format). With --compare, one or more drives.
    #[arg(long, num_args = 1.., required = true)]
    pub input: Vec<std::path::PathBuf>,
    /// Output pose CSV (t,x,y,z,alpha,beta,gamma in s, m, rad); with --compare, the report (JSON).
    #[arg(long)]
    pub out: std::path::PathBuf,
    /// The bench: cue the drives by both cueing files and compare what the rider perceives (perceived specific
    /// force and rotation errors, false cues, envelope used, limiter interventions, solve times); --plot draws
    /// the perceived forces of both.
    #[arg(long, num_args = 2, value_names = ["A.toml", "B.toml"],
          conflicts_with_all = ["config", "profile", "telemetry_format", "udp_port", "outsim_opts"])]
    pub compare: Option<Vec<std::path::PathBuf>>,
    /// With --compare: first tune the first file's classical washout for the best score on the same drives and
    /// envelope (a small coordinate search, see the book's Motion cueing chapter).
    #[arg(long, requires = "compare")]
    pub tune: bool,
    /// With --compare: add the floor, the least perceived force error any motion inside the envelope's ranges
    /// can give, found with the whole drive known (one programme per axis over the drive); with an optimal
    /// cueing as B, also the floor within B's own room and limits (its shares, velocity, acceleration and rate
    /// limits, its rotation error priced), its motion scored like a cueing's.
    #[arg(long, requires = "compare")]
    pub floor: bool,
    /// With --floor: also the floor inside an outer polytope of the rig's whole envelope, every axis planned
    /// together as the rig couples them (one programme over the drive with every face at every sample: tens
    /// of seconds on a few minutes of drive); with an optimal cueing as B, also within B's limits there, its
    /// motion scored.
    #[arg(long, requires = "floor")]
    pub envelope_floor: bool,
    /// With `algorithm = "optimal"`: the reference over the horizon is the drive's own next samples (`--preview`
    /// or `--preview drive`: a recorded drive's future, a yardstick) or the laps driven before, aligned by the
    /// drive's `lap_distance` column (`--preview lap`: what a live game allows), rather than the last sample held.
    /// With --compare and `lap`, the second file is cued both live and with the lap preview, and drives with a lap
    /// distance are scored from their second lap.
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "drive", value_name = "drive|lap")]
    pub preview: Option<crate::cueing::offline::Preview>,
    /// Washout parameters (TOML; every key optional, see the book's Motion cueing chapter).
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
    pub telemetry_format: Option<crate::games::TelemetryFormat>,
    /// With a packet capture as --input: its UDP datagrams to this port only (a capture of several flows).
    #[arg(long)]
    pub udp_port: Option<u16>,
    /// With a packet capture as --input: Live for Speed's `OutSim Opts` (hexadecimal, as in its cfg.txt), which
    /// an `outsim2` packet's size alone does not always tell.
    #[arg(long, value_name = "HEX", value_parser = crate::games::outsim2::Opts::parse_hex)]
    pub outsim_opts: Option<crate::games::outsim2::Opts>,
}
