//! Command-line interface definition.

mod analysis;
mod device;
pub mod requests;
mod stream;

pub use analysis::{
    CheckArgs, Common, CueArgs, DrawArgs, DynamicsArgs, FkArgs, LoadsArgs, PoseArgs, RatesArgs, ReactionsArgs,
    RigAction, StructureArgs, WorkspaceArgs,
};
pub use device::{ControllerArgs, DeviceAction, DeviceArgs, UiArgs};
pub use requests::platform;
pub use stream::StreamArgs;

use clap::{Parser, Subcommand};

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
    /// Streams poses to the controller (a board on --port, or the simulated controller with --sim) from one source,
    /// which must be given (there is no default): --input FILE.csv, --motion NAME, --udp ADDR or --telemetry-udp
    /// ADDR. Checks the input's first pose, connects, powers up and homes if needed, streams (poses outside the
    /// envelope limited into it; a file's rows interpolated every 10 ms across longer gaps, a live source's last
    /// pose held while it pauses), then stops and waits for rest. Exit codes: 0 every pose followed (limited ones included), 1 the stream could not start, 3 input
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
    /// Lists the serial ports with their USB VID:PID (a board shows up as a USB CDC port, 1209:0001: /dev/ttyACM* on
    /// Linux, COMn on Windows).
    Ports,
    /// Writes the firmware into the board over its USB cable with the STM32F411's ROM bootloader (USB DFU: no probe
    /// needed): the running firmware is asked to restart into it (only at rest, supplies off), or a board held in
    /// it (BOOT0) is found; the sectors the image covers are erased (the settings are kept), the image written, read
    /// back and compared, and the new firmware must come back naming it. The image: --image FILE (.elf or .bin), or
    /// the firmware built from this source tree (cargo, `--profile firmware`). Exit codes: 0 flashed, verified and
    /// answering; 3 the image was refused (nothing was done); 4 no board, or it did not enter its bootloader; 5
    /// the transfer failed half way, 6 the image read back differs (for both: flash again); 7 the new firmware did
    /// not come back as flashed.
    Flash {
        /// The firmware image (ELF or raw .bin from the start of flash) instead of building it.
        #[arg(long, value_name = "FILE")]
        image: Option<std::path::PathBuf>,
        /// The board's serial port, when more than one board is plugged in (found by its USB id otherwise).
        #[arg(long)]
        port: Option<String>,
        /// The ROM bootloader served over TCP (`tcp://HOST:PORT`) instead of the machine's USB: the emulated board's
        /// harness serves it so (`tests/rehost`).
        #[arg(long, value_name = "tcp://HOST:PORT")]
        dfu: Option<String>,
    },
    /// Static drive loads for a payload at a pose (ring platforms): carriage torques and actuator forces.
    Loads(LoadsArgs),
    /// Paper 002's matrix method on a ring platform (trainer-ch5, rotopod-ch4, or a rig file of rod and radial
    /// chains): pairs, link matrices and loops closed by Gauss-Newton, moved along a built-in motion about home; the
    /// Lagrange equation gives the drive torques and forces, the energies and the drives' power, each force checked
    /// against the ring platform's own inverse dynamics. Exits 0, or 3 when they differ by more than 1e-6.
    Dynamics(DynamicsArgs),
    /// Loads of a tool wrench on the five-DOF tool carrier (paper 003's projection method): drive forces and
    /// torques, the X guide's bearing load, the frame pivots' forces and the constraint couple.
    Reactions(ReactionsArgs),
    /// Paper 003's figs. 3-5: the Gram determinants of its three-DOF translational mechanism's wrenches (constraint,
    /// actuation, all) over a slice of its workspace, drawn as four maps (with the sign of det M_C) and written as
    /// a markdown table; with --reactions, figs. 3 and 5's largest constraint reaction, unprojected and projected.
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
        /// Also draw figs. 3 and 5, the largest constraint reaction without and with projection (.png or .svg),
        /// for a load of 1 N down and 0.1 N m about each axis (the paper does not say which it used).
        #[arg(long, value_name = "FILE")]
        reactions: Option<std::path::PathBuf>,
    },
    /// Scans the workspace of a ring platform or the tool carrier with all its checks (in parallel), draws a section
    /// (positions, or the two tilts) coloured by the limiting check, and prints the cells inside, the reachable
    /// ranges, the volume, each axis's range at home, and whether the spec ranges are inside.
    Workspace(WorkspaceArgs),
    /// Motion cueing: vehicle telemetry (specific force, angular rates) to platform poses by the classical washout
    /// (translation high-passed, sustained force by tilt coordination, yaw by heading), every pose limited into the
    /// envelope; writes the pose CSV that `stream --input` reads. Exits 0, or 3 when rows could not be used.
    Cue(CueArgs),
    /// Serves the simulated controller on a pseudo-terminal (Unix) or over TCP and prints its path or address, so
    /// that `--port` (and any other program) can talk to it as to a board. Runs until interrupted.
    Simulate {
        /// Serve on a pseudo-terminal (Unix only).
        #[arg(long, required_unless_present = "tcp", conflicts_with = "tcp")]
        pty: bool,
        /// Serve over TCP on this address (`127.0.0.1:5760`; port 0 picks a free one); reach it with
        /// `--port tcp://ADDRESS`.
        #[arg(long, value_name = "ADDRESS")]
        tcp: Option<std::net::SocketAddr>,
        /// Simulate this rig file's platform (with the trainer model's drives and switches) instead of the trainer
        /// model.
        #[arg(long, value_name = "RIG.toml")]
        geometry: Option<std::path::PathBuf>,
        /// Simulate this preset's ring platform (`ringpod presets`), as --geometry does with its exported rig file.
        #[arg(long, value_name = "PRESET", conflicts_with = "geometry")]
        mechanism: Option<String>,
    },
}

impl Command {
    /// Whether the command watches the stopping signals itself (it stops the platform or its server first, then
    /// reports): the others, which compute or ask the device and wait for its answer (`device home` waits for the
    /// homing's end), are ended by `signals::end_on_signal`, as the default action would end them.
    pub fn watches_signals(&self) -> bool {
        match self {
            Self::Device(args) => args.action == DeviceAction::Inputs && args.watch,
            _ => matches!(
                self,
                Self::Stream(_) | Self::Ui(_) | Self::Simulate { .. } | Self::Monitor { .. }
            ),
        }
    }
}
