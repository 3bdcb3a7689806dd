"""The EXTI controller's interrupt side for GPIO lines 0-15 (RM0383 section 10.2).

Qiling's EXTI model only stores its registers. Here an edge on a pin (`edge`, from the harness driving an input)
sets the line's pending bit when the line's trigger is selected for that edge (RTSR/FTSR, 10.3.3/10.3.4) and the
pin's port is the one SYSCFG_EXTICR routes to the line (7.2.3-7.2.6); an unmasked pending line (IMR, 10.3.1)
raises its NVIC line. PR is write-1-to-clear (10.3.6); SWIER (10.3.5) sets PR by software.
"""

from models.base import Block

IMR, EMR, RTSR, FTSR, SWIER, PR = 0x00, 0x04, 0x08, 0x0C, 0x10, 0x14
# RM0383 10.2 (vector table): EXTI0-4, EXTI9_5, EXTI15_10
IRQ_OF_LINE = [6, 7, 8, 9, 10] + [23] * 5 + [40] * 6


class Exti(Block):
    def __init__(self, pend, exticr):
        self.pend = pend
        self.exticr = exticr  # line -> port index (0 = A) from SYSCFG_EXTICRx
        self.reset()

    def reset(self):
        self.imr = self.emr = self.rtsr = self.ftsr = self.pr = 0
        self.edges = 0  # edges that set a pending bit

    def read32(self, offset):
        return {IMR: self.imr, EMR: self.emr, RTSR: self.rtsr, FTSR: self.ftsr, SWIER: 0, PR: self.pr}.get(offset, 0)

    def write32(self, offset, value):
        value &= 0x7FFFFF
        if offset == IMR:
            self.imr = value
        elif offset == EMR:
            self.emr = value
        elif offset == RTSR:
            self.rtsr = value
        elif offset == FTSR:
            self.ftsr = value
        elif offset == SWIER:
            self._set(value)
        elif offset == PR:
            self.pr &= ~value
        self._raise()

    def edge(self, port, line, rising):
        """A pin of `port` (0 = A) on EXTI `line` changed level."""
        if self.exticr(line) != port:
            return
        if (self.rtsr if rising else self.ftsr) >> line & 1:
            self.edges += 1
            self._set(1 << line)
            self._raise()

    def _set(self, bits):
        self.pr |= bits

    def _raise(self):
        pending = self.pr & self.imr
        for line in range(16):
            if pending >> line & 1:
                self.pend(IRQ_OF_LINE[line])
