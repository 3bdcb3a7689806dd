//! The simulated controller: the firmware's controller core and a simulated plant behind the real framed bytes,
//! served in process (`--sim`), on a pseudo-terminal (`simulate --pty`) or over TCP (`simulate --tcp`).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use embassy_futures::block_on;
use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::protocol::RigSource;
use ringpod_core::protocol::{self, FrameReader};
use ringpod_core::sim::RamFlash;
use ringpod_core::sim::{Plant, Rig, TRAINER_MODEL_PARKED};
use ringpod_core::store;

use crate::link::client::Transport;

/// How far the real-time simulator may fall behind the wall clock and still tick the periods it owes: a tenth of
/// the stream's default timeout (100 ms), so that a catch-up burst can never run it out.
const CATCH_UP: Duration = Duration::from_millis(10);

/// Erase page of the simulator's settings flash.
const SIM_FLASH_PAGE: usize = 2048;
/// Size of the simulator's settings flash (as the QEMU controller's).
const SIM_FLASH_SIZE: usize = 4 * SIM_FLASH_PAGE;

/// The simulated controller: the same controller core as the firmware (dispatch, supervisor, pipeline, step
/// scheduler) with a simulated plant, behind the real framed bytes. Time passes only through [`Transport::elapse`]:
/// in real time (sleeping to keep pace with the wall clock) or as fast as the machine can compute.
pub struct SimDevice {
    rig: Rig,
    /// Its settings flash, written and read as the firmware's settings task does.
    flash: RamFlash<'static, SIM_FLASH_PAGE>,
    reader: FrameReader,
    outbox: VecDeque<u8>,
    tick_us: u64,
    owed_us: u64,
    realtime: bool,
    /// Where the simulated clock is tied to the wall clock (the wall's instant and the simulated time then), if it
    /// is: from the start in real time; as fast as the machine computes, only once the source is live
    /// ([`Transport::keep_pace`]).
    paced: Option<(Instant, u64)>,
    simulated_us: u64,
    /// Periods passed after hold-ups (see [`SimDevice::held_up`]), reported in the status as a board's are.
    passed: u32,
}

impl SimDevice {
    /// A simulated trainer model, parked near home, powered off.
    pub fn new(realtime: bool) -> Self {
        let config = ControllerConfig::trainer_model();
        let controller = Controller::new(config).expect("the built-in model configuration is valid");
        Self::with(realtime, controller, Plant::trainer_model(TRAINER_MODEL_PARKED))
    }

    /// A simulated ring platform of a rig file, with the trainer model's drives, switches and timings, parked as
    /// the model is (each axis a little before its switch), powered off.
    pub fn for_rig(realtime: bool, rig: &crate::rig::Rig) -> Result<Self, super::LinkError> {
        // The record a board would store: geometry, home, axes, pose limits and inputs, through the same code.
        let undrivable = |reason| super::LinkError::Undrivable {
            rig: rig.record.name().to_owned(),
            reason,
        };
        let mut config = ControllerConfig::from_record(&rig.record).map_err(undrivable)?;
        // The spare axes are a section beside the record, as a board stores them.
        config
            .apply(&ringpod_core::protocol::Settings::Spare(rig.spare))
            .and_then(|()| config.validate())
            .map_err(undrivable)?;
        let controller = Controller::new(config).map_err(undrivable)?;
        Ok(Self::with(realtime, controller, Plant::for_config(&config)))
    }

    fn with(realtime: bool, controller: Controller, plant: Plant) -> Self {
        let tick_us = u64::from(controller.pipeline().config().tick_us);
        let rig = Rig {
            controller,
            plant,
            ticks: 0,
        };
        // One flash per simulated device, for the life of the program (a few KiB).
        let bytes: &'static mut [u8] = Box::leak(vec![0xff; SIM_FLASH_SIZE].into_boxed_slice());
        Self {
            rig,
            flash: RamFlash::new(bytes),
            reader: FrameReader::default(),
            outbox: VecDeque::new(),
            tick_us,
            owed_us: 0,
            realtime,
            paced: realtime.then(|| (Instant::now(), 0)),
            simulated_us: 0,
            passed: 0,
        }
    }

