"""DWT cycle counter (ARMv7-M ARM C1.8.6-C1.8.8): CYCCNT counts CPU cycles while DWT_CTRL.CYCCNTENA is set.

The firmware reads it to measure the control loop (`Machine::cycles`); in Qiling's profile it is plain memory
that reads 0. One emulated instruction is one cycle here.
"""

from .base import Block


class Dwt(Block):
    CTRL, CYCCNT = 0x0, 0x4
    size = 0x1000

    def __init__(self, clock):
        self.clock = clock
        self.ctrl = 0x40000000  # NUMCOMP = 4 (Cortex-M4), CYCCNTENA = 0
        self.base_count, self.t_a = 0, 0
        self.regs = {}

    def read32(self, off):
        if off == self.CTRL:
            return self.ctrl
        if off == self.CYCCNT:
            now = self.clock()
            run = now - self.t_a if self.ctrl & 1 else 0
            return (self.base_count + run) & 0xFFFFFFFF
        return self.regs.get(off, 0)

    def write32(self, off, value):
        if off == self.CTRL:
            self.base_count = self.read32(self.CYCCNT)
            self.t_a = self.clock()
            self.ctrl = (self.ctrl & 0xFFFF0000) | (value & 0xFFFF)
        elif off == self.CYCCNT:
            self.base_count, self.t_a = value, self.clock()
        else:
            self.regs[off] = value
