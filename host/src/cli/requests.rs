//! What each command's arguments ask for, as the typed options and requests the commands take: the commands
//! never see a clap struct.

use super::{
    CheckArgs, Common, CueArgs, DeviceAction, DeviceArgs, DrawArgs, FkArgs, LoadsArgs, RatesArgs, StreamArgs,
    StructureArgs, WorkspaceArgs,
};

impl RatesArgs {
    /// The command's typed options.
    pub fn options(&self) -> crate::analysis::rates::Options<'_> {
        use crate::analysis::rates::Given;
        crate::analysis::rates::Options {
            on: self.common.on(),
            pose: self.pose.as_deref(),
            given: match (&self.pose_rates, &self.actuator_rates) {
                (_, Some(q)) => Given::ActuatorRates(q),
                (Some(p), None) => Given::PoseRates(p),
                // clap requires one of them.
                (None, None) => Given::PoseRates(""),
            },
        }
    }
}

impl CheckArgs {
    /// The options `check --tip-over` takes.
    pub fn tip_over(&self) -> crate::analysis::tipover::Options<'_> {
        crate::analysis::tipover::Options {
            on: self.common.on(),
            pose: self.pose.as_deref(),
            payload_com: self.payload_com.as_deref(),
            accel: self.accel.as_deref(),
        }
    }
}

impl DrawArgs {
    /// The options `draw` takes.
    pub fn options(&self) -> crate::analysis::draw::Options<'_> {
        crate::analysis::draw::Options {
            on: self.common.on(),
            pose: self.pose.as_deref(),
            out: &self.out,
        }
    }
}

impl StructureArgs {
    /// The options `structure` takes.
    pub fn options(&self) -> crate::analysis::structure::Options<'_> {
        crate::analysis::structure::Options {
            on: self.common.on(),
            pose: self.pose.as_deref(),
            chain: self.chain,
        }
    }
}

impl Common {
    /// The options the analysis commands take.
    pub fn on(&self) -> crate::analysis::kinematics::On<'_> {
        crate::analysis::kinematics::On {
            mechanism: &self.mechanism,
            geometry: self.geometry.as_deref(),
            degrees: self.degrees,
            json: self.json,
        }
    }
}

impl FkArgs {
    /// The options `fk` takes.
    pub fn options(&self) -> crate::analysis::kinematics::FkOptions<'_> {
        crate::analysis::kinematics::FkOptions {
            on: self.common.on(),
            actuators: &self.actuators,
            guess: self.guess.as_deref(),
            max_iterations: self.max_iterations,
            anywhere: self.anywhere,
            assembly: self.branch,
        }
    }
}

impl LoadsArgs {
    /// The options `loads` takes.
    pub fn options(&self) -> crate::analysis::kinematics::LoadsOptions<'_> {
        crate::analysis::kinematics::LoadsOptions {
            on: self.common.on(),
            pose: self.pose.as_deref(),
            mass: self.mass,
            input: self.input.as_deref(),
            inertia: self.inertia.as_deref(),
            plot: self.plot.as_deref(),
        }
    }
}

impl super::DynamicsArgs {
    /// What `dynamics` is asked.
    pub fn request(&self) -> crate::analysis::dynamics::Request<'_> {
        crate::analysis::dynamics::Request {
            mechanism: &self.mechanism,
            geometry: self.geometry.as_deref(),
            mass: self.mass,
            inertia: &self.inertia,
            amplitude: self.amplitude,
            duration: self.duration,
            step: self.step,
            table: self.table.as_deref(),
            plot: self.plot.as_deref(),
            file: self.file.as_deref(),
            input: self.input.as_deref(),
            file_options: crate::analysis::dynamics::FileOptions {
                forward: self.forward.then(|| self.force.as_deref().unwrap_or("")),
                points: &self.point,
                paths: self.paths.as_deref(),
                paths_plot: self.paths_plot.as_deref(),
            },
        }
    }
}

