"""Flash memory and its interface (RM0383 section 3): erased cells read 0xFF, and the FLASH registers (ACR,
KEYR, SR, CR) unlock, erase sectors and program, so that what the firmware stores can be seen where it lands.

Qiling's profile maps flash as RAM filled with 0x00 (an empty settings area then looks like written records) and
its FLASH interface only stores register values. The harness fills flash with 0xFF before loading the ELF and
routes every CPU store into flash through `cpu_write`.

A sector erase takes time: BSY reads 1 until `busy_until`, and the machine stalls the CPU until then (RM0383 3.5:
a read of the flash while it is being erased stalls the bus; the firmware's code and vector table are in flash, so
nothing runs, not even an interrupt handler). The time is the STM32F411xC/E datasheet's (DS10314, flash memory
programming characteristics) maximum for a 128 KiB sector at x32 parallelism, 2 s; 16 and 64 KiB sectors take a
proportional share (not the datasheet's figures: the firmware only erases the 128 KiB sectors 6-7). Programming a
word is instant here (16 us typical in that table).
"""

from .base import Block

FLASH_BASE = 0x0800_0000
# RM0383 3.3 (flash module organisation): sectors 0-3 of 16 KiB, 4 of 64 KiB, 5-7 of 128 KiB (512 KiB, STM32F411xE)
SECTORS = [(0x0000, 0x4000), (0x4000, 0x4000), (0x8000, 0x4000), (0xC000, 0x4000), (0x10000, 0x10000)] + [
    (0x20000 * i, 0x20000) for i in (1, 2, 3)
]
FLASH_SIZE = 0x80000
ERASE_128K_S = 2.0  # DS10314, t_ERASE128KB at x32 parallelism: 1 s typical, 2 s maximum
KEY1, KEY2 = 0x4567_0123, 0xCDEF_89AB  # RM0383 3.5.1, FLASH_KEYR: unlock sequence
# RM0383 ch. 3 registers, FLASH_CR
PG, SER, MER, STRT, LOCK = 1 << 0, 1 << 1, 1 << 2, 1 << 16, 1 << 31
# RM0383 ch. 3 registers, FLASH_SR
EOP, OPERR, WRPERR, PGAERR, PGPERR, PGSERR, BSY = 1, 2, 1 << 4, 1 << 5, 1 << 6, 1 << 7, 1 << 16


def sector_of(addr):
    off = addr - FLASH_BASE
    for n, (start, size) in enumerate(SECTORS):
        if start <= off < start + size:
            return n
    return None


class FlashInterface(Block):
    ACR, KEYR, OPTKEYR, SR, CR, OPTCR = 0x00, 0x04, 0x08, 0x0C, 0x10, 0x14

    def __init__(self, memory, clock=lambda: 0, cycles_per_s=96_000_000):
        """`memory.write(addr, data)` reaches the flash array; `clock()` is the time in CPU cycles."""
        self.memory, self.clock = memory, clock
        self.erase_cycles_per_byte = ERASE_128K_S * cycles_per_s / 0x20000
        self.busy_from = self.busy_until = 0  # the last erase's start and end (cycles)
        self.acr = 0
        self.sr = 0
        self.cr = LOCK  # RM0383 FLASH_CR: resets locked (0x8000_0000)
        self.optcr = 0x0FFF_AAED  # RM0383 FLASH_OPTCR reset value
        self.key_step = 0
        self.key_error = False
        self.erases = []  # sector numbers erased
        self.programs = []  # (address, size) of each programmed access
        self.rejected = []  # (address, size, why) of stores that did not program

    def read32(self, off):
        if off == self.ACR:
            return self.acr
        if off == self.SR:
            return self.sr | (BSY if self.clock() < self.busy_until else 0)
        if off == self.CR:
            return self.cr
        if off == self.OPTCR:
            return self.optcr
        return 0  # the key registers are write only

    def write32(self, off, value):
        if off == self.ACR:
            self.acr = value & 0x1F0F  # LATENCY (3:0), PRFTEN, ICEN, DCEN, ICRST, DCRST (RM0383 3.4, FLASH_ACR)
        elif off == self.KEYR:
            # RM0383 3.5.1: KEY1 then KEY2 clears LOCK; a wrong sequence locks the interface until reset
            if self.key_error or not self.cr & LOCK:
                self.key_error = True
            elif self.key_step == 0 and value == KEY1:
                self.key_step = 1
            elif self.key_step == 1 and value == KEY2:
                self.cr &= ~LOCK
                self.key_step = 0
            else:
                self.key_error = True
        elif off == self.SR:
            self.sr &= ~(value & (EOP | OPERR | WRPERR | PGAERR | PGPERR | PGSERR))  # rc_w1 (FLASH_SR)
        elif off == self.CR:
            if self.cr & LOCK:
                return  # RM0383 3.5.1 / FLASH_CR: CR cannot be written while locked
            self.cr = value & 0x8301_03FF
            if value & STRT and value & SER:
                self._erase((value >> 3) & 0xF)
            elif value & STRT and value & MER:
                for n in range(len(SECTORS)):
                    self._erase(n)
            self.cr &= ~STRT
        elif off == self.OPTCR:
            pass  # option bytes are not modelled

    def _erase(self, n):
        # RM0383 3.5.3 sector erase: every cell of the sector reads 0xFF afterwards
        if n >= len(SECTORS):
            self.sr |= PGSERR
            return
        start, size = SECTORS[n]
        self.memory.write(FLASH_BASE + start, b"\xff" * size)
        self.erases.append(n)
        self.busy_from = self.clock()
        self.busy_until = self.busy_from + int(size * self.erase_cycles_per_byte)
        self.sr |= EOP

    def cpu_write(self, addr, size, value, old):
        """A CPU store of `size` bytes into flash, whose previous content was `old` (bytes). Returns the bytes the
        array holds afterwards: programming only clears bits (RM0383 3.5.4), and without CR.PG nothing changes
        and PGSERR is set (FLASH_SR)."""
        if self.cr & LOCK or not self.cr & PG:
            self.sr |= PGSERR
            self.rejected.append((addr, size, "locked" if self.cr & LOCK else "PG not set"))
            return old
        new = bytes(o & v for o, v in zip(old, value.to_bytes(size, "little")))
        self.programs.append((addr, size))
        self.sr |= EOP
        return new
