"""A USART in asynchronous mode, 8N1 or 9 data bits, no flow control (RM0383 section 19).

Qiling's USART model moves bytes at once and raises no interrupts by the register flags; this one keeps the line's
timing: a frame takes (1 start + M data + STOP stop) bit times of BRR peripheral-clock cycles each (19.3.4
oversampling by 16, OVER8 = 0), bytes from the host arrive one frame after another, and the interrupt line follows
the flags and their enable bits (19.4 USART interrupts). Everything the firmware sends is handed to `on_tx`.
With CR3.DMAT or DMAR (19.3.13, continuous communication using DMA), TXE and RXNE request DMA transfers on the
request lines `tx_dma` and `rx_dma` (the machine wires them to DMA2's streams, RM0383 9.3.3 table 28) while they
hold and the stream is enabled; the receiver's bytes are then taken even while the CPU is stalled.
"""

from models.base import NEVER, Block

# 19.6.1 USART_SR
PE, FE, NF, ORE, IDLE, RXNE, TC, TXE = (1 << i for i in range(8))
# 19.6.4 USART_CR1
SBK, RWU, RE, TE, IDLEIE, RXNEIE, TCIE, TXEIE, PEIE, PS, PCE, WAKE, M, UE, OVER8 = (1 << i for i in range(16) if i != 14)
# 19.6.6 USART_CR3
EIE, DMAR, DMAT = 1 << 0, 1 << 6, 1 << 7
SR, DR, BRR, CR1, CR2, CR3, GTPR = 0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18


