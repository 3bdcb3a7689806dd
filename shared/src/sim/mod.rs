//! A simulated machine: six axes that count the controller's steps, switches that trip at their positions, and
//! supplies whose sense lines follow the relays. The host's simulator and the end-to-end tests drive the controller
//! with it when no board is attached.

pub mod drivers;
mod flash;

use crate::controller::{Controller, Inputs, TickOutput};
use drivers::{DriverInputs, TimingViolation};

/// Where the switches of one axis are (physical steps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSwitches {
    /// The home switch trips in `[home, home + width)` (a carriage's index flag) or, for a linear actuator's home
    /// end, at or below `home`.
    pub home: i64,
    /// Width of a carriage's index flag (steps); `None` for a linear actuator's end switch.
    pub flag_width: Option<i64>,
    /// A carriage's steps per turn of the ring: its flag passes once a turn, wherever the count is (a platform that
    /// turned twice finds it two turns on). `None` for a linear actuator.
    pub per_turn: Option<i64>,
    /// A linear actuator's far end-of-travel switch trips at or above this.
    pub far_limit: Option<i64>,
}

pub use crate::model::TRAINER_MODEL_PARKED;

/// Where the simulator parks a ring platform's axes (steps from each switch), as it parks the trainer model
/// ([`TRAINER_MODEL_PARKED`], which this gives for the model's axes): carriages 500 to 100 steps (7 to 1.4 degrees
/// at the model's 25,600 steps per turn) before their index flags, linear actuators 8,000 to 9,000 steps (5 to 5.6
/// mm) above their home ends, elbow chains' shoulders 900 to 400 steps (5 to 2.3 degrees at 64,000 steps per turn)
/// before their index flags. Each kind takes the next of its own kind's positions, so a rotopod's fifth and sixth
/// carriages park like carriages, not like the model's actuators.
pub fn parked(axes: &[crate::kinematics::AxisKind; 6]) -> [i64; 6] {
    use crate::kinematics::AxisKind;
    const CARRIAGES: [i64; 6] = [-500, -400, -300, -200, -150, -100];
    const LINEAR: [i64; 6] = [8_000, 9_000, 8_500, 8_000, 9_000, 8_500];
    const SHOULDERS: [i64; 6] = [-900, -400, -700, -600, -500, -800];
    let mut next = [0usize; 3];
    core::array::from_fn(|a| {
        let (k, positions) = match axes[a] {
            AxisKind::Ring => (0, &CARRIAGES),
            AxisKind::Linear => (1, &LINEAR),
            AxisKind::Angle => (2, &SHOULDERS),
        };
        next[k] += 1;
        positions[(next[k] - 1) % 6]
    })
}
pub use flash::RamFlash;

/// The simulated plant.
#[derive(Debug, Clone)]
pub struct Plant {
    /// Physical position of each axis (steps from its home switch).
    pub position: [i64; 6],
    /// Switch positions.
    pub switches: [AxisSwitches; 6],
    /// The e-stop chain is open.
    pub estop_open: bool,
    /// Supplies fail to come up (sense stays low).
    pub supply_dead: bool,
    /// Steps received while the drivers were disabled (must stay zero).
    pub steps_while_disabled: u64,
    /// Total steps received per axis.
    pub steps_received: [u64; 6],
    /// Bit per axis: its motor is wired or mounted the other way round, so a forward step moves the axis back
    /// (what the axes section's `reverse` corrects).
    pub reversed: u8,
    /// The auxiliary outputs as the controller last set them (bit 0 AUX1, bit 1 AUX2): what the equipment on them
    /// (a spindle, a pump, a valve) is doing.
    pub aux: u8,
    /// Position of the spare axes 7 and 8 (steps from where they stood at the start).
    pub spare: [i64; 2],
}

impl Plant {
    /// The trainer model parked near home: carriages a few degrees before their index flags, linear actuators
    /// some millimetres above their home ends.
    pub fn trainer_model(start: [i64; 6]) -> Self {
        let carriage = AxisSwitches {
            home: 0,
            flag_width: Some(60),
            per_turn: Some(crate::motion::steps::AxisScale::MODEL_CARRIAGE.steps_per_turn),
            far_limit: None,
        };
        let linear = AxisSwitches {
            home: 0,
            flag_width: None,
            per_turn: None,
            far_limit: Some(240_000),
        };
        Self {
            position: start,
            switches: [carriage, carriage, carriage, carriage, linear, linear],
            estop_open: false,
            supply_dead: false,
            steps_while_disabled: 0,
            steps_received: [0; 6],
            reversed: 0,
            aux: 0,
            spare: [0; 2],
        }
    }

    /// Another ring platform parked like the trainer model: carriages and elbow chains' shoulders with index flags,
    /// linear actuators with a home end switch and a far end `far_limit` steps above it.
    pub fn for_axes(axes: &[crate::kinematics::AxisKind; 6], start: [i64; 6], far_limit: i64) -> Self {
        let model = Self::trainer_model(start);
        let (carriage, linear) = (model.switches[0], model.switches[4]);
        Self {
            switches: core::array::from_fn(|a| {
                if axes[a] != crate::kinematics::AxisKind::Linear {
                    carriage
                } else {
                    AxisSwitches {
                        far_limit: Some(far_limit),
                        ..linear
                    }
                }
            }),
            ..model
        }
    }

