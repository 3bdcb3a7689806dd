"""DMA1/DMA2 controllers (RM0383 section 9): eight streams each, transfers paced by peripheral requests,
circular mode, half-transfer and transfer-complete flags and interrupts.

Qiling's STM32F4xxDma moves a whole block at once without waiting for requests, has no circular reload and no
half-transfer flag, and indexes stream 4 wrongly. Here a stream moves one data item per request of the channel
its CR.CHSEL selects (RM0383 9.3.3, the DMA1/DMA2 request mapping tables); `request(stream, channel, n)` is called by the requesting
peripheral model. Not modelled: memory-to-memory, double-buffer mode (CR.DBM), the FIFO's threshold behaviour
(direct and FIFO mode move the same data here), bursts, priorities between streams, error flags.
"""

import struct

from .base import Block

# RM0383 9.5.5 DMA_SxCR
EN, DMEIE, TEIE, HTIE, TCIE = 1 << 0, 1 << 1, 1 << 2, 1 << 3, 1 << 4
CIRC, PINC, MINC = 1 << 8, 1 << 9, 1 << 10
# RM0383 9.5.1-9.5.4: per-stream flag bits (FEIF 0, DMEIF 2, TEIF 3, HTIF 4, TCIF 5), shifted per stream
FEIF, DMEIF, TEIF, HTIF, TCIF = 1 << 0, 1 << 2, 1 << 3, 1 << 4, 1 << 5
FLAG_SHIFT = [0, 6, 16, 22]
SIZES = [1, 2, 4, 4]  # PSIZE/MSIZE encodings 00, 01, 10 (11 is reserved)


class Stream:
    def __init__(self):
        self.cr = 0
        self.ndtr = 0
        self.par = self.m0ar = self.m1ar = 0
        self.fcr = 0x21  # RM0383 9.5.10: reset value (FIFO empty, direct mode)
        self.flags = 0
        self.reload = 0  # NDTR when the stream was enabled: circular mode reloads it (RM0383 9.3, circular mode)
        self.done = 0  # items moved in the current cycle
        self.items = 0  # items moved since reset

    @property
    def channel(self):
        return (self.cr >> 25) & 7


