//! ringpod controller firmware.
//!
//! `main` only starts the board: the board module (a folder under `board/`, chosen by a cargo feature) brings up clocks and
//! pins in their safe state, restores the settings and spawns the tasks of `app`, which wire the shared control
//! core (`ringpod_core::controller`) to the host link, the control tick, the switches and the step generator.
//! `board-f411` (the default) is the STM32F411CE Black Pill.

#![no_std]
#![no_main]

#[cfg(feature = "board-f411")]
#[path = "board/stm32f411/mod.rs"]
mod board;

#[embassy_executor::main]
async fn main(spawner: embassy_executor::Spawner) {
    board::start(spawner).await;
}
