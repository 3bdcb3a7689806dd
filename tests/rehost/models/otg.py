"""USB OTG FS in device mode (RM0383 chapter 22): the core and device registers embassy's Synopsys OTG driver uses,
the shared receive FIFO and the per-endpoint transmit FIFOs through the FIFO windows, and the global interrupt
(OTG_FS, IRQ 67, RM0383 10.2). The bus side is a set of calls a host model makes (`usb_host.py`): attach, bus
reset and speed enumeration, SOF, suspend, and SETUP/OUT/IN transactions answered ACK, NAK, STALL or not at all.

Modelled (section numbers of RM0383):
- 22.16.1 GOTGCTL/GOTGINT (B-session valid from VBUS sensing, SEDET), GAHBCFG.GINT and TXFELVL, GUSBCFG (stored:
  FDMOD, PHYSEL, TRDT), GRSTCTL (core soft reset and FIFO flushes complete at once, AHBIDL), GINTSTS (rc_w1 bits;
  RXFLVL, IEPINT and OEPINT computed from the FIFO and the endpoint registers; CMOD 0), GINTMSK, GRXSTSR/GRXSTSP
  (status entries: OUT data, OUT done, SETUP data, SETUP done), GRXFSIZ, DIEPTXF0, DIEPTXFx, GCCFG (PWRDWN powers
  the transceiver; NOVBUSSENS, VBUSBSEN: VBUS sensing), CID 0x0000_1200.
- 22.16.3 DCFG (DSPD, DAD), DCTL (SDIS: the D+ pull-up), DSTS (SUSPSTS, ENUMSPD full speed, FNSOF), DIEPMSK,
  DOEPMSK, DAINT, DAINTMSK, DIEPEMPMSK; per endpoint 0-3 (22.4: four bidirectional endpoints) DIEPCTLx/DOEPCTLx
  (MPSIZ, USBAEP, NAKSTS by SNAK/CNAK, EPTYP, STALL, TXFNUM, EPDIS, EPENA), DIEPINTx/DOEPINTx (rc_w1; TXFE read
  only), DIEPTSIZx/DOEPTSIZx (XFRSIZ, PKTCNT, STUPCNT), DTXFSTSx (free words of the endpoint's TX FIFO).
- 22.11 (FIFO architecture): a read of any FIFO window pops the receive FIFO, a write to window n pushes into
  endpoint n's TX FIFO; the receive FIFO holds GRXFSIZ words, each TX FIFO its DIEPTXFx depth.
- 22.17.6 (device programming model): a SETUP is always accepted into the RX FIFO (STUPCNT counts down) and sets
  NAK on OUT endpoint 0; popping "SETUP done" raises DOEPINT0.STUP, popping "OUT transfer completed" raises XFRC.
  An OUT packet is accepted while the endpoint is active (endpoint 0 always), not stalled, not NAKing and the RX
  FIFO has room; the core then NAKs that endpoint until the application clears NAK (CNAK), PKTCNT counts down and
  at 0 (or on a short packet) the transfer completes (EPENA cleared). An IN token is answered from the TX FIFO once
  EPENA is set, NAK is clear and the FIFO holds the packet (XFRSIZ up to MPSIZ bytes); the last packet clears EPENA
  and raises XFRC. A USB reset clears USBAEP on endpoints 1-3 (DIEPCTLx/DOEPCTLx USBAEP).
- The clock: with RCC_AHB2ENR.OTGFSEN clear the block reads 0 and ignores writes (RM0383 6.3.10), so a driver
  never sees AHBIDL and the device never attaches.

Not modelled: host mode and the OTG protocols (SRP/HNP, ID pin, A-device), DATA0/DATA1 toggles and CRC or bit
errors (every packet arrives whole), isochronous endpoints and incomplete-isochronous interrupts, the OTG power
savings (PCGCCTL stored, no clock gating), remote wakeup signalling, the global IN/OUT NAK (SGINAK/SGONAK are stored
without effect), endpoint-disable handshakes beyond EPDISD at once, DMA (the F411's OTG FS has none), the
transceiver's electrical behaviour and SOF output, and the FIFO RAM layout (each FIFO is checked against its own
size, not against overlaps with the others).
"""

