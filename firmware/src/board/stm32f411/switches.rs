//! The switch inputs on PA0-PA8 and the supply senses on PA9 and PC14, each on its own EXTI line (0-9, 14), and the
//! task that debounces them. With a spare axis fitted the senses' pins are STEP7 and DIR8: there are no senses then.

use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::Pull;
use embassy_stm32::mode::Async;
use ringpod_core::safety::debounce::InputBit;
use ringpod_firmware::app::{self, inputs::InputPins, Shared};

use super::resources::{Irqs, SensePins, SwitchPins};

/// The switch inputs on PA0-PA8 (order of `InputBit`), and the supply senses on PA9 and PC14 unless their pins
/// drive spare axes.
pub struct Switches {
    pins: [ExtiInput<'static, Async>; 9],
    senses: Option<[ExtiInput<'static, Async>; 2]>,
}

/// Which logical bit each of `Switches::pins` is.
const SWITCH_BITS: [InputBit; 9] = [
    InputBit::EStop,
    InputBit::Home(0),
    InputBit::Home(1),
    InputBit::Home(2),
    InputBit::Home(3),
    InputBit::Home(4),
    InputBit::Home(5),
    InputBit::Limit(4),
    InputBit::Limit(5),
];

/// Which logical bit each of `Switches::senses` is. Without senses both read low, as their pull-downs would with
/// the supplies off: the supervisor then sequences by timing alone (the configuration refuses a sensed supply
/// beside a fitted spare axis).
const SENSE_BITS: [InputBit; 2] = [InputBit::LogicOk, InputBit::PowerOk];

/// The inputs this board has no pin for (far ends of carriages 1-4) read high, as an open switch to ground on a
/// pull-up does: inactive with the default wiring, instead of four limit switches always tripped.
const UNWIRED_HIGH: u16 =
    InputBit::Limit(0).mask() | InputBit::Limit(1).mask() | InputBit::Limit(2).mask() | InputBit::Limit(3).mask();

impl InputPins for Switches {
    fn read(&mut self) -> u16 {
        let senses = self.senses.iter().flatten().zip(SENSE_BITS);
        self.pins
            .iter()
            .zip(SWITCH_BITS)
            .chain(senses)
            .fold(UNWIRED_HIGH, |w, (p, b)| if p.is_high() { w | b.mask() } else { w })
    }

    async fn edge(&mut self) {
        use embassy_futures::select::{select, select_array};
        let waits = self.pins.each_mut().map(|p| p.wait_for_any_edge());
        match self.senses.as_mut() {
            Some(senses) => {
                let sensed = senses.each_mut().map(|p| p.wait_for_any_edge());
                select(select_array(waits), select_array(sensed)).await;
            }
            None => {
                select_array(waits).await;
            }
        }
    }
}

/// The inputs with their pulls (the pin table, README and the book's Hardware chapter): the e-stop chain has an external pull-up, the switches to
/// ground the internal one, and the supply senses (`None`: their pins drive spare axes) are pulled down.
pub fn new(r: SwitchPins, senses: Option<SensePins>) -> Switches {
    Switches {
        senses: senses.map(|r| {
            [
                ExtiInput::new(r.logic_ok, r.logic_ok_line, Pull::Down, Irqs),
                ExtiInput::new(r.power_ok, r.power_ok_line, Pull::Down, Irqs),
            ]
        }),
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
        ],
    }
}

#[embassy_executor::task]
pub async fn inputs_task(mut switches: Switches, shared: &'static Shared) -> ! {
    app::inputs::run(&mut switches, shared).await
}
