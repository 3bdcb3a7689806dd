"""TIM1 (advanced-control, RM0383 section 12) and TIM2-TIM5 / TIM9-TIM11 (general-purpose, sections 13-14):
the up-counting time base, update and compare events with their interrupts, and update and compare DMA requests.

Qiling's STM32F4xxTim has no compare flags (embassy's time driver on TIM5 waits on CC1IF/CC2IF and never ticks),
stores SR writes instead of clearing on write 0, ignores EGR.UG and makes no DMA requests.

The counter is computed from the clock rather than stepped: at time `t_a` it held `c_a`, and it counts once per
`PSC + 1` cycles of the timer clock (here the CPU clock: on this board both APB timer clocks equal SYSCLK, 96 MHz,
RM0383 6.2, clock tree). Not modelled: down and centre-aligned counting (CR1.DIR/CMS), slave modes (SMCR), input
capture, output pins, break (BDTR), DMA burst (DCR/DMAR), CR2.CCDS = 1 (a compare's DMA request at the update).
"""

from .base import NEVER, Block

# RM0383 12.4.1 / 13.4.1 TIMx_CR1
CEN, UDIS, URS, ARPE = 1 << 0, 1 << 1, 1 << 2, 1 << 7
# RM0383 12.4.4 / 13.4.4 TIMx_DIER
UIE, UDE = 1 << 0, 1 << 8
CCIE = [1 << 1, 1 << 2, 1 << 3, 1 << 4]
CCDE = [1 << 9, 1 << 10, 1 << 11, 1 << 12]
# RM0383 12.4.5 / 13.4.5 TIMx_SR
UIF = 1 << 0
CCIF = [1 << 1, 1 << 2, 1 << 3, 1 << 4]
CC_FLAGS = 0x1E


