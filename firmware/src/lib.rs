//! The ringpod controller's firmware tasks, independent of the board: [`app`].
//!
//! The STM32F411 binary (`src/main.rs` with `board/stm32f411/`) and the QEMU mps2-an386 program
//! (`tests/qemu/src/bin/controller/`) are each a board module around these same tasks.

#![no_std]
#![allow(async_fn_in_trait)]

pub mod app;
