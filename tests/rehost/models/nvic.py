"""NVIC of the Cortex-M4 (PM0214 4.2; ARMv7-M ARM B3.4), replacing Qiling's CortexM4Nvic.

Qiling's model ignores STIR, drops an interrupt raised while PRIMASK is set (it runs the handler at once or never)
and nests handlers as recursive emulator calls. Here the NVIC only keeps state (enabled, pending, active,
priority); `machine.Cpu` decides when an exception is taken, and keeps the active stack.

Exception numbers: IRQn + 16 for external interrupts; 11 SVCall, 14 PendSV, 15 SysTick. Qiling's peripherals
call `set_pending(IRQn)` with IRQn < 0 for system exceptions (-2 PendSV, -1 SysTick), as CMSIS numbers them.
"""

from .base import Block

IRQS = 240  # PM0214 4.2: up to 240 interrupts (the F411 has 86, RM0383 10.2, vector table)
PRIO_BITS = 0xF0  # PM0214 4.2.7: the STM32F4 implements the 4 upper bits of each priority byte


class Nvic(Block):
    # PM0214 4.2 Table 47, offsets from 0xE000_E100
    ISER, ICER, ISPR, ICPR, IABR, IPR, STIR = 0x000, 0x080, 0x100, 0x180, 0x200, 0x300, 0xE00
    # PM0214 4.2 Table 47 and 4.4 (SCB at 0xE000_ED00): the NVIC's registers are two windows, ISER-IPR and STIR,
    # with the SCB between them; one window up to STIR would shadow the SCB (AIRCR, VTOR, SHPR) on the bus
    region = [(0x000, 0x400), (0xE00, 0xE04)]

    def __init__(self, sys_priority=lambda exc: 0):
        # sys_priority(exc) gives the priority of a system exception (SCB.SHPRx, PM0214 4.4.8).
        self.sys_priority = sys_priority
        self.reset()

    def reset(self):
        self.enabled = set()  # IRQn
        self.pending = set()  # exception numbers (16+IRQn, or 11/14/15)
        self.active = set()  # exception numbers, kept by the CPU
        self.prio = bytearray(IRQS)
        self.stir_writes = 0
        self.held = set()  # IRQn the harness cuts off (fault injection): never taken while held
        self.changed = False  # set on every enable/pend: the CPU checks for an exception to take

    # -- the interface Qiling's peripherals and the CPU use --
    def set_pending(self, irqn):
        exc = irqn + 16
        if exc not in self.pending:
            self.pending.add(exc)
            self.changed = True

    def clear_pending(self, irqn):
        self.pending.discard(irqn + 16)

    def priority(self, exc):
        return self.prio[exc - 16] if exc >= 16 else self.sys_priority(exc)

    def takeable(self, exc):
        """Pending and enabled (system exceptions are always enabled here: PM0214 4.4.9 SHCSR covers faults)."""
        return exc < 16 or ((exc - 16) in self.enabled and (exc - 16) not in self.held)

    def best_pending(self):
        """(priority, exception) of the pending exception to take next, or None: lowest priority value first,
        then the lowest exception number (ARMv7-M ARM B1.5.4)."""
        best = None
        for exc in self.pending:
            if self.takeable(exc):
                key = (self.priority(exc), exc)
                if best is None or key < best:
                    best = key
        return best

    # -- registers --
    def _bits(self, group):
        words = [0] * 8
        for n in group:
            if 0 <= n < IRQS:
                words[n >> 5] |= 1 << (n & 31)
        return words

    def read32(self, off):
        if self.ISER <= off < self.ISER + 32 or self.ICER <= off < self.ICER + 32:
            # PM0214 4.2.2/4.2.3: both read the enable state
            return self._bits(self.enabled)[(off & 0x1F) >> 2]
        if self.ISPR <= off < self.ISPR + 32 or self.ICPR <= off < self.ICPR + 32:
            # PM0214 4.2.4/4.2.5: both read the pending state
            return self._bits(e - 16 for e in self.pending)[(off & 0x1F) >> 2]
        if self.IABR <= off < self.IABR + 32:
            # PM0214 4.2.6: active bits, read only
            return self._bits(e - 16 for e in self.active)[(off & 0x1F) >> 2]
        if self.IPR <= off < self.IPR + IRQS:
            n = off - self.IPR
            return int.from_bytes(self.prio[n : n + 4], "little")
        return 0  # STIR is write only (PM0214 4.2.8)

    def write(self, offset, size, value):
        # IPR is byte-accessible (PM0214 4.2.7): a byte write must not touch its neighbours
        if self.IPR <= offset < self.IPR + IRQS:
            for i in range(size):
                if offset + i - self.IPR < IRQS:
                    self.prio[offset + i - self.IPR] = (value >> (8 * i)) & PRIO_BITS
            return
        Block.write(self, offset, size, value)

    def write32(self, off, value):
        base = (off & 0x1F) * 8  # IRQ number of bit 0 of this word
        ones = [base + i for i in range(32) if value >> i & 1]
        if self.ISER <= off < self.ISER + 32:  # PM0214 4.2.2: write 1 enables
            self.enabled.update(ones)
            self.changed = True
        elif self.ICER <= off < self.ICER + 32:  # PM0214 4.2.3: write 1 disables
            self.enabled.difference_update(ones)
        elif self.ISPR <= off < self.ISPR + 32:  # PM0214 4.2.4: write 1 pends
            for n in ones:
                self.set_pending(n)
        elif self.ICPR <= off < self.ICPR + 32:  # PM0214 4.2.5: write 1 clears pending
            for n in ones:
                self.clear_pending(n)
        elif off == self.STIR:  # PM0214 4.2.8: INTID (bits 8:0) pends that interrupt
            self.stir_writes += 1
            self.set_pending(value & 0x1FF)
        elif self.IPR <= off < self.IPR + IRQS:
            self.write(off, 4, value)
