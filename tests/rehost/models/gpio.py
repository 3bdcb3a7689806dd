"""GPIO ports on Qiling's STM32F4xxGpio register layout, with what this board needs added (RM0383 section 8).

Qiling's model applies BSRR's reset bits after its set bits (the opposite priority), reads every input as 0
whatever its pull resistor, and handles a BSRR word bit by bit with a log call: too slow for 400,000 DMA words
a simulated second. `bsrr_words` takes the DMA's words in bulk and counts the pin edges they make.
"""

from collections import Counter

from qiling.hw.gpio.stm32f4xx_gpio import STM32F4xxGpio

MODER, PUPDR, IDR, ODR, BSRR = 0x00, 0x0C, 0x10, 0x14, 0x18


class Gpio(STM32F4xxGpio):
    def __init__(self, ql, label, **kwargs):
        super().__init__(ql, label, **kwargs)
        self.external = {}  # pin -> level driven from outside the chip
        self.bsrr_writes = 0
        self.dma_words = 0  # of bsrr_writes, those the DMA made (counted by the bus)
        self.rises = Counter()  # mask of pins that rose together -> count
        self.falls = Counter()
        self.on_change = None  # called with (old ODR, new ODR, DMA word index) on every change of the pins

    def drive(self, pin, level):
        """Drive an input pin from outside (a switch, a relay contact)."""
        self.external[pin] = 1 if level else 0

    def _input_level(self, pin):
        # RM0383 8.3.1 / 8.4.4: an input with no external driver reads its pull-up (1) or pull-down (0)
        if pin in self.external:
            return self.external[pin]
        pull = (self.instance.PUPDR >> (2 * pin)) & 3
        return 1 if pull == 1 else 0

    def idr(self):
        # RM0383 8.3 (I/O port control): IDR samples every pin, so an output reads back its level
        odr, moder, value = self.instance.ODR, self.instance.MODER, 0
        for pin in range(16):
            mode = (moder >> (2 * pin)) & 3
            level = (odr >> pin) & 1 if mode == 1 else self._input_level(pin)
            value |= level << pin
        return value

    def read(self, offset, size):
        if offset == IDR:
            return self.idr()
        if offset == BSRR:
            return 0  # RM0383 8.4.7: BSRR is write only
        return super().read(offset, size)

    def _set_odr(self, new):
        old = self.instance.ODR
        if new != old and self.on_change:
            self.on_change(old, new, self.dma_words)
        if new != old:
            if new & ~old:
                self.rises[new & ~old] += 1
            if old & ~new:
                self.falls[old & ~new] += 1
            self.instance.ODR = new

    def write(self, offset, size, value):
        if offset == BSRR:
            self.bsrr_words([value])
        elif offset == ODR:
            self._set_odr(value & 0xFFFF)
        elif offset != IDR:
            super().write(offset, size, value)

    def bsrr_words(self, words):
        """RM0383 8.4.7 GPIOx_BSRR: BRy (bits 31:16) reset, BSy (15:0) set; BSy has priority over BRy."""
        self.bsrr_writes += len(words)
        odr = self.instance.ODR
        watch = self.on_change
        for i, w in enumerate(words):
            if w:
                new = (odr & ~(w >> 16) | w) & 0xFFFF
                if new != odr:
                    if new & ~odr:
                        self.rises[new & ~odr] += 1
                    if odr & ~new:
                        self.falls[odr & ~new] += 1
                    if watch:
                        watch(odr, new, self.dma_words + i)
                    odr = new
        self.instance.ODR = odr

    def edges(self, pin, counter):
        return sum(n for mask, n in counter.items() if mask >> pin & 1)
