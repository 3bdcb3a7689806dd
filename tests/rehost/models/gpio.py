"""GPIO ports on Qiling's STM32F4xxGpio register layout, with what this board needs added (RM0383 section 8).

Qiling's model applies BSRR's reset bits after its set bits (the opposite priority), reads every input as 0
whatever its pull resistor, and handles a BSRR word bit by bit with a log call: too slow for 400,000 DMA words
a simulated second. `bsrr_words` takes the DMA's words in bulk and counts the pin edges they make.

The pins seen from outside the chip: `driven(pin)` is the level an output drives (ODR through a push-pull output;
an open-drain output drives only its low), `None` for a pin that drives nothing (an input, analog, an alternate
function whose level is the peripheral's); an input reads what drives it from outside (`drive`), else its pull,
else it floats: a read of a floating `wired` pin is counted in `floating_reads` (on silicon it reads noise).
"""

from collections import Counter

from qiling.hw.gpio.stm32f4xx_gpio import STM32F4xxGpio

MODER, OTYPER, PUPDR, IDR, ODR, BSRR = 0x00, 0x04, 0x0C, 0x10, 0x14, 0x18
INPUT, OUTPUT, ALTERNATE, ANALOG = range(4)  # RM0383 8.4.1 GPIOx_MODER


class Gpio(STM32F4xxGpio):
    def __init__(self, ql, label, **kwargs):
        super().__init__(ql, label, **kwargs)
        self.external = {}  # pin -> level driven from outside the chip (absent or None: nothing drives it)
        self.wired = set()  # pins something outside is connected to: their floating reads are counted
        self.floating_reads = Counter()  # pin -> reads of IDR while that wired input floated
        self.bsrr_writes = 0
        self.dma_words = 0  # of bsrr_writes, those the DMA made (counted by the bus)
        self.rises = Counter()  # mask of pins that rose together -> count
        self.falls = Counter()
        self.on_change = None  # called with (old ODR, new ODR, DMA word index) on every change of the pins

    def drive(self, pin, level):
        """Drive a pin from outside: 0 (a contact to ground), 1 (a supply, an external pull-up) or None (released)."""
        self.external[pin] = None if level is None else (1 if level else 0)

    def mode(self, pin):
        return (self.instance.MODER >> (2 * pin)) & 3

    def driven(self, pin, odr=None):
        """The level the chip drives on `pin` (RM0383 8.3.10: ODR through the output driver when MODER is output;
        open drain (OTYPER) drives only the low), None when it drives nothing. `odr`: ODR as it is about to be."""
        if self.mode(pin) != OUTPUT:
            return None
        bit = ((self.instance.ODR if odr is None else odr) >> pin) & 1
        if (self.instance.OTYPER >> pin) & 1:
            return 0 if bit == 0 else None
        return bit

    def pull(self, pin):
        """1 for a pull-up, 0 for a pull-down, None for none (RM0383 8.4.4 GPIOx_PUPDR; 11 is reserved)."""
        return {1: 1, 2: 0}.get((self.instance.PUPDR >> (2 * pin)) & 3)

    def level(self, pin):
        """The pin's electrical level: the chip's output, else what drives it from outside, else its pull; None
        when it floats."""
        out = self.driven(pin)
        if out is not None:
            return out
        ext = self.external.get(pin)
        return ext if ext is not None else self.pull(pin)

    def idr(self):
        # RM0383 8.3 (I/O port control): IDR samples every pin, so an output reads back its level; an analog pin
        # reads 0 (8.3.12: the Schmitt trigger is off)
        value = 0
        for pin in range(16):
            if self.mode(pin) == ANALOG:
                continue
            level = self.level(pin)
            if level is None:
                if pin in self.wired:
                    self.floating_reads[pin] += 1
                continue  # floating: read as 0 here, counted as a fault
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
