//! Arguments of the commands that talk to a controller: `device`, `ui` and where the controller is.

use clap::Args;

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
    /// Restart into the MCU's ROM bootloader (USB DFU, 0483:df11; supplies off) once everything is stored, to be
    /// flashed (`ringpod flash` does this itself). Asked without a handshake: a board of any protocol version takes it.
    Bootloader,
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
    /// Sections: stream (timeout_ms, gross_jump_ms, follow, margins.N, telemetry_hz, host_gone_ms), control
    /// (tick_hz), motion (pose_velocity.N, pose_acceleration.N, actuator_velocity.N, actuator_acceleration.N),
    /// inputs (active_low, debounce_ms), axes.N (steps_per_unit, reverse), homing, supervisor; N counts from 0,
    /// e.g. `set axes.4.reverse true`, `set stream.timeout_ms 200`. For `jog`: AXIS DISTANCE; for `buzz`: AXIS;
    /// for `rig`: `load RIG.toml` or `show`; for `aux`: N on|off.
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

/// `--files DIR`: a folder there is, said at the start (a misspelt one would show only when a page asks for a
/// file). clap names the option and the value; this says what is wrong with it.
fn existing_dir(text: &str) -> Result<std::path::PathBuf, String> {
    match std::fs::metadata(text) {
        Ok(m) if m.is_dir() => Ok(text.into()),
        Ok(_) => Err("not a folder".into()),
        Err(e) => Err(e.to_string()),
    }
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
    /// Let the page stream pose files under DIR by name. Without it the page streams only the files picked in it.
    #[arg(long, value_name = "DIR", value_parser = existing_dir)]
    pub files: Option<std::path::PathBuf>,
    /// VR motion compensation (Windows): write the pose the seat followed, whenever the device reports it (every
    /// run from the page, and at rest), where OpenXR-MotionCompensation's virtual tracker of this type reads it, as
    /// `stream --motion-compensation` does.
    #[arg(long, value_enum, value_name = "TRACKER")]
    pub motion_compensation: Option<crate::vr::Tracker>,
    /// The cueing file whose profiles (`[profiles.NAME]`, one per game) the page chooses, loads, saves and
    /// duplicates, as `stream --cue-config FILE --profile NAME` reads them; made by the first save. Without it
    /// the page's profiles last until the workbench ends.
    #[arg(long, value_name = "FILE")]
    pub cue_config: Option<std::path::PathBuf>,
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
    #[arg(long, value_name = "RIG.toml", requires = "sim", conflicts_with = "port")]
    pub geometry: Option<std::path::PathBuf>,
    /// With --sim: simulate this preset's ring platform (`ringpod presets`) with the trainer model's drives and
    /// switches, as --geometry does with its exported rig file.
    #[arg(long, value_name = "PRESET", requires = "sim", conflicts_with_all = ["geometry", "port"])]
    pub mechanism: Option<String>,
}
