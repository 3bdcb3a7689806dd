"""USB OTG FS stub (RM0383 section 22.16): enough for embassy's driver to initialise the core and then wait
for a host that never comes, as a board on a charger-only cable would.

Qiling's profile does not map 0x5000_0000 at all; as plain memory the driver spins on GRSTCTL.AHBIDL. No USB
traffic is modelled: the link over USB is for the first board (tests/rehost/README.md).
"""

from .base import Block

# RM0383 22.16, OTG_FS_GRSTCTL
CSRST, RXFFLSH, TXFFLSH, AHBIDL = 1 << 0, 1 << 4, 1 << 5, 1 << 31
SELF_CLEARING = CSRST | RXFFLSH | TXFFLSH | (1 << 2)  # core soft reset, FIFO flushes, HCLK soft reset
# RM0383 22.16, OTG_FS_GINTSTS: bits the core sets, cleared by writing 1 (rc_w1)
GINTSTS_RC_W1 = 0xF030_FC0A


class OtgFs(Block):
    GRSTCTL, GINTSTS, CID = 0x010, 0x014, 0x03C
    size = 0x40000  # registers and the FIFO windows (0x1000-0x20000)

    def __init__(self):
        self.regs = {}
        self.accesses = 0

    def read32(self, off):
        self.accesses += 1
        if off == self.GRSTCTL:
            # the AHB master is idle and every reset or flush completes at once
            return (self.regs.get(off, 0) & ~SELF_CLEARING) | AHBIDL
        if off == self.GINTSTS:
            # CMOD (bit 0) = 0: device mode; no host: no reset, enumeration or traffic is ever flagged
            return self.regs.get(off, 0) & ~1
        if off == self.CID:
            return self.regs.get(off, 0x0000_1200)  # RM0383 22.16, OTG_FS_CID: a product ID, not checked
        return self.regs.get(off, 0)

    def write32(self, off, value):
        self.accesses += 1
        if off == self.GINTSTS:
            self.regs[off] = self.regs.get(off, 0) & ~(value & GINTSTS_RC_W1)
        elif off == self.GRSTCTL:
            self.regs[off] = value & ~SELF_CLEARING
        else:
            self.regs[off] = value