class Tim(Block):
    # register offsets, RM0383 12.4.21 / 13.4.21 register maps
    CR1, CR2, SMCR, DIER, SR, EGR = 0x00, 0x04, 0x08, 0x0C, 0x10, 0x14
    CCMR1, CCMR2, CCER, CNT, PSC, ARR, RCR = 0x18, 0x1C, 0x20, 0x24, 0x28, 0x2C, 0x30
    CCR = [0x34, 0x38, 0x3C, 0x40]
    BDTR, DCR, DMAR, OR = 0x44, 0x48, 0x4C, 0x50
    PLAIN = (0x04, 0x08, 0x18, 0x1C, 0x20, 0x44, 0x48, 0x4C, 0x50)

    def __init__(self, name, clock, pend, irq_up, irq_cc, bits=16):
        """`irq_up`/`irq_cc`: the NVIC lines of the update and capture/compare interrupts (the same line on
        TIM2-5; TIM1_UP_TIM10 = 25 and TIM1_CC = 27 on TIM1, RM0383 10.2, vector table)."""
        self.name, self.clock, self.pend = name, clock, pend
        self.irq_up, self.irq_cc = irq_up, irq_cc
        self.max = (1 << bits) - 1
        # DMA channels this timer's update request is wired to: callables request(n) -> None and
        # horizon() -> requests until the DMA next raises an enabled interrupt (or None).
        self.update_dma = []
        # The same for each compare channel's request (CCxDE, RM0383 12.4.4: a request at each CCx event).
        self.cc_dma = [[], [], [], []]
        self.reset()

    def reset(self):
        self.regs = {off: 0 for off in self.PLAIN}
        self.cr1 = self.dier = self.sr = self.psc = self.rcr = 0
        self.arr = self.max  # RM0383 12.4.12 / 13.4.12: ARR resets to all ones
        self.ccr = [0, 0, 0, 0]
        # active (shadow) registers, loaded at an update event (RM0383 12.3.1, time-base unit)
        self.psc_act, self.arr_act, self.rep = 0, self.max, 0
        self.t_a = self.last = self.clock()
        self.c_a = 0
        self.updates = 0  # update events since reset
        self.dma_requests = 0
        self.cc_requests = [0, 0, 0, 0]  # compare DMA requests since reset, per channel

    # -- the counter --
    def _per(self):
        return self.psc_act + 1

    def _top(self):
        # after ARR was lowered below the counter, the counter runs on to its maximum before wrapping
        return self.arr_act if self.c_a <= self.arr_act else self.max

    def _count(self, t):
        if not self.cr1 & CEN:
            return self.c_a
        return self.c_a + (t - self.t_a) // self._per()

    def _load_shadows(self):
        self.psc_act = self.psc
        self.arr_act = self.arr
        self.rep = self.rcr

    def _update_events(self, n):
        """n update events (UEV): RM0383 12.3.1: UIF set, DMA request when UDE, shadows loaded."""
        self.updates += n
        self.sr |= UIF
        if self.dier & UDE:
            self.dma_requests += n
            for request in self.update_dma:
                request(n)
        self._load_shadows()

    def _compare_events(self, ch, n):
        """n compare matches of channel `ch` (RM0383 12.3.8, output compare mode: CCxIF set, and a DMA request
        when CCxDE, whatever the output mode, the frozen one included)."""
        self.sr |= CCIF[ch]
        if self.dier & CCDE[ch]:
            self.cc_requests[ch] += n
            for request in self.cc_dma[ch]:
                request(n)

    def advance(self, now):
        if now <= self.last:
            return
        if not self.cr1 & CEN:
            self.last = now
            return
        while True:
            per, top = self._per(), self._top()
            t_wrap = self.t_a + (top + 1 - self.c_a) * per
            end = min(now, t_wrap)
            c0, c1 = self._count(self.last), self.c_a + (end - self.t_a) // per
            if c1 > c0:
                # RM0383 12.3 / 13.3, output compare mode: CCxIF when the counter matches CCRx
                for ch in range(4):
                    ccr = self.ccr[ch]
                    if c0 < ccr <= min(c1, top) or (ccr == 0 and end == t_wrap):
                        self._compare_events(ch, 1)
            if t_wrap > now:
                break
            # overflow at t_wrap: RM0383 12.3.3 repetition counter (RCR = 0 on TIM2-5: a UEV at every overflow)
            self.t_a, self.c_a, self.last = t_wrap, 0, t_wrap
            if self.cr1 & UDIS:
                continue
            if self.rep:
                self.rep -= 1
                continue
            self._update_events(1)
            # fast forward whole periods while nothing preloaded changes (TIM1 makes 400,000 updates a second)
            period = (self.arr_act + 1) * (self.psc_act + 1)
            k = (now - t_wrap) // period
            if k > 0 and self.rcr == 0 and not self.cr1 & UDIS:
                self.t_a += k * period
                self.last = self.t_a
                self._update_events(k)
                for ch in range(4):
                    if self.ccr[ch] <= self.arr_act:
                        self._compare_events(ch, k)  # one match in each whole period
        self.last = now
        self._irq()

    def _irq(self):
        """Interrupt lines are levels: pending while a flag and its enable are both set (RM0383 12.4.4)."""
        active = self.sr & self.dier
        if active & UIF:
            self.pend(self.irq_up)
        if active & CC_FLAGS:
            self.pend(self.irq_cc)

    def next_event(self, now):
        """Earliest time after `now` at which an enabled interrupt flag is set or the DMA it feeds interrupts."""
        if not self.cr1 & CEN:
            return NEVER
        per, top = self._per(), self._top()
        c = self._count(now)
        t_wrap = self.t_a + (top + 1 - self.c_a) * per
        best = NEVER
        if self.dier & UIE:
            best = t_wrap
        for ch in range(4):
            if self.dier & CCIE[ch] and self.ccr[ch] <= self.max:
                ccr = self.ccr[ch]
                t = self.t_a + (ccr - self.c_a) * per if c < ccr <= top else t_wrap + ccr * per
                best = min(best, t)
        period = (self.arr + 1) * (self.psc + 1)
        if self.dier & UDE:
            for request in self.update_dma:
                h = request.horizon()
                if h is not None:
                    best = min(best, t_wrap + (max(h, 1) - 1) * period)
        for ch in range(4):
            ccr = self.ccr[ch]
            if not self.dier & CCDE[ch] or ccr > top:
                continue
            # the next match: in this period if the counter is below CCRx, else in the next
            first = self.t_a + (ccr - self.c_a) * per if c < ccr else t_wrap + ccr * per
            for request in self.cc_dma[ch]:
                h = request.horizon()
                if h is not None:
                    best = min(best, first + (max(h, 1) - 1) * period)
        return max(best, now + 1)

    # -- registers --
    def read32(self, off):
        self.advance(self.clock())
        if off == self.CR1:
            return self.cr1
        if off == self.DIER:
            return self.dier
        if off == self.SR:
            return self.sr
        if off == self.CNT:
            return self._count(self.clock()) & self.max
        if off == self.PSC:
            return self.psc
        if off == self.ARR:
            return self.arr
        if off == self.RCR:
            return self.rcr
        if off in self.CCR:
            return self.ccr[self.CCR.index(off)]
        return self.regs.get(off, 0)  # EGR reads 0 (RM0383 12.4.6)

    def write32(self, off, value):
        now = self.clock()
        self.advance(now)
        if off == self.CR1:
            if (value ^ self.cr1) & CEN:
                # starting or stopping freezes the count here; counting resumes from it (RM0383 12.3.2)
                self.c_a, self.t_a = self._count(now), now
            self.cr1 = value & 0x3FF
        elif off == self.DIER:
            self.dier = value & 0x5FFF
        elif off == self.SR:
            # RM0383 12.4.5 / 13.4.5 TIMx_SR: rc_w0, writing 0 clears a flag and writing 1 has no effect
            self.sr &= value
        elif off == self.EGR:
            if value & 1:
                # RM0383 12.4.6 EGR.UG: re-initialise the counter and load the shadow registers; with URS = 1
                # no UIF and no DMA request (CR1.URS, RM0383 12.4.1)
                self.c_a, self.t_a = 0, now
                if self.cr1 & URS:
                    self._load_shadows()
                else:
                    self._update_events(1)
            for ch in range(4):  # CCxG: a capture/compare event sets CCxIF
                if value & (2 << ch):
                    self.sr |= CCIF[ch]
        elif off == self.CNT:
            self.c_a, self.t_a = value & self.max, now
        elif off == self.PSC:
            self.psc = value & 0xFFFF  # RM0383 12.4.11: preloaded, active from the next update event
        elif off == self.ARR:
            self.arr = value & self.max
            if not self.cr1 & ARPE:  # RM0383 12.4.1 ARPE = 0: ARR is not buffered
                self.arr_act = self.arr
        elif off == self.RCR:
            self.rcr = value & 0xFF
        elif off in self.CCR:
            self.ccr[self.CCR.index(off)] = value & self.max  # compare preload (OCxPE) not modelled
        elif off in self.regs:
            self.regs[off] = value
        self._irq()
