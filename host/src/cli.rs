//! Command-line interface definition.

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
    /// Lists the built-in geometries.
    Presets {
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Inverse kinematics: the six actuator values for a pose, with every workspace check and its margin.
    /// Exits 0 whenever the pose has a solution (failing checks are reported), 1 when it has none.
    Ik(PoseArgs),
    /// Workspace checks of a pose. Exits 0 when all pass, 3 when any fails, 1 when the pose has no solution.
    Check(PoseArgs),
    /// Forward kinematics: the pose for six actuator values, by Newton iteration from a guess.
    Fk(FkArgs),
}

#[derive(Debug, Args)]
pub struct Common {
    /// Geometry: trainer-model, trainer-ch5, rotopod-ch4, tool5-ex (see `ringpod presets`).
    #[arg(long, short, default_value = "trainer-model")]
    pub mechanism: String,
    /// Angles in degrees, on input and output (default radians).
    #[arg(long)]
    pub degrees: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct PoseArgs {
    #[command(flatten)]
    pub common: Common,
    /// Pose x,y,z,alpha,beta,gamma (metres; radians unless --degrees). Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: Option<String>,
}

#[derive(Debug, Args)]
pub struct FkArgs {
    #[command(flatten)]
    pub common: Common,
    /// Six actuator values in the mechanism's order (see `ringpod ik`): angles in radians unless --degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub actuators: String,
    /// Starting pose x,y,z,alpha,beta,gamma for the iteration. Default: the preset's home pose.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
    /// Maximum Newton iterations.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: u8,
}
