//! The switch inputs on PA0-PA9 and PC14, each on its own EXTI line (0-9, 14), and the task that debounces them.

use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::Pull;
use embassy_stm32::mode::Async;
use ringpod_core::safety::debounce::InputBit;
use ringpod_firmware::app::{self, inputs::InputPins, Shared};

use super::resources::{Irqs, SwitchPins};

/// The switch inputs on PA0-PA9 and PC14 (order of `InputBit`).
pub struct Switches {
    pins: [ExtiInput<'static, Async>; 11],
}

/// Which logical bit each of `Switches::pins` is.
const SWITCH_BITS: [InputBit; 11] = [
    InputBit::EStop,
    InputBit::Home(0),
    InputBit::Home(1),
    InputBit::Home(2),
    InputBit::Home(3),
    InputBit::Home(4),
    InputBit::Home(5),
    InputBit::Limit(4),
    InputBit::Limit(5),
    InputBit::LogicOk,
    InputBit::PowerOk,
];

/// The inputs this board has no pin for (far ends of carriages 1-4) read high, as an open switch to ground on a
/// pull-up does: inactive with the default wiring, instead of four limit switches always tripped.
const UNWIRED_HIGH: u16 =
    InputBit::Limit(0).mask() | InputBit::Limit(1).mask() | InputBit::Limit(2).mask() | InputBit::Limit(3).mask();

impl InputPins for Switches {
    fn read(&mut self) -> u16 {
        self.pins
            .iter()
            .zip(SWITCH_BITS)
            .fold(UNWIRED_HIGH, |w, (p, b)| if p.is_high() { w | b.mask() } else { w })
    }

    async fn edge(&mut self) {
        let waits = self.pins.each_mut().map(|p| p.wait_for_any_edge());
        embassy_futures::select::select_array(waits).await;
    }
}

/// The inputs with their pulls (the pin table, README and the book's Hardware chapter): the e-stop chain has an external pull-up, the switches to
/// ground the internal one, and the supply senses are pulled down.
pub fn new(r: SwitchPins) -> Switches {
    Switches {
        pins: [
            ExtiInput::new(r.estop, r.estop_line, Pull::None, Irqs),
            ExtiInput::new(r.home1, r.home1_line, Pull::Up, Irqs),
            ExtiInput::new(r.home2, r.home2_line, Pull::Up, Irqs),
            ExtiInput::new(r.home3, r.home3_line, Pull::Up, Irqs),
            ExtiInput::new(r.home4, r.home4_line, Pull::Up, Irqs),
            ExtiInput::new(r.home5, r.home5_line, Pull::Up, Irqs),
            ExtiInput::new(r.home6, r.home6_line, Pull::Up, Irqs),
            ExtiInput::new(r.limit5, r.limit5_line, Pull::Up, Irqs),
            ExtiInput::new(r.limit6, r.limit6_line, Pull::Up, Irqs),
            ExtiInput::new(r.logic_ok, r.logic_ok_line, Pull::Down, Irqs),
            ExtiInput::new(r.power_ok, r.power_ok_line, Pull::Down, Irqs),
        ],
    }
}

#[embassy_executor::task]
pub async fn inputs_task(mut switches: Switches, shared: &'static Shared) -> ! {
    app::inputs::run(&mut switches, shared).await
}