impl WorkspaceArgs {
    /// The options `workspace` takes.
    pub fn options(&self) -> crate::analysis::workspace::Options<'_> {
        crate::analysis::workspace::Options {
            mechanism: &self.mechanism,
            geometry: self.geometry.as_deref(),
            section: self.section,
            z: self.z,
            cells: self.cells,
            out: &self.out,
            quiet: self.quiet,
        }
    }
}

impl CueArgs {
    /// The bench's options, with --compare.
    pub fn bench(&self) -> Option<crate::cueing::bench::Options<'_>> {
        let c = self.compare.as_deref()?;
        let [a, b] = c else { return None };
        Some(crate::cueing::bench::Options {
            configs: [a, b],
            inputs: &self.input,
            out: &self.out,
            plot: self.plot.as_deref(),
            tune: self.tune,
            json: self.json,
            preview: self.preview.unwrap_or_default(),
            floor: self.floor,
            envelope_floor: self.envelope_floor,
            mechanism: &self.mechanism,
            geometry: self.geometry.as_deref(),
        })
    }

    /// The options `cue` takes (one input: several are for --compare).
    pub fn options(&self) -> Result<crate::cueing::offline::Options<'_>, RequestError> {
        let [input] = self.input.as_slice() else {
            return Err(RequestError::CueOneInput);
        };
        Ok(crate::cueing::offline::Options {
            input,
            out: &self.out,
            config: self.config.as_deref(),
            profile: self.profile.as_deref(),
            plot: self.plot.as_deref(),
            json: self.json,
            preview: self.preview.unwrap_or_default(),
            telemetry_format: self.telemetry_format,
            udp_port: self.udp_port,
            outsim_opts: self.outsim_opts,
            mechanism: &self.mechanism,
            geometry: self.geometry.as_deref(),
        })
    }
}

/// Arguments that do not go together (the combinations clap cannot express).
#[derive(Debug, thiserror::Error)]
pub enum RequestError {
    /// `cue` with several inputs but no --compare.
    #[error("cue takes one --input (several are for --compare)")]
    CueOneInput,
    /// `--capture` without a live source.
    #[error("--capture records a live source: it needs --udp, --telemetry-udp or --telemetry-shm")]
    CaptureWithoutUdp,
    /// `--outsim-opts` with a telemetry format that never reads `OutSimPack2`.
    #[error(
        "--outsim-opts describes Live for Speed's OutSimPack2 packets: it needs --telemetry-format outsim2 or auto"
    )]
    OutsimOptsFormat,
    /// `stream` without a source (clap requires one; this is the same rule for a request built otherwise).
    #[error(
        "stream needs a source: --input FILE.csv, --motion NAME, --udp ADDR, --telemetry-udp ADDR or --telemetry-shm GAME"
    )]
    NoSource,
    /// `--motion sine` without all of its parameters.
    #[error("--motion sine needs --axis, --frequency and --velocity-amplitude or --amplitude")]
    IncompleteSine,
    /// A sine's parameters without `--motion sine`.
    #[error("--axis, --frequency and the amplitudes are for --motion sine")]
    SineParametersAlone,
    /// Words after a device action that takes none.
    #[error("only `device config`, `jog`, `buzz`, `rig` and `aux` take further words")]
    ExtraWords,
    /// `--watch` with another action than `inputs`.
    #[error("--watch is for `device inputs`")]
    WatchAlone,
    /// `device rig` with other words.
    #[error("`device rig load RIG.toml` or `device rig show`")]
    RigUsage,
    /// `device aux` with other words.
    #[error("usage: `device aux N on|off` with N 1 or 2")]
    AuxUsage,
    /// Neither `--port` nor `--sim`.
    #[error(transparent)]
    Target(#[from] crate::link::LinkError),
}

