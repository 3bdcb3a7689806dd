"""Peripheral models the harness owns where Qiling's stm32f411 profile is missing, thin or wrong.

Each model is plain Python: `read(offset, size)` / `write(offset, size, value)` on its register block, a clock
(a callable returning the current time in CPU cycles) and, where it interrupts, a `pend(irq)` callable. They know
nothing of Qiling or Unicorn, so `tests/` exercises them alone; `machine.py` plugs them into Qiling's bus.
Section numbers are those of RM0383 (STM32F411xC/E reference manual, rev 3) unless they name PM0214 (the
Cortex-M4 programming manual) or the ARMv7-M Architecture Reference Manual (ARM DDI 0403E).
"""
