//! The commands (and a jog): which state each is taken in, and what it needs (the e-stop chain closed, no end
//! switch made, no latched fault but for `ClearFault`).

use super::{Shutdown, State, Supervisor, Supplies};
use crate::safety::events::{Command, Event, Refusal};

impl Supervisor {
    /// What a command that may move something (homing, a jog, clearing a fault) needs: the e-stop chain closed and
    /// no end switch made.
    fn may_move(&self) -> Result<(), Refusal> {
        if self.inputs.estop_open {
            return Err(Refusal::EStopOpen);
        }
        if self.inputs.limits != 0 {
            return Err(Refusal::LimitActive);
        }
        Ok(())
    }

    /// Takes a command (or a jog) where its state allows it; otherwise refuses it and changes nothing.
    pub(super) fn command(&mut self, command: Event) -> Result<(), Refusal> {
        // Switching an output off is always safe, and always taken (where it is off already, nothing changes).
        if let Event::Command(Command::Aux { output, on: false }) = command {
            self.aux &= !output.bit();
            return Ok(());
        }
        if self.is_fault() && command != Event::Command(Command::ClearFault) {
            return Err(Refusal::Faulted);
        }
        match (command, self.state) {
            (Event::Command(Command::Enable), State::Off) => {
                if self.inputs.estop_open {
                    return Err(Refusal::EStopOpen);
                }
                self.go(State::LogicOn);
            }
            (Event::Command(Command::Disable), State::LogicOn | State::PowerOn { .. } | State::Ready) => {
                // Without drive current the steppers hold nothing: the axes may be moved by hand or by gravity,
                // so the positions homing found are no longer known.
                self.homed = false;
                self.go(State::ShuttingDown(Shutdown::Drivers));
            }
            (Event::Command(Command::Home), State::PowerOn { settled: true } | State::Ready) => {
                self.may_move()?;
                self.homed = false;
                self.go(State::Homing);
            }
            (Event::Jog, State::PowerOn { settled: true } | State::Ready) => {
                self.may_move()?;
                // One axis moves away from the pose homing left: the platform must be homed again to stream.
                self.homed = false;
                self.go(State::Jogging);
            }
            (Event::Command(Command::Stop), State::Jogging) => self.go(State::PowerOn { settled: true }),
            (Event::Command(Command::Start), State::Ready) => self.go(State::Running),
            (Event::Command(Command::Aux { output, .. }), State::Ready | State::Running) => self.aux |= output.bit(),
            (Event::Command(Command::Stop), State::Running) => self.go(State::Stopping),
            (Event::Command(Command::Stop), State::Homing) => {
                self.homed = false;
                self.go(State::PowerOn { settled: true });
            }
            (Event::Command(Command::ClearFault), State::Fault(_, supplies)) => {
                self.may_move()?;
                self.go(match supplies {
                    Supplies::Both => State::PowerOn { settled: true },
                    // Logic is kept, power is off: the way back up is the normal Enable sequence from Off, and
                    // Off opens the logic relay, which is allowed because power is already off.
                    Supplies::Logic | Supplies::None => State::Off,
                });
            }
            _ => return Err(Refusal::WrongState),
        }
        Ok(())
    }
}