impl StreamArgs {
    /// The stream these arguments ask for (clap has already refused the combinations that make no sense).
    pub fn job(&self) -> Result<crate::stream::command::Job, RequestError> {
        use crate::stream::command::{Device, Job, LoadsCheck};
        let input = self.input()?;
        let c = &self.controller;
        let device = match crate::link::Target::named(c.port.as_deref(), c.sim)? {
            crate::link::Target::Port(port) => Device::Port(port),
            crate::link::Target::Sim => Device::Sim {
                fast: self.fast,
                platform: platform(&c.geometry, &c.mechanism),
            },
        };
        Ok(Job {
            input,
            device,
            check_loads: self.check_loads.then(|| LoadsCheck {
                mass: self.mass.unwrap_or(f64::NAN),
                inertia: self.inertia.clone(),
            }),
            options: crate::stream::Options {
                home: self.home,
                host_limits: !self.device_limits_only,
                telemetry: self.motion_compensation.is_some(),
                telemetry_hz: self.record_hz,
                resend_stop: true,
                quiet: self.quiet,
            },
            record: self.record.clone(),
            capture: self.capture.clone(),
            report_json: self.report_json,
            motion_compensation: self.motion_compensation,
        })
    }
}

impl StreamArgs {
    /// Where the stream's poses come from.
    fn input(&self) -> Result<crate::stream::command::Input, RequestError> {
        use crate::stream::command::{Datagrams, Input};
        let udp = |addr, holds| Input::Udp {
            addr,
            holds,
            from: self.udp_from,
            idle: self.udp_idle,
        };
        let live = self.udp.is_some() || self.telemetry_udp.is_some() || self.telemetry_shm.is_some();
        if self.capture.is_some() && !live {
            return Err(RequestError::CaptureWithoutUdp);
        }
        if self.outsim_opts.is_some() && !self.telemetry_format.reads_outsim2() {
            return Err(RequestError::OutsimOptsFormat);
        }
        Ok(match (self.udp, self.telemetry_udp, self.telemetry_shm, &self.input) {
            (Some(addr), ..) => udp(
                addr,
                match &self.pose_format {
                    Some(template) => Datagrams::Strings(Box::new(template.clone().with_ranges(self.pose_range))),
                    None => Datagrams::Poses { degrees: self.degrees },
                },
            ),
            (None, Some(addr), ..) => udp(
                addr,
                Datagrams::Telemetry {
                    format: self.telemetry_format,
                    cue_config: self.cue_config.clone(),
                    profile: self.profile.clone(),
                    outsim_opts: self.outsim_opts,
                    lap_preview: self.lap_preview,
                },
            ),
            (None, None, Some(game), _) => Input::Shm {
                game,
                cue_config: self.cue_config.clone(),
                profile: self.profile.clone(),
                idle: self.udp_idle,
                lap_preview: self.lap_preview,
            },
            (None, None, None, Some(path)) => Input::File {
                path: path.clone(),
                degrees: self.degrees,
            },
            (None, None, None, None) => Input::Motion {
                motion: self.motion.ok_or(RequestError::NoSource)?,
                sine: self.sine()?,
                seconds: self.duration,
                rate_hz: self.rate,
            },
        })
    }

    /// `--motion sine`'s parameters: all of them for a sine, none for anything else.
    fn sine(&self) -> Result<Option<crate::stream::Sine>, RequestError> {
        use crate::stream::{Amplitude, Motion, Sine};
        let amplitude = match (self.velocity_amplitude, self.amplitude) {
            (Some(v), _) => Some(Amplitude::Velocity(v)),
            (None, Some(a)) => Some(Amplitude::Position(a)),
            (None, None) => None,
        };
        match (self.motion, self.axis, self.frequency, amplitude) {
            (Some(Motion::Sine), Some(axis), Some(frequency), Some(amplitude)) => Ok(Some(Sine {
                axis,
                frequency,
                amplitude,
                seconds: self.duration,
            })),
            (Some(Motion::Sine), ..) => Err(RequestError::IncompleteSine),
            (_, None, None, None) => Ok(None),
            _ => Err(RequestError::SineParametersAlone),
        }
    }
}