class Usart(Block):
    def __init__(self, label, clock, pend, irq, cycles_per_pclk=1):
        self.label, self.clock, self.pend, self.irq = label, clock, pend, irq
        self.cycles_per_pclk = cycles_per_pclk  # CPU cycles per peripheral clock cycle (APB prescaler)
        self.on_tx = None  # called with each byte when its stop bit has gone out
        self.tx_dma = self.rx_dma = ()  # DMA request lines: callables `line(n)` with `line.active()`
        self.serving_dma = False
        self.reset()

    def reset(self):
        """19.6: the reset values; bytes still on their way from the host are dropped (the line is not listened to)."""
        self.sr = TXE | TC  # 19.6.1: reset value 0x00C0
        self.cr1 = self.cr2 = self.cr3 = self.brr = self.gtpr = 0
        self.rdr = 0
        self.rx_wire = bytearray()  # bytes the host has sent that are not yet received
        self.rx_at = NEVER  # when the next of them is complete (its stop bit sampled)
        self.idle_at = NEVER  # when a line idle for one frame sets IDLE
        self.idle_armed = False  # 19.6.1 IDLE: set again only after RXNE has been set
        self.tdr = None  # the byte in the transmit data register
        self.shift = None  # the byte in the transmit shift register
        self.tx_at = NEVER  # when it has gone out
        self.sr_seen = 0  # the SR flags the last SR read saw (the clearing sequences of 19.6.1)
        self.received = self.sent = self.overruns = 0

    # -- the line --
    def frame_cycles(self):
        bits = 1 + (9 if self.cr1 & M else 8) + (2 if (self.cr2 >> 12) & 3 == 2 else 1)
        if self.cr1 & OVER8:
            div = (self.brr & 0xFFF0) * 2 + (self.brr & 7) * 2  # 19.3.4: OVER8 = 1 keeps DIV_Fraction[2:0]
            div = div // 2 or 1
        else:
            div = self.brr or 1
        return bits * div * self.cycles_per_pclk

    def baud(self, pclk):
        return pclk / max(1, self.brr)

    def feed(self, data):
        """Bytes the host put on the RX line, sent back to back from now (after any still on their way)."""
        if not data:
            return
        if not self.rx_wire:
            self.rx_at = self.clock() + self.frame_cycles()
        self.rx_wire += data

    def level(self):
        """19.4: the interrupt request, from the event flags and their enable bits."""
        sr, cr1 = self.sr, self.cr1
        return bool((sr & TXE and cr1 & TXEIE) or (sr & TC and cr1 & TCIE) or (sr & (RXNE | ORE) and cr1 & RXNEIE)
                    or (sr & IDLE and cr1 & IDLEIE) or (sr & PE and cr1 & PEIE)
                    # 19.4: noise, overrun and framing errors interrupt through EIE, which is used with DMAR only
                    or (sr & (NF | ORE | FE) and self.cr3 & EIE and self.cr3 & DMAR))

    def serve_dma(self):
        """19.3.13: a DMA request while TXE (DMAT) or RXNE (DMAR) holds; each transfer writes or reads DR, which
        clears the flag. Called whenever a flag, an enable bit or a stream's enable changes."""
        if self.serving_dma:
            return  # the transfer's own DR access comes back here
        self.serving_dma = True
        try:
            moved = True
            while moved:
                moved = False
                for flag, bit, lines in ((TXE, DMAT, self.tx_dma), (RXNE, DMAR, self.rx_dma)):
                    if self.sr & flag and self.cr3 & bit and self.cr1 & UE:
                        for line in lines:
                            if line.active():
                                line(1)
                                moved = True
                                break
        finally:
            self.serving_dma = False

    def _raise(self):
        if self.level():
            self.pend(self.irq)

    # -- registers --
    def write(self, offset, size, value):
        if offset in (SR, DR):  # a byte write of DR or SR is that register's write, with no read of it first
            self.write32(offset, value)
        else:
            super().write(offset, size, value)

    def read32(self, offset):
        if offset == SR:
            self.sr_seen = self.sr
            return self.sr
        if offset == DR:
            # 19.6.1: a DR read clears RXNE; after an SR read it also clears IDLE, ORE, NF, FE and PE
            self.sr &= ~(RXNE | (self.sr_seen & (IDLE | ORE | NF | FE | PE)))
            self.sr_seen = 0
            return self.rdr
        return {BRR: self.brr, CR1: self.cr1, CR2: self.cr2, CR3: self.cr3, GTPR: self.gtpr}.get(offset, 0)

    def write32(self, offset, value):
        if offset == SR:
            # 19.6.1: RXNE and TC are rc_w0 (written 0 clears, 1 keeps); the other flags are read only
            self.sr &= value | ~(RXNE | TC)
        elif offset == DR:
            # 19.6.1 TC: cleared by an SR read followed by a DR write; 19.3.2: the byte goes to TDR
            if self.sr_seen & TC:
                self.sr &= ~TC
            self.sr_seen = 0
            if self.cr1 & UE and self.cr1 & TE:
                self.tdr = value & 0xFF
                self.sr &= ~TXE
                self._load_shift(self.clock())
        elif offset == BRR:
            self.brr = value & 0xFFFF
        elif offset == CR1:
            was = self.cr1
            self.cr1 = value & 0xBFFF
            if was & UE and not self.cr1 & UE:  # 19.6.4 UE: the prescalers and outputs stop at once
                self.tdr = self.shift = None
                self.tx_at = NEVER
                self.sr |= TXE
        elif offset == CR2:
            self.cr2 = value & 0x7F7F
        elif offset == CR3:
            self.cr3 = value & 0x0FFF
        elif offset == GTPR:
            self.gtpr = value & 0xFFFF
        self.serve_dma()
        self._raise()

    def _load_shift(self, now):
        """19.3.2: TDR moves to the shift register when it is empty; TXE says TDR is free again."""
        if self.shift is None and self.tdr is not None:
            self.shift, self.tdr = self.tdr, None
            self.sr |= TXE
            self.sr &= ~TC
            self.tx_at = now + self.frame_cycles()

    # -- time --
    def advance(self, now):
        while True:
            t = min(self.tx_at, self.rx_at, self.idle_at)
            if t > now:
                break
            if t == self.tx_at:
                byte, self.shift, self.tx_at = self.shift, None, NEVER
                self.sent += 1
                if self.on_tx:
                    self.on_tx(byte)
                self._load_shift(t)
                self.serve_dma()
                if self.shift is None:
                    self.sr |= TC  # 19.6.1 TC: the frame is out and TXE is set
            elif t == self.rx_at:
                byte = self.rx_wire.pop(0)
                self.rx_at = t + self.frame_cycles() if self.rx_wire else NEVER
                if not (self.cr1 & UE and self.cr1 & RE):
                    continue  # the receiver is off: the byte is not seen
                if self.sr & RXNE:
                    self.sr |= ORE  # 19.6.1 ORE: RDR keeps the unread byte, this one is lost
                    self.overruns += 1
                else:
                    self.rdr = byte
                    self.sr |= RXNE
                    self.received += 1
                self.idle_armed = True
                self.idle_at = NEVER if self.rx_wire else t + self.frame_cycles()
                self.serve_dma()
            else:
                self.idle_at = NEVER
                if self.idle_armed:
                    self.sr |= IDLE  # 19.6.1 IDLE: an idle frame after the last byte
                    self.idle_armed = False
        self._raise()

    def next_event(self, now):
        return min(self.tx_at, self.rx_at, self.idle_at)