from collections import deque

from .base import Block

IRQ = 67  # RM0383 10.2: OTG_FS global interrupt
ENDPOINTS = 4
# 22.16.1 GRSTCTL
CSRST, HSRST, RXFFLSH, TXFFLSH, AHBIDL = 1 << 0, 1 << 1, 1 << 4, 1 << 5, 1 << 31
# 22.16.1 GINTSTS / GINTMSK
OTGINT, SOF, RXFLVL, ESUSP, USBSUSP, USBRST, ENUMDNE = 1 << 2, 1 << 3, 1 << 4, 1 << 10, 1 << 11, 1 << 12, 1 << 13
IEPINT, OEPINT, SRQINT, WKUPINT = 1 << 18, 1 << 19, 1 << 30, 1 << 31
GINTSTS_RC_W1 = 0xF030_FC0A
# 22.16.1 GCCFG
PWRDWN, VBUSASEN, VBUSBSEN, NOVBUSSENS = 1 << 16, 1 << 18, 1 << 19, 1 << 21
# 22.16.3 DxEPCTLx
USBAEP, NAKSTS, STALL, CNAK, SNAK, EPDIS, EPENA = 1 << 15, 1 << 17, 1 << 21, 1 << 26, 1 << 27, 1 << 30, 1 << 31
CTL_WRITE_ONLY = CNAK | SNAK | (1 << 28) | (1 << 29)
# 22.16.3 DIEPINTx / DOEPINTx
XFRC, EPDISD, STUP, TXFE = 1 << 0, 1 << 1, 1 << 3, 1 << 7
# 22.16.1 GRXSTSP PKTSTS (device mode)
OUT_DATA, OUT_DONE, SETUP_DONE, SETUP_DATA = 2, 3, 4, 6

GOTGCTL, GOTGINT, GAHBCFG, GUSBCFG, GRSTCTL, GINTSTS, GINTMSK = 0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18
GRXSTSR, GRXSTSP, GRXFSIZ, DIEPTXF0, GCCFG, CID = 0x1C, 0x20, 0x24, 0x28, 0x38, 0x3C
DCFG, DCTL, DSTS, DIEPMSK, DOEPMSK, DAINT, DAINTMSK, DIEPEMPMSK = 0x800, 0x804, 0x808, 0x810, 0x814, 0x818, 0x81C, 0x834
DIEPCTL, DIEPINT, DIEPTSIZ, DTXFSTS, DOEPCTL, DOEPINT, DOEPTSIZ = 0x900, 0x908, 0x910, 0x918, 0xB00, 0xB08, 0xB10
FIFO = 0x1000