impl DeviceArgs {
    /// The device and what to do there; words that an action does not take are refused here.
    pub fn request(&self) -> Result<(crate::link::Target, crate::device::Action), RequestError> {
        use crate::device::Action;
        use DeviceAction as A;
        if !matches!(self.action, A::Config | A::Jog | A::Buzz | A::Rig | A::Aux) && !self.config.is_empty() {
            return Err(RequestError::ExtraWords);
        }
        if self.watch && self.action != A::Inputs {
            return Err(RequestError::WatchAlone);
        }
        let words = self.config.clone();
        let action = match self.action {
            A::Status => Action::Status,
            A::Enable => Action::Enable,
            A::Disable => Action::Disable,
            A::Home => Action::Home,
            A::Start => Action::Start,
            A::Stop => Action::Stop,
            A::Clear => Action::Clear,
            A::Config => Action::Config(words),
            A::Inputs => Action::Inputs { watch: self.watch },
            A::Jog => Action::Jog(words),
            A::Buzz => Action::Buzz(words),
            A::Rig => match words.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
                ["load", file] => Action::LoadRig(std::path::PathBuf::from(file)),
                ["show"] => Action::ShowRig,
                _ => return Err(RequestError::RigUsage),
            },
            A::Restart => Action::Restart,
            A::Bootloader => Action::Bootloader,
            A::Aux => {
                let parsed = match words.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
                    [n, level] => n
                        .parse::<u8>()
                        .ok()
                        .and_then(ringpod_core::safety::Aux::from_number)
                        .zip(match *level {
                            "on" => Some(true),
                            "off" => Some(false),
                            _ => None,
                        }),
                    _ => None,
                };
                let Some((output, on)) = parsed else {
                    return Err(RequestError::AuxUsage);
                };
                Action::Aux { output, on }
            }
        };
        Ok((crate::link::Target::named(self.port.as_deref(), self.sim)?, action))
    }
}

/// The platform a simulated controller runs: `--geometry RIG.toml` or `--mechanism PRESET` (clap keeps them apart),
/// or the trainer model.
pub fn platform(geometry: &Option<std::path::PathBuf>, mechanism: &Option<String>) -> Option<crate::device::Platform> {
    match (geometry, mechanism) {
        (Some(path), _) => Some(crate::device::Platform::File(path.clone())),
        (None, Some(name)) => Some(crate::device::Platform::Preset(name.clone())),
        (None, None) => None,
    }
}

impl super::UiArgs {
    /// The workbench's options.
    pub fn options(&self) -> Result<crate::ui::Options, RequestError> {
        Ok(crate::ui::Options {
            target: crate::link::Target::named(self.controller.port.as_deref(), self.controller.sim)?,
            platform: platform(&self.controller.geometry, &self.controller.mechanism),
            listen: self.listen,
            files: self.files.clone(),
            motion_compensation: self.motion_compensation,
            cue_config: self.cue_config.clone(),
        })
    }
}

impl super::StabilityArgs {
    /// The options `stability` takes; `stopped` ends an experiment early.
    pub fn options<'a>(&'a self, stopped: &'a dyn Fn() -> bool) -> crate::experiment::stability::Options<'a> {
        crate::experiment::stability::Options {
            track: self.track,
            wheelbase: self.wheelbase,
            cg_height: self.cg_height,
            cg_from_rear: self.cg_from_rear,
            roll: self
                .roll_stiffness
                .zip(self.mass)
                .zip(self.roll_centre_height)
                .map(|((k, m), h)| (k, m, h)),
            radius: self.turn_radius,
            experiment: self.experiment.as_deref(),
            rate_deg_s: self.rate,
            json: self.json,
            stopped,
        }
    }
}
