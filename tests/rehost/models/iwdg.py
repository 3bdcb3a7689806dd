"""Independent watchdog (RM0383 section 15). Qiling's profile names IWDG but has no model for it.

The down-counter runs from the LSI (32 kHz nominal, RM0383 6.2, LSI clock) through the prescaler (4 << PR); when it
reaches 0 the chip resets (17.3.1). Times are in CPU cycles: `cycles_per_s` converts (96 MHz on this board).
"""

from .base import NEVER, Block

KEY_RELOAD, KEY_ACCESS, KEY_START = 0xAAAA, 0x5555, 0xCCCC  # RM0383 15.4.1 IWDG_KR
PVU, RVU = 1 << 0, 1 << 1  # RM0383 15.4.4 IWDG_SR


class Iwdg(Block):
    KR, PR, RLR, SR = 0x0, 0x4, 0x8, 0xC

    def __init__(self, clock, on_timeout, cycles_per_s=96_000_000, lsi_hz=32_000):
        self.clock, self.on_timeout = clock, on_timeout
        self.cycles_per_s, self.lsi_hz = cycles_per_s, lsi_hz
        self.reset()

    def reset(self):
        self.started = False
        self.access = False
        self.pr = self.pr_act = 0  # RM0383 15.4.2 IWDG_PR: PR resets to 0 (divide by 4)
        self.rlr = self.rlr_act = 0xFFF  # RM0383 15.4.3 IWDG_RLR: RLR resets to 0xFFF
        self.pvu_until = self.rvu_until = 0
        self.t_a, self.c_a = 0, 0xFFF  # counter value c_a at time t_a
        self.reloads = []  # times of every KR = 0xAAAA while running
        self.config_reloads = []  # of those, the ones that end a configuration (after a KR = 0x5555)
        self.configuring = False
        self.expired_at = None

    def tick(self, pr):
        """Cycles per counter step: (4 << PR) LSI periods."""
        return (4 << pr) * self.cycles_per_s // self.lsi_hz

    def update_time(self):
        # RM0383 15.4.4 IWDG_SR: a PR or RLR update takes up to 5 LSI periods (RC 40 kHz cycles) in the VDD domain
        return 5 * self.cycles_per_s // self.lsi_hz

    def counter(self, now):
        return max(0, self.c_a - (now - self.t_a) // self.tick(self.pr_act))

    def deadline(self):
        return self.t_a + self.c_a * self.tick(self.pr_act) if self.started else NEVER

    def _apply_updates(self, now):
        # the new prescaler counts from here on; a new reload value is used from the next reload (RM0383 15.3)
        if self.pvu_until and self.pvu_until <= now:
            at = self.pvu_until
            if self.started:
                self.c_a, self.t_a = self.counter(at), at
            self.pr_act, self.pvu_until = self.pr, 0
        if self.rvu_until and self.rvu_until <= now:
            self.rlr_act, self.rvu_until = self.rlr, 0

    def advance(self, now):
        self._apply_updates(now)
        if self.started and self.expired_at is None and self.deadline() <= now:
            self.expired_at = self.deadline()
            self.on_timeout(self.expired_at)  # RM0383 15.3: counter at 0x000: reset

    def next_event(self, now):
        return max(now + 1, min(self.deadline(), self.pvu_until or NEVER, self.rvu_until or NEVER))

    def read32(self, off):
        now = self.clock()
        self._apply_updates(now)
        if off == self.PR:
            return self.pr
        if off == self.RLR:
            return self.rlr
        if off == self.SR:
            return (PVU if self.pvu_until else 0) | (RVU if self.rvu_until else 0)
        return 0  # KR is write only

    def write32(self, off, value):
        now = self.clock()
        self.advance(now)
        if off == self.KR:
            key = value & 0xFFFF
            self.configuring |= key == KEY_ACCESS
            self.access = key == KEY_ACCESS  # RM0383 15.3 (register access protection): any other key protects PR and RLR again
            if key == KEY_START and not self.started:
                self.started = True  # RM0383 15.3: start counting from the reset value 0xFFF
                self.c_a, self.t_a = self.rlr_act, now
            elif key == KEY_RELOAD:
                if self.started:
                    self.reloads.append(now)
                    if self.configuring:
                        self.config_reloads.append(now)
                self.configuring = False
                self.c_a, self.t_a = self.rlr_act, now  # RM0383 15.3: reload the counter with RLR
        elif off == self.PR and self.access:
            self.pr, self.pvu_until = value & 7, now + self.update_time()
        elif off == self.RLR and self.access:
            self.rlr, self.rvu_until = value & 0xFFF, now + self.update_time()