class OtgFs(Block):
    GRSTCTL, GINTSTS, CID = GRSTCTL, GINTSTS, CID
    size = FIFO * (ENDPOINTS + 1)  # registers, then one 4 KB window per endpoint's FIFO (22.16, Table 128)

    def __init__(self, pend=lambda irq: None, clocked=lambda: True, vbus_on_pa9=False):
        self.pend, self.clocked = pend, clocked
        self.vbus_on_pa9 = vbus_on_pa9  # the board wires VBUS to PA9 (the Black Pill does not)
        self.vbus = False  # a host's 5 V on the cable
        self.accesses = 0
        self.reset()

    def reset(self):
        """The reset values (22.16); the cable and its VBUS stay as they are."""
        self.regs = {CID: 0x0000_1200, GRXFSIZ: 0x200, DCTL: 0}
        self.gintsts = 0x0400_0020  # 22.16.1: the reset value (NPTXFE, PTXFE: host mode's)
        self.gotgint = 0
        self.rx = deque()  # (status word, data) entries
        self.rx_data = deque()  # the words of the popped entry, read through a FIFO window
        self.tx = [bytearray() for _ in range(ENDPOINTS)]
        self.inctl = [0] * ENDPOINTS
        self.outctl = [0] * ENDPOINTS
        self.inint = [0] * ENDPOINTS
        self.outint = [0] * ENDPOINTS
        self.intsiz = [0] * ENDPOINTS
        self.outsiz = [0] * ENDPOINTS
        self.fnsof = 0
        self.suspended = False
        self.enum_speed = 0
        self.address = 0  # the address the core answers to: DCFG.DAD once a control transfer's status stage is done

    # -- the bus side (a host model calls these) --
    def session_valid(self):
        """22.4 / 22.16.1 GCCFG: with NOVBUSSENS the B-session is always valid; with VBUSBSEN it follows VBUS on PA9."""
        g = self.regs.get(GCCFG, 0)
        return bool(g & NOVBUSSENS or (g & VBUSBSEN and self.vbus and self.vbus_on_pa9))

    def attached(self):
        """The D+ pull-up is on: clocked, transceiver powered (PWRDWN), not soft-disconnected, session valid."""
        return (self.clocked() and bool(self.regs.get(GCCFG, 0) & PWRDWN) and not self.regs.get(DCTL, 0) & 2
                and self.vbus and self.session_valid())

    def bus_reset(self):
        """USB reset signalling seen (22.17.5): USBRST; USBAEP cleared on endpoints 1-3; the suspend ends."""
        self.gintsts |= USBRST
        for n in range(1, ENDPOINTS):
            self.inctl[n] &= ~(USBAEP | EPENA)
            self.outctl[n] &= ~(USBAEP | EPENA)
        self.suspended = False
        self.address = 0
        self._irq()

    def enumerated(self):
        """The reset ended: ENUMDNE, DSTS.ENUMSPD 3 (full speed, 48 MHz PHY clock)."""
        self.enum_speed = 3
        self.gintsts |= ENUMDNE
        self._irq()

    def sof(self):
        self.fnsof = (self.fnsof + 1) & 0x3FFF
        self.gintsts |= SOF
        if self.suspended:
            self.suspended = False
            self.gintsts |= WKUPINT
        self._irq()

    def suspend(self):
        """3 ms of an idle bus (22.17.7): early suspend, then suspend."""
        if not self.suspended:
            self.suspended = True
            self.gintsts |= ESUSP | USBSUSP
            self._irq()

    def _addressed(self, addr):
        return self.attached() and addr == self.address

    def setup(self, addr, packet):
        """A SETUP to endpoint 0: None (no answer) or "ACK"."""
        if not self._addressed(addr) or self._rx_free() < 4:
            return None
        self.rx.append((SETUP_DATA << 17 | 8 << 4, bytes(packet)))
        self.rx.append((SETUP_DONE << 17, b""))
        stup = (self.outsiz[0] >> 29) & 3
        self.outsiz[0] = (self.outsiz[0] & ~(3 << 29)) | (max(stup - 1, 0) << 29)
        self.outctl[0] = (self.outctl[0] | NAKSTS) & ~STALL
        self.inctl[0] &= ~STALL
        self._irq()
        return "ACK"

    def out(self, addr, ep, data):
        """An OUT packet: None, "ACK", "NAK" or "STALL"."""
        if not self._addressed(addr) or ep >= ENDPOINTS:
            return None
        ctl = self.outctl[ep]
        if ep and not ctl & USBAEP:
            return None
        if ctl & STALL:
            return "STALL"
        if ctl & NAKSTS or self._rx_free() < 1 + (len(data) + 3) // 4:
            return "NAK"
        self.rx.append((OUT_DATA << 17 | len(data) << 4 | ep, bytes(data)))
        siz = self.outsiz[ep]
        pkts = (siz >> 19) & (1 if ep == 0 else 0x3FF)
        xfr = max((siz & 0x7FFFF) - len(data), 0)
        pkts = max(pkts - 1, 0)
        self.outsiz[ep] = (siz & ~(0x3FF << 19 | 0x7FFFF)) | pkts << 19 | xfr
        if pkts == 0 or len(data) < self._mps(ep, out=True):
            self.rx.append((OUT_DONE << 17 | ep, b""))
        self.outctl[ep] |= NAKSTS
        self._irq()
        return "ACK"

    def in_(self, addr, ep):
        """An IN token: None, "NAK", "STALL" or the packet's bytes."""
        if not self._addressed(addr) or ep >= ENDPOINTS:
            return None
        ctl = self.inctl[ep]
        if ep and not ctl & USBAEP:
            return None
        if ctl & STALL:
            return "STALL"
        if not ctl & EPENA or ctl & NAKSTS:
            return "NAK"
        siz = self.intsiz[ep]
        n = min(siz & 0x7FFFF, self._mps(ep))
        if len(self.tx[ep]) < n:
            return "NAK"  # the application has not written the whole packet yet
        data = bytes(self.tx[ep][:n])
        del self.tx[ep][:(n + 3) // 4 * 4]
        pkts = max(((siz >> 19) & 0x3FF) - 1, 0)
        self.intsiz[ep] = (siz & ~(0x3FF << 19 | 0x7FFFF)) | pkts << 19 | ((siz & 0x7FFFF) - n)
        if pkts == 0:
            self.inctl[ep] &= ~EPENA
            self.inint[ep] |= XFRC
            if ep == 0:
                # USB 2.0 9.4.6: SET_ADDRESS takes effect after its status stage; the driver writes DAD before it
                self.address = (self.regs.get(DCFG, 0) >> 4) & 0x7F
        self._irq()
        return data

    # -- helpers --
    def _mps(self, ep, out=False):
        ctl = self.outctl[ep] if out else self.inctl[ep]
        if ep == 0:
            return (64, 32, 16, 8)[ctl & 3]
        return ctl & 0x7FF

    def _rx_free(self):
        used = sum(1 + (len(d) + 3) // 4 for _, d in self.rx) + len(self.rx_data)
        return (self.regs.get(GRXFSIZ, 0) & 0xFFFF) - used

    def _tx_depth(self, ep):
        reg = DIEPTXF0 if ep == 0 else 0x104 + 4 * (ep - 1)
        return self.regs.get(reg, 0) >> 16

    def _txfe(self, ep):
        # GAHBCFG.TXFELVL: 0 = half empty, 1 = completely empty
        used = (len(self.tx[ep]) + 3) // 4
        return used == 0 or (not self.regs.get(GAHBCFG, 0) & 0x80 and used * 2 <= self._tx_depth(ep))

    def daint(self):
        inmask, outmask = self.regs.get(DIEPMSK, 0), self.regs.get(DOEPMSK, 0)
        empmask = self.regs.get(DIEPEMPMSK, 0)
        bits = 0
        for n in range(ENDPOINTS):
            txfe = TXFE if empmask >> n & 1 and self._txfe(n) else 0
            if self.inint[n] & inmask or txfe:
                bits |= 1 << n
            if self.outint[n] & outmask:
                bits |= 1 << (16 + n)
        return bits

    def _gintsts(self):
        value = self.gintsts & ~(RXFLVL | IEPINT | OEPINT | OTGINT)
        if self.rx:
            value |= RXFLVL
        daint = self.daint() & self.regs.get(DAINTMSK, 0)
        if daint & 0xFFFF:
            value |= IEPINT
        if daint >> 16:
            value |= OEPINT
        if self.gotgint:
            value |= OTGINT
        return value

    def level(self):
        return bool(self.regs.get(GAHBCFG, 0) & 1 and self._gintsts() & self.regs.get(GINTMSK, 0))

    def _irq(self):
        if self.level():
            self.pend(IRQ)

    # -- registers --
    def read32(self, off):
        self.accesses += 1
        if not self.clocked():
            return 0
        value = self._read(off)
        self._irq()
        return value

    def _read(self, off):
        if off >= FIFO:
            return self._pop_word()
        if off < 0x800:
            if off == GRSTCTL:
                return (self.regs.get(off, 0) & ~(CSRST | HSRST | RXFFLSH | TXFFLSH)) | AHBIDL
            if off == GINTSTS:
                return self._gintsts()
            if off == GOTGCTL:
                return self.regs.get(off, 0) | (1 << 16) | ((1 << 19) if self.session_valid() else 0)
            if off == GOTGINT:
                return self.gotgint
            if off in (GRXSTSR, GRXSTSP):
                if not self.rx:
                    return 0
                status, data = self.rx.popleft() if off == GRXSTSP else self.rx[0]
                if off == GRXSTSP:
                    self._popped(status, data)
                return status
            return self.regs.get(off, 0)
        if off == DSTS:
            return int(self.suspended) | self.enum_speed << 1 | self.fnsof << 8
        if off == DAINT:
            return self.daint()
        if DIEPCTL <= off < DOEPCTL + 0x20 * ENDPOINTS:
            ep, reg = ((off - DIEPCTL) % 0x200) // 0x20, off & 0x1F
            out = off >= DOEPCTL
            if reg == 0x00:
                ctl = (self.outctl if out else self.inctl)[ep]
                return ctl | (USBAEP if ep == 0 else 0)
            if reg == 0x08:
                if out:
                    return self.outint[ep]
                return self.inint[ep] | (TXFE if self._txfe(ep) else 0)
            if reg == 0x10:
                return (self.outsiz if out else self.intsiz)[ep]
            if reg == 0x18 and not out:
                return max(self._tx_depth(ep) - (len(self.tx[ep]) + 3) // 4, 0)
            return 0
        return self.regs.get(off, 0)

    def _popped(self, status, data):
        """22.11: the popped entry's data words follow through the FIFO window; the "done" entries interrupt."""
        ep, kind = status & 0xF, (status >> 17) & 0xF
        self.rx_data.extend(int.from_bytes(data[i:i + 4].ljust(4, b"\0"), "little") for i in range(0, len(data), 4))
        if kind == SETUP_DONE:
            self.outint[ep] |= STUP
        elif kind == OUT_DONE:
            self.outint[ep] |= XFRC
            self.outctl[ep] &= ~EPENA

    def _pop_word(self):
        return self.rx_data.popleft() if self.rx_data else 0

    def write32(self, off, value):
        self.accesses += 1
        if not self.clocked():
            return
        self._write(off, value)
        self._irq()

    def _write(self, off, value):
        if off >= FIFO:
            ep = off // FIFO - 1
            if (len(self.tx[ep]) + 4) // 4 <= self._tx_depth(ep):
                self.tx[ep] += value.to_bytes(4, "little")
            return
        if off == GINTSTS:
            self.gintsts &= ~(value & GINTSTS_RC_W1)
        elif off == GOTGINT:
            self.gotgint &= ~value
        elif off == GRSTCTL:
            if value & CSRST:
                keep = self.regs.get(GCCFG, 0), self.regs.get(GUSBCFG, 0)
                self.gintsts = 0
                self.regs[GCCFG], self.regs[GUSBCFG] = keep  # 22.16.1 CSRST: the core, not the configuration
            if value & RXFFLSH:
                self.rx.clear()
                self.rx_data.clear()
            if value & TXFFLSH:
                num = (value >> 6) & 0x1F
                for ep in range(ENDPOINTS) if num == 0x10 else [num] if num < ENDPOINTS else []:
                    self.tx[ep].clear()
            self.regs[off] = value & ~(CSRST | HSRST | RXFFLSH | TXFFLSH)
        elif DIEPCTL <= off < DOEPCTL + 0x20 * ENDPOINTS and off < 0xE00:
            self._endpoint_write(((off - DIEPCTL) % 0x200) // 0x20, off >= DOEPCTL, off & 0x1F, value)
        elif off not in (DSTS, DAINT, GRXSTSR, GRXSTSP, CID):
            self.regs[off] = value

    def _endpoint_write(self, ep, out, reg, value):
        if reg == 0x00:
            ctls = self.outctl if out else self.inctl
            old = ctls[ep]
            ctl = value & ~(CTL_WRITE_ONLY | NAKSTS) | (old & NAKSTS)
            if value & SNAK:
                ctl |= NAKSTS
            if value & CNAK:
                ctl &= ~NAKSTS
            if value & EPDIS and old & EPENA:
                ctl &= ~(EPENA | EPDIS)  # the endpoint disables at once
                (self.outint if out else self.inint)[ep] |= EPDISD
            elif not old & EPENA:
                ctl &= ~EPDIS
            if ep == 0:
                ctl = ctl & ~0x7FF | (value & 3)
            ctls[ep] = ctl
        elif reg == 0x08:
            ints = self.outint if out else self.inint
            ints[ep] &= ~value
        elif reg == 0x10:
            (self.outsiz if out else self.intsiz)[ep] = value