    /// What the firmware's settings task does: stores the changed configuration (the controller hands it out only
    /// with the supplies off), and restarts when the host asked for it, restoring from the flash as a
    /// board's start does (the plant is the stored rig's machine, parked near its switches).
    fn settings_task(&mut self) {
        let range = self.flash.range();
        let c = &mut self.rig.controller;
        if let Some(config) = c.take_unsaved() {
            // A RAM flash only fails when full; the device then runs on and the next start finds the old record.
            let _ = block_on(store::store(&mut self.flash, range.clone(), &config));
        }
        // The simulated controller has no ROM bootloader: a request for it restarts the controller.
        if c.restart_due().is_some() {
            let (config, restored) = block_on(store::restore(
                &mut self.flash,
                range,
                ControllerConfig::trainer_model(),
            ));
            let Ok(mut controller) = Controller::new(config) else {
                return;
            };
            controller.set_rig_source(restored.rig);
            let plant = match restored.rig {
                RigSource::Stored => Plant::for_config(&config),
                _ => Plant::trainer_model(TRAINER_MODEL_PARKED),
            };
            self.tick_us = u64::from(config.pipeline.tick_us);
            self.rig = Rig {
                controller,
                plant,
                ticks: 0,
            };
            self.reader = FrameReader::default();
        }
    }

    /// Whether the period about to run is one a hold-up of this process cost (when paced by the wall clock): the
    /// simulated clock is more than [`CATCH_UP`] behind the wall clock, as after the process was stopped (`kill
    /// -STOP`), swapped out or starved on a busy machine. Those periods are passed, as a board passes the periods a
    /// flash erase cost: ticked in a burst, they would run the stream's timeout out in a few milliseconds of wall
    /// time, before the setpoints the host sent meanwhile could arrive. Lags up to [`CATCH_UP`] are ticked: a busy
    /// machine's ordinary jitter loses no motion.
    fn held_up(&self) -> bool {
        self.due()
            .is_some_and(|due| Instant::now().saturating_duration_since(due) > CATCH_UP)
    }

    /// When the wall clock reaches the simulated time, if the two are tied.
    fn due(&self) -> Option<Instant> {
        self.paced
            .map(|(wall, us)| wall + Duration::from_micros(self.simulated_us.saturating_sub(us)))
    }

    fn flush_unsolicited(&mut self) {
        let mut out = [0u8; protocol::MAX_FRAME];
        while let Some(msg) = self.rig.controller.unsolicited() {
            if let Ok(n) = protocol::encode(&msg, &mut out) {
                self.outbox.extend(&out[..n]);
            }
        }
    }
}

impl Transport for SimDevice {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let mut out = [0u8; protocol::MAX_FRAME];
        for &b in bytes {
            if let Some(frame) = self.reader.push(b) {
                let frame = frame.to_vec();
                let n = self.rig.controller.handle_frame(&frame, &mut out);
                self.outbox.extend(&out[..n]);
            }
        }
        Ok(())
    }

    fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.outbox.len());
        for (slot, b) in buf.iter_mut().zip(self.outbox.drain(..n)) {
            *slot = b;
        }
        Ok(n)
    }

    fn elapse(&mut self, dt: Duration) {
        self.owed_us += dt.as_micros() as u64;
        // Tied to the wall clock, the device's periods are the wall's, as a board's are: a caller that let less
        // time pass than the wall did (its own work between two calls) still has every period run. Without this
        // the lag grew by that work at each call until every period was one to pass, and the platform froze.
        if let Some(due) = self.due() {
            let behind = Instant::now().saturating_duration_since(due).as_micros() as u64;
            self.owed_us = self.owed_us.max(behind);
        }
        while self.owed_us >= self.tick_us {
            self.owed_us -= self.tick_us;
            if self.held_up() {
                self.rig.pass();
                self.passed = self.passed.saturating_add(1);
                self.rig.controller.set_step_counters(0, self.passed);
            } else {
                let started = Instant::now();
                self.rig.tick();
                let cost = started.elapsed().as_nanos().min(u128::from(u32::MAX)) as u32;
                self.rig.controller.set_platform_stats(cost, 0);
            }
            self.simulated_us += self.tick_us;
            if self.rig.ticks.is_multiple_of(100) {
                self.settings_task();
            }
            // After every tick, as the firmware's control task does: no sample is coalesced with the next.
            self.flush_unsolicited();
        }
        if let Some(wait) = self
            .due()
            .filter(|_| self.realtime)
            .and_then(|due| due.checked_duration_since(Instant::now()))
        {
            std::thread::sleep(wait);
        }
    }

    fn keep_pace(&mut self) {
        // In real time the clocks are tied from the start. As fast as the machine computes, the simulated clock ran
        // ahead (homing, the lead-in) and is tied from now on: a live source's gaps are wall time, so a hold-up of
        // this process is one to pass as in real time, not a burst of ticks that loses the stream.
        if !self.realtime {
            self.paced = Some((Instant::now(), self.simulated_us));
        }
    }
}