    /// The machine a configuration describes, parked as [`parked`] parks its axes: carriages and elbow chains'
    /// shoulders with index flags, linear actuators with a home end switch and a far end switch 2 mm past their
    /// stroke.
    pub fn for_config(config: &crate::controller::ControllerConfig) -> Self {
        let axes = config.geometry.axes();
        let start = parked(&axes);
        let stroke = config.geometry.limits.stroke;
        let per_m = axes
            .iter()
            .zip(&config.scales)
            .find(|(k, _)| **k == crate::kinematics::AxisKind::Linear)
            .map_or(0.0, |(_, s)| f64::from(s.steps_per_unit));
        let far = ((stroke[1] - stroke[0] + 0.002) * per_m) as i64;
        let mut plant = Self::for_axes(&axes, start, far);
        for (s, scale) in plant.switches.iter_mut().zip(&config.scales) {
            if s.per_turn.is_some() {
                s.per_turn = Some(scale.steps_per_turn);
            }
        }
        plant
    }

    /// Switch and supply levels for the controller, given the relays of the last tick.
    pub fn inputs(&self, logic_relay: bool, power_relay: bool) -> Inputs {
        let mut home = 0u16;
        let mut limits = 0u16;
        for (a, (p, s)) in self.position.iter().zip(&self.switches).enumerate() {
            let active = match (s.flag_width, s.per_turn) {
                (Some(w), Some(turn)) if turn > 0 => (*p - s.home).rem_euclid(turn) < w,
                (Some(w), _) => *p >= s.home && *p < s.home + w,
                (None, _) => *p <= s.home,
            };
            if active {
                home |= 1 << a;
            }
            if s.far_limit.is_some_and(|f| *p >= f) {
                limits |= 1 << a;
            }
        }
        Inputs {
            estop_open: self.estop_open,
            home,
            limits,
            logic_ok: logic_relay && !self.supply_dead,
            power_ok: power_relay && !self.supply_dead,
        }
    }

    /// Applies one period's pulses.
    pub fn apply(&mut self, out: &TickOutput) {
        self.aux = out.outputs.aux;
        for (a, m) in out.moves.iter().enumerate() {
            if m.count > 0 && !out.outputs.driver_enable {
                self.steps_while_disabled += u64::from(m.count);
            }
            self.position[a] += self.direction(a) * m.signed();
            self.steps_received[a] += u64::from(m.count);
        }
    }

    /// Applies one period's pulses of the spare axes ([`Controller::spare_moves`](crate::controller::Controller::spare_moves)).
    pub fn apply_spare(&mut self, moves: Option<[crate::motion::AxisMove; 2]>, driver_enable: bool) {
        for (a, m) in moves.iter().flatten().enumerate() {
            if m.count > 0 && !driver_enable {
                self.steps_while_disabled += u64::from(m.count);
            }
            self.spare[a] += m.signed();
        }
    }

    /// +1, or -1 for a reversed motor.
    fn direction(&self, axis: usize) -> i64 {
        if self.reversed & (1 << axis) != 0 {
            -1
        } else {
            1
        }
    }

    /// Plays one buffer of the step generator's port words into the drivers and moves each axis by the STEP edges
    /// they counted (what a board's DMA would make the motors do). The first timing rule the words break, if any.
    pub fn play(&mut self, drivers: &mut DriverInputs, words: &[u32], driver_enable: bool) -> Option<TimingViolation> {
        let (position, edges) = (drivers.position(), drivers.edges());
        let broken = drivers.play_all(words);
        for a in 0..6 {
            let n = drivers.edges()[a] - edges[a];
            if n > 0 && !driver_enable {
                self.steps_while_disabled += n;
            }
            self.position[a] += self.direction(a) * (drivers.position()[a] - position[a]);
            self.steps_received[a] += n;
        }
        broken
    }
}

/// Controller and plant in one loop, one call per control period.
pub struct Rig {
    /// The controller core, as the firmware runs it.
    pub controller: Controller,
    /// The machine.
    pub plant: Plant,
    /// Control periods run.
    pub ticks: u64,
}

impl Rig {
    /// One control period: inputs from the plant, tick, pulses to the plant.
    pub fn tick(&mut self) -> TickOutput {
        let o = self.controller.supervisor().outputs();
        self.controller
            .set_inputs(self.plant.inputs(o.logic_relay, o.power_relay));
        let out = self.controller.tick();
        self.plant.apply(&out);
        self.plant
            .apply_spare(self.controller.spare_moves(), out.outputs.driver_enable);
        self.ticks += 1;
        out
    }

    /// A control period that the loop missed (a hold-up of the process that runs it): inputs from the plant and
    /// [`Controller::pass`], as the firmware does for the periods a hold-up cost; the motors stand still in it.
    pub fn pass(&mut self) {
        let o = self.controller.supervisor().outputs();
        self.controller
            .set_inputs(self.plant.inputs(o.logic_relay, o.power_relay));
        let outputs = self.controller.pass();
        self.plant.aux = outputs.aux;
        self.ticks += 1;
    }
}