class Dma(Block):
    LISR, HISR, LIFCR, HIFCR = 0x00, 0x04, 0x08, 0x0C

    def __init__(self, name, bus, pend, irqs):
        """`bus.read_words(addr, n)` / `bus.write_words(addr, words)` (same address, PINC = 0) and
        `bus.read(addr, size)` / `bus.write(addr, size, value)`; `irqs`: the NVIC line of each stream
        (DMA1: 11-17, 47; DMA2: 56-60, 68-70, RM0383 10.2, vector table)."""
        self.name, self.bus, self.pend, self.irqs = name, bus, pend, irqs
        self.on_enable = []  # called with a stream's number when it is enabled (a request already held is served)
        self.reset()

    def reset(self):
        self.streams = [Stream() for _ in range(8)]

    # -- requests --
    def request(self, s, channel, n):
        """`n` requests on stream `s` from a peripheral wired to `channel`."""
        st = self.streams[s]
        if not st.cr & EN or st.channel != channel:
            return  # RM0383 9.3.3: only the selected channel's requests reach the stream
        while n > 0 and st.cr & EN:
            half = st.reload // 2
            k = min(n, st.ndtr)
            if st.cr & HTIE and st.done < half:
                k = min(k, half - st.done)  # stop at the half-transfer point to flag it
            self._move(st, k)
            n -= k
            st.done += k
            st.items += k
            st.ndtr -= k
            if st.done >= half and st.done - k < half:
                st.flags |= HTIF  # RM0383 9.3, interrupts: half of the data items transferred
            if st.ndtr == 0:
                st.flags |= TCIF  # RM0383 9.3, interrupts: NDTR reached 0
                if st.cr & CIRC:
                    st.ndtr, st.done = st.reload, 0  # RM0383 9.3, circular mode: NDTR reloaded
                else:
                    st.cr &= ~EN  # RM0383 9.3, stream configuration: the stream is disabled at the end of the transfer
        self._irq(s)

    def horizon(self, s):
        """Requests until stream `s` sets a flag whose interrupt is enabled, or None."""
        st = self.streams[s]
        if not st.cr & EN:
            return None
        best = None
        if st.cr & TCIE:
            best = st.ndtr
        half = st.reload // 2
        if st.cr & HTIE:
            h = half - st.done if st.done < half else st.ndtr + half
            best = h if best is None else min(best, h)
        return best

    def _move(self, st, k):
        direction = (st.cr >> 6) & 3
        psize, msize = SIZES[(st.cr >> 11) & 3], SIZES[(st.cr >> 13) & 3]
        maddr = st.m0ar + (st.done * msize if st.cr & MINC else 0)
        if direction == 1 and psize == msize == 4 and st.cr & MINC and not st.cr & PINC:
            # memory to peripheral, words: the step generator's case, done in bulk
            self.bus.write_words(st.par, self.bus.read_words(maddr, k))
            return
        for i in range(k):
            paddr = st.par + ((st.done + i) * psize if st.cr & PINC else 0)
            m = maddr + (i * msize if st.cr & MINC else 0)
            if direction == 1:
                self.bus.write(paddr, psize, self.bus.read(m, msize))
            elif direction == 0:
                self.bus.write(m, msize, self.bus.read(paddr, psize))

    def _irq(self, s):
        st = self.streams[s]
        enabled = (TCIF if st.cr & TCIE else 0) | (HTIF if st.cr & HTIE else 0) | (TEIF if st.cr & TEIE else 0)
        if st.flags & enabled:
            self.pend(self.irqs[s])

    # -- registers --
    def read32(self, off):
        if off in (self.LISR, self.HISR):
            base = 0 if off == self.LISR else 4
            return sum(self.streams[base + i].flags << FLAG_SHIFT[i] for i in range(4))
        if off < 0x10 or off >= 0x10 + 8 * 0x18:
            return 0  # LIFCR/HIFCR read 0 (RM0383 9.5.3-9.5.4)
        st, reg = self.streams[(off - 0x10) // 0x18], (off - 0x10) % 0x18
        return [st.cr, st.ndtr, st.par, st.m0ar, st.m1ar, st.fcr][reg // 4]

    def write32(self, off, value):
        if off in (self.LIFCR, self.HIFCR):
            # RM0383 9.5.3-9.5.4: writing 1 clears the corresponding flag
            base = 0 if off == self.LIFCR else 4
            for i in range(4):
                self.streams[base + i].flags &= ~((value >> FLAG_SHIFT[i]) & 0x3D)
            return
        if off < 0x10 or off >= 0x10 + 8 * 0x18:
            return
        s, reg = (off - 0x10) // 0x18, (off - 0x10) % 0x18
        st = self.streams[s]
        if reg == 0:
            if st.cr & EN:
                if not value & EN:
                    # RM0383 9.3, stream configuration: disabling a stream mid-transfer ends it and sets TCIF
                    st.cr &= ~EN
                    st.flags |= TCIF
                    self._irq(s)
                return  # RM0383 9.5.5: the other bits are read-only while EN = 1
            st.cr = value & 0x0FEFFFFF
            if value & EN:
                if st.ndtr == 0:
                    st.cr &= ~EN  # RM0383 9.5.6: a stream with NDTR = 0 cannot be enabled
                else:
                    st.reload, st.done = st.ndtr, 0
            self._irq(s)
            if st.cr & EN:
                for listener in self.on_enable:
                    listener(s)
        elif st.cr & EN:
            return  # RM0383 9.5.6-9.5.9: NDTR, PAR, M0AR are writable only while the stream is disabled
        elif reg == 4:
            st.ndtr = value & 0xFFFF
        elif reg == 8:
            st.par = value
        elif reg == 12:
            st.m0ar = value
        elif reg == 16:
            st.m1ar = value
        elif reg == 20:
            st.fcr = (st.fcr & 0x38) | (value & 0x87)  # FS (bits 5:3) is read only


class RequestLine:
    """A peripheral's request line into one DMA stream (RM0383 9.3.3): a timer's update or compare, a USART's."""

    def __init__(self, dma, stream, channel):
        self.dma, self.stream, self.channel = dma, stream, channel

    def __call__(self, n):
        self.dma.request(self.stream, self.channel, n)

    def active(self):
        """Whether the stream is enabled and selects this line's channel: a request now moves an item."""
        st = self.dma.streams[self.stream]
        return bool(st.cr & EN) and st.channel == self.channel

    def horizon(self):
        st = self.dma.streams[self.stream]
        return self.dma.horizon(self.stream) if st.channel == self.channel else None


def unpack_words(data):
    return list(struct.unpack(f"<{len(data) // 4}I", data))
