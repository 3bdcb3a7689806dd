"""The release ELF on Qiling's stm32f411 profile, with the harness's models and its own CPU scheduler.

Qiling provides the memory map, the ELF loader, Unicorn, and its models of RCC, PWR, SCB, GPIO, EXTI, SYSCFG and
DBGMCU. The harness replaces NVIC, TIMx, DMAx and the FLASH interface, adds IWDG, DWT and the OTG FS
device core (`models/`), and runs the CPU itself instead of `ql.run()`:

- Time is counted in CPU cycles, one per instruction, at the 96 MHz the firmware configures. The CPU runs in
  chunks that end before the next peripheral event (`next_event`), so a chunk never hides an interrupt; the
  peripherals are brought up to date between chunks, and a register read during a chunk sees the chunk's start.
- Exceptions follow ARMv7-M (ARM DDI 0403E B1.5): priorities with PRIMASK/BASEPRI, preemption, a hardware frame
  pushed on the stack (the extended frame with s0-s15/FPSCR when CONTROL.FPCA is set), EXC_RETURN, and return to
  the interrupted context. Entry happens between chunks, at an exception return and at WFE (while an interrupt
  waits behind PRIMASK or BASEPRI, chunks are `UNMASK_CHUNK` instructions long); Unicorn signals an
  exception return (a branch to 0xFFFFFFxx in handler mode) as EXCP_EXCEPTION_EXIT, handled without stopping.
- Unicorn treats WFE as an invalid instruction: a hook on each WFE/WFI applies B1.5.18 (the event register, set
  by SEV and by exception entry and return) and otherwise puts the CPU to sleep until an interrupt is pending.
"""

import struct
import time

from qiling import Qiling
from qiling.const import QL_ARCH, QL_OS, QL_VERBOSE
from qiling.extensions.mcu.stm32f4 import stm32f411
from qiling.hw.peripheral import QlPeripheral
from unicorn import UC_HOOK_CODE, UC_HOOK_INTR, UC_HOOK_MEM_WRITE, UC_PROT_READ, UC_QUERY_PAGE_SIZE, Uc, UcError
from unicorn import arm_const as A

from elf import Elf
from models.dma import Dma, RequestLine, unpack_words
from models.dwt import Dwt
from models.exti import Exti
from models.flash import FLASH_BASE, FLASH_SIZE, FlashInterface
from models.gpio import Gpio
from models.iwdg import Iwdg
from models.nvic import Nvic
from models.otg import OtgFs
from models.rcc import IWDGRSTF, PINRSTF, POWER_ON, SFTRSTF, Rcc
from models.tim import Tim
from models.usart import Usart

SYSCLK = 96_000_000
EXCP_EXCEPTION_EXIT = 8  # QEMU's exception number for an EXC_RETURN branch
WFE, WFI, SEV = 0xBF20, 0xBF30, 0xBF40
# While an interrupt is pending behind PRIMASK/BASEPRI the CPU runs in chunks this short, instead of a hook on each
# of the firmware's ~55 MSR PRIMASK sites: with Unicorn's instruction count on, every instruction walks every code
# hook, and those hooks tripled the emulation's time.
UNMASK_CHUNK = 16
PAINT = 0xA5  # unused RAM is painted with this before the run, to measure the stack's deepest point
R = [A.UC_ARM_REG_R0, A.UC_ARM_REG_R1, A.UC_ARM_REG_R2, A.UC_ARM_REG_R3, A.UC_ARM_REG_R12, A.UC_ARM_REG_LR]
S = [getattr(A, f"UC_ARM_REG_S{i}") for i in range(16)]

# RM0383 10.2 (vector table): the NVIC lines of the modelled peripherals
TIMERS = {  # label: (base, irq_up, irq_cc, bits)
    "tim1": (0x4001_0000, 25, 27, 16),
    "tim2": (0x4000_0000, 28, 28, 32),
    "tim3": (0x4000_0400, 29, 29, 16),
    "tim4": (0x4000_0800, 30, 30, 16),
    "tim5": (0x4000_0C00, 50, 50, 32),
}
DMA1_IRQS = [11, 12, 13, 14, 15, 16, 17, 47]
DMA2_IRQS = [56, 57, 58, 59, 60, 68, 69, 70]
# RM0383 9.3.3 (request mapping tables): where each timer's update request goes (controller, stream, channel)
UPDATE_REQUESTS = {
    "tim1": [("dma2", 5, 6)],
    "tim2": [("dma1", 1, 3), ("dma1", 7, 3)],
    "tim3": [("dma1", 2, 5)],
    "tim4": [("dma1", 6, 2)],
    "tim5": [("dma1", 0, 6), ("dma1", 6, 6)],
}
# RM0383 9.3.3, table 28 (DMA2): where TIM1's compare requests go (channel 0-3 -> (controller, stream, channel)).
# The step generator's spare axes use CH1 on stream 1 and CH2 on stream 2; the other timers' are not wired.
COMPARE_REQUESTS = {
    "tim1": {0: [("dma2", 1, 6), ("dma2", 3, 6), ("dma2", 6, 0)], 1: [("dma2", 2, 6), ("dma2", 6, 0)],
             2: [("dma2", 6, 6), ("dma2", 6, 0)], 3: [("dma2", 4, 6)]},
}
# RM0383 9.3.3, table 28 (DMA2): USART1's receive and transmit requests (controller, stream, channel)
USART1_RX_REQUESTS = [("dma2", 2, 4), ("dma2", 5, 4)]
USART1_TX_REQUESTS = [("dma2", 7, 4)]
QILING_PERIPHERALS = ["pwr", "syscfg", "dbgmcu", "usart2", "usart6"]
# RM0383 39.1: the 96-bit unique device ID at 0x1FFF7A10 (X and Y on the wafer, 16 bits each; the wafer number;
# the lot number, seven ASCII characters), in the page after system memory that also holds the OTP area (RM0383
# 3.8, 0x1FFF7800-0x1FFF7A0F, erased: 0xFF). Qiling's profile maps system memory up to 0x1FFF77FF only. This
# board's ID:
UID_ADDR = 0x1FFF_7A10
UID = struct.pack("<HHB", 35, 65, 7) + b"RINGPOD"
OTP_BASE, OTP_SIZE = 0x1FFF_7800, 0x210
USART1_IRQ = 37  # RM0383 10.2: USART1 global interrupt; on APB2, clocked at SYSCLK here


class Fault(Exception):
    pass


class Machine:
    def __init__(self, elf_path, ram, max_chunk=10_000):
        self.elf = Elf(elf_path)
        self.ram_base, self.ram_size = ram
        self.max_chunk = max_chunk
        self.now = 0
        self.ql = Qiling([elf_path], archtype=QL_ARCH.CORTEX_M, ostype=QL_OS.MCU, env=stm32f411,
                         verbose=QL_VERBOSE.DISABLED)
        self.ql.clear_hooks()  # Qiling's interrupt hook runs handlers recursively: the CPU below replaces it
        self.uc = self.ql.uc
        self.hw = self.ql.hw
        self._cache = {}
        self.hw.find = self._find
        self.hw.setup_mmio(0x5000_0000, 0x40000, info="[OTG FS]")
        self.resets = []  # (time, cause)
        self.cpu_held_until = 0  # a hold-up of the CPU a check asks for (cycles): see `run`
        self.reset_request = None
        self.fault = None
        self.observers = []  # called between chunks, at most once a simulated millisecond
        self.sim_limit, self.wall_limit = None, None  # `limit`
        self.over_limit = None  # why the run stopped at its limit
        self._build()
        # Erased flash reads 0xFF (RM0383 3.3); then the ELF exactly as a programmer writes it.
        self.uc.mem_write(FLASH_BASE, b"\xff" * FLASH_SIZE)
        for addr, data in self.elf.segments:
            if FLASH_BASE <= addr < FLASH_BASE + FLASH_SIZE:
                self.uc.mem_write(addr, data)
        self._map_uid()
        self._paint_ram()
        self._hooks()
        self._cpu_reset()
        self.rcc.set_reset_flags(POWER_ON)

    def _map_uid(self):
        """The OTP area and the unique ID (see `UID`): the Unicorn page that holds them mapped read-only, when the
        profile's system memory does not already reach it (rounded up to a page); nothing below 0x1FFF7800 is
        mapped or written here."""
        mapped = any(lo <= UID_ADDR and UID_ADDR + len(UID) - 1 <= hi for lo, hi, _ in self.uc.mem_regions())
        if not mapped:
            page = self.uc.query(UC_QUERY_PAGE_SIZE)
            base = UID_ADDR & ~(page - 1)
            if base < OTP_BASE or UID_ADDR + len(UID) > base + page:
                raise Fault(f"a {page}-byte page at {base:#x} would reach below the OTP area into system memory")
            self.uc.mem_map(base, page, UC_PROT_READ)
        self.uc.mem_write(OTP_BASE, b"\xff" * OTP_SIZE)
        self.uc.mem_write(UID_ADDR, UID)

    def uid_hex(self):
        """The serial number the firmware gives the USB host: the ID's bytes from the lowest address, in hex."""
        return bytes(self.uc.mem_read(UID_ADDR, len(UID))).hex().upper()

    # -- the bus --
    def _find(self, address):
        hit = self._cache.get(address)
        if hit is None:
            for label, regions in self.hw.region.items():
                if any(lo <= address < hi for lo, hi in regions):
                    hit = self.hw.entity[label]
                    break
            else:
                hit = False
            self._cache[address] = hit
        return hit or None

    def install(self, label, base, model):
        if not isinstance(model, QlPeripheral):
            model.base = base  # Qiling's peripherals find their base in hw.region
        self.hw.entity[label] = model
        self.hw.region[label] = [(base + lo, base + hi) for lo, hi in model.region]
        self.hw.stepable.pop(label, None)
        self._cache.clear()
        return model

    def clock(self):
        return self.now

    def pend(self, irq):
        self.nvic.set_pending(irq)

    def _build(self):
        hw = self.hw
        for label in QILING_PERIPHERALS:
            hw.delete(label)
            hw.create(label)
        self.rcc = self.install("rcc", 0x4002_3800, Rcc(self.ql, "rcc"))
        self.gpio = {}
        for port, base in (("a", 0x4002_0000), ("b", 0x4002_0400), ("c", 0x4002_0800)):
            self.gpio[port] = self.install(f"gpio{port}", base, Gpio(self.ql, f"gpio{port}"))
        scb = hw.entity["scb"]
        self.nvic = self.install("nvic", 0xE000_E100, Nvic(sys_priority=lambda exc: scb.instance.SHP[exc - 4]))
        scb.hook_write(self._scb_write)
        self.flash = self.install("flash interface", 0x4002_3C00, FlashInterface(self, self.clock, SYSCLK))
        self.dma = {"dma1": self.install("dma1", 0x4002_6000, Dma("dma1", self, self.pend, DMA1_IRQS)),
                    "dma2": self.install("dma2", 0x4002_6400, Dma("dma2", self, self.pend, DMA2_IRQS))}
        self.tim = {}
        for label, (base, up, cc, bits) in TIMERS.items():
            tim = self.install(label, base, Tim(label, self.clock, self.pend, up, cc, bits))
            for dma, stream, channel in UPDATE_REQUESTS[label]:
                tim.update_dma.append(RequestLine(self.dma[dma], stream, channel))
            for ch, lines in COMPARE_REQUESTS.get(label, {}).items():
                tim.cc_dma[ch] += [RequestLine(self.dma[dma], stream, channel) for dma, stream, channel in lines]
            self.tim[label] = tim
        self.iwdg = self.install("iwdg", 0x4000_3000, Iwdg(self.clock, self._watchdog_timeout, SYSCLK))
        # RM0383 6.3.10 RCC_AHB2ENR.OTGFSEN (bit 7) clocks the OTG FS core
        self.otg = self.install("otg_fs", 0x5000_0000,
                                OtgFs(self.pend, clocked=lambda: self.rcc.instance.AHB2ENR >> 7 & 1))
        self.dwt = self.install("dwt", 0xE000_1000, Dwt(self.clock))
        self.exti = self.install("exti", 0x4001_3C00, Exti(self.pend, self._exticr))
        self.usart1 = self.install("usart1", 0x4001_1000, Usart("usart1", self.clock, self.pend, USART1_IRQ))
        self.usart1.rx_dma = [RequestLine(self.dma[d], stream, channel) for d, stream, channel in USART1_RX_REQUESTS]
        self.usart1.tx_dma = [RequestLine(self.dma[d], stream, channel) for d, stream, channel in USART1_TX_REQUESTS]
        # a stream enabled while the USART's request holds starts at once (a request is a level, RM0383 9.3.2)
        self.dma["dma2"].on_enable.append(lambda stream: self.usart1.serve_dma())
        self.timed = [self.iwdg, self.usart1, *self.tim.values()]

    def _exticr(self, line):
        """RM0383 7.2.3: SYSCFG_EXTICR1-4, four bits per line: the port routed to EXTI `line` (0 = A)."""
        return self.read(0x4001_3808 + 4 * (line // 4), 4) >> (4 * (line % 4)) & 0xF

    # memory access for the DMA and the flash model
    def read(self, addr, size):
        dev = self._find(addr)
        if dev:
            return dev.read(addr - dev.base, size)
        return int.from_bytes(self.uc.mem_read(addr, size), "little")

    def write(self, addr, data_or_size, value=None):
        if value is None:  # write(addr, bytes): the flash model's array access (an erase)
            self._apply_flash_fixups()  # the stores before it land first
            self.uc.mem_write(addr, bytes(data_or_size))
            return
        dev = self._find(addr)
        if dev:
            dev.write(addr - dev.base, data_or_size, value)
        else:
            self.uc.mem_write(addr, value.to_bytes(data_or_size, "little"))

    def read_words(self, addr, n):
        return unpack_words(bytes(self.uc.mem_read(addr, 4 * n)))

    def write_words(self, addr, words):
        dev = self._find(addr)
        if isinstance(dev, Gpio) and addr - dev.base == 0x18:
            dev.bsrr_words(words)
            dev.dma_words += len(words)
        else:
            for w in words:
                self.write(addr, 4, w)

    # -- hooks --
    def _hooks(self):
        uc = self.uc
        uc.hook_add(UC_HOOK_INTR, self._intr)
        for addr in self.elf.hint_sites(WFE) + self.elf.hint_sites(WFI):
            uc.hook_add(UC_HOOK_CODE, self._wfe, None, addr, addr)
        for addr in self.elf.hint_sites(SEV):
            uc.hook_add(UC_HOOK_CODE, self._sev, None, addr, addr)
        uc.hook_add(UC_HOOK_MEM_WRITE, self._flash_store, None, FLASH_BASE, FLASH_BASE + FLASH_SIZE - 1)
        self.flash_fixups = {}  # flash byte address -> what the array holds after this chunk's stores

    def count_instructions(self):
        """Counts every executed instruction in `self.instructions` (slow: for measuring only)."""
        self.instructions = 0

        def count(uc, addr, size, ud):
            self.instructions += 1

        self.uc.hook_add(UC_HOOK_CODE, count)

    def add_breakpoint(self, addr, callback):
        """Calls `callback(self)` before the instruction at `addr` runs; returns the hook (for `uc.hook_del`). Each
        code hook costs every instruction while Unicorn counts them: remove one whose work is done."""
        return self.uc.hook_add(UC_HOOK_CODE, lambda uc, a, size, ud: callback(self), None, addr & ~1, addr & ~1)

    def _scb_write(self, scb, access, offset, size, value):
        # PM0214 4.4.4 AIRCR: SYSRESETREQ with the key 0x05FA requests a system reset
        if offset == 0x0C and value >> 16 == 0x05FA and value & 4:
            self.reset_request = (self.now, "SYSRESETREQ")
            self.uc.emu_stop()

    def _flash_store(self, uc, access, addr, size, value, ud):
        # The store is about to happen (Unicorn writes the raw value into the array): the flash model decides now,
        # with FLASH_CR as it is at this store (embassy unlocks, programs one word and locks again within a chunk),
        # and the array gets what programming leaves (`cpu_write`) after the chunk.
        raw = uc.mem_read(addr, size)
        old = bytes(self.flash_fixups.get(addr + i, raw[i]) for i in range(size))
        for i, b in enumerate(self.flash.cpu_write(addr, size, value, old)):
            self.flash_fixups[addr + i] = b

    def _apply_flash_fixups(self):
        for addr, b in self.flash_fixups.items():
            self.uc.mem_write(addr, bytes([b]))
        self.flash_fixups.clear()

    def _watchdog_timeout(self, at):
        self.reset_request = (at, "IWDG")

    # -- the CPU: exceptions (ARMv7-M ARM B1.5) --
    def reg(self, r):
        return self.uc.reg_read(r)

    def pc(self):
        return self.uc.reg_read(A.UC_ARM_REG_PC)

    def exec_priority(self):
        """B1.5.4: the current execution priority from the active exceptions, PRIMASK and BASEPRI."""
        prio = 256
        for exc in self.active:
            prio = min(prio, self.nvic.priority(exc))
        if self.reg(A.UC_ARM_REG_PRIMASK) & 1:
            prio = min(prio, 0)
        basepri = self.reg(A.UC_ARM_REG_BASEPRI) & 0xF0
        if basepri:
            prio = min(prio, basepri)
        return prio

    def masked(self):
        """An exception is pending that the active ones would let in but PRIMASK or BASEPRI holds back (B1.5.4)."""
        best = self.nvic.best_pending()
        if best is None:
            return False
        prio = min((self.nvic.priority(exc) for exc in self.active), default=256)
        return best[0] < prio

    def try_take(self, return_pc):
        best = self.nvic.best_pending()
        self.nvic.changed = False
        if best is None or best[0] >= self.exec_priority():
            return False
        self._enter(best[1], return_pc)
        return True

    def _enter(self, exc, return_pc):
        uc = self.uc
        control = self.reg(A.UC_ARM_REG_CONTROL)
        handler = bool(self.reg(A.UC_ARM_REG_IPSR) & 0x1FF)
        if control & 2 and not handler:
            raise Fault("thread mode on the process stack (PSP) is not modelled")
        fp = bool(control & 4)
        sp = self.reg(A.UC_ARM_REG_MSP)
        size = 0x68 if fp else 0x20
        frame = (sp - size) & ~7  # B1.5.7: the frame is 8-byte aligned (CCR.STKALIGN = 1)
        xpsr = self.reg(A.UC_ARM_REG_XPSR) | (1 << 24)
        if sp & 4:
            xpsr |= 1 << 9
        else:
            xpsr &= ~(1 << 9)
        words = [self.reg(r) for r in R] + [return_pc & ~1, xpsr]
        if fp:
            words += [self.reg(s) & 0xFFFFFFFF for s in S] + [self.reg(A.UC_ARM_REG_FPSCR), 0]
        if frame < self.ram_base:
            raise Fault(f"stack overflow: exception frame at {frame:#010x}")
        uc.mem_write(frame, struct.pack(f"<{len(words)}I", *words))
        self.stack_low = min(self.stack_low, frame)
        uc.reg_write(A.UC_ARM_REG_MSP, frame)
        exc_return = 0xFFFFFFF1 if handler else 0xFFFFFFF9  # B1.5.8
        if fp:
            exc_return &= ~0x10
        uc.reg_write(A.UC_ARM_REG_CONTROL, control & ~4)
        uc.reg_write(A.UC_ARM_REG_IPSR, exc)
        uc.reg_write(A.UC_ARM_REG_LR, exc_return)
        vtor = self.hw.entity["scb"].instance.VTOR
        uc.reg_write(A.UC_ARM_REG_PC, self.read(vtor + 4 * exc, 4) | 1)
        self.nvic.pending.discard(exc)
        self.nvic.active.add(exc)
        self.active.append(exc)
        self.entries[exc] = self.entries.get(exc, 0) + 1
        self.event = True  # B1.5.18: exception entry sets the event register

    def _exit(self, exc_return):
        uc = self.uc
        exc = self.active.pop()
        self.nvic.active.discard(exc)
        fp = not exc_return & 0x10
        sp = self.reg(A.UC_ARM_REG_MSP)
        n = 26 if fp else 8
        words = struct.unpack(f"<{n}I", bytes(uc.mem_read(sp, 4 * n)))
        for r, v in zip(R, words[:6]):
            uc.reg_write(r, v)
        xpsr = words[7]
        if fp:
            for s, v in zip(S, words[8:24]):
                uc.reg_write(s, v)
            uc.reg_write(A.UC_ARM_REG_FPSCR, words[24])
        uc.reg_write(A.UC_ARM_REG_MSP, sp + 4 * n + (4 if xpsr & (1 << 9) else 0))
        control = self.reg(A.UC_ARM_REG_CONTROL)
        uc.reg_write(A.UC_ARM_REG_CONTROL, (control | 4) if fp else (control & ~4))
        uc.reg_write(A.UC_ARM_REG_XPSR, xpsr & ~(1 << 9))
        uc.reg_write(A.UC_ARM_REG_IPSR, xpsr & 0x1FF)
        uc.reg_write(A.UC_ARM_REG_PC, words[6] | 1)
        self.event = True  # B1.5.18: exception return sets the event register
        if (xpsr & 0x1FF) != (self.active[-1] if self.active else 0):
            raise Fault(f"exception return to IPSR {xpsr & 0x1FF}, active {self.active}")
        # B1.5.12: a pending exception that now has priority is taken at once (tail-chaining, as an entry here)
        self.try_take(words[6])

    def _intr(self, uc, intno, ud):
        try:
            if intno == EXCP_EXCEPTION_EXIT and self.active:
                self._exit(self.pc() | 1)
                return
            raise Fault(f"CPU exception {intno} at {self.pc():#010x}")
        except Fault as e:
            self.fault = str(e)
            uc.emu_stop()

    def _wfe(self, uc, addr, size, ud):
        # B1.5.18 / B1.5.19: WFE returns at once when the event register is set (and clears it); WFI and WFE
        # wake for a pending interrupt; otherwise the core sleeps
        if uc.mem_read(addr, 2) == b"\x20\xbf" and self.event:
            self.event = False
            uc.reg_write(A.UC_ARM_REG_PC, (addr + 2) | 1)
            return
        if self.try_take(addr):
            return
        self.sleeping = addr
        uc.emu_stop()

    def _sev(self, uc, addr, size, ud):
        self.event = True

    # -- resets --
    def _paint_ram(self):
        """Fill RAM above the program's statics (`_stack_end`, cortex-m-rt) with PAINT."""
        low = self.elf.address("_stack_end")
        top = self.ram_base + self.ram_size
        self.paint_low = low
        self.uc.mem_write(low, bytes([PAINT]) * (top - low))

    def stack_depth_lowest(self):
        """The lowest RAM address written above `_stack_end` (the stack's deepest point)."""
        top = self.ram_base + self.ram_size
        data = bytes(self.uc.mem_read(self.paint_low, top - self.paint_low))
        untouched = len(data) - len(data.lstrip(bytes([PAINT])))
        return self.paint_low + untouched

    def _cpu_reset(self):
        uc = self.uc
        for r in (A.UC_ARM_REG_PRIMASK, A.UC_ARM_REG_BASEPRI, A.UC_ARM_REG_FAULTMASK, A.UC_ARM_REG_CONTROL):
            uc.reg_write(r, 0)
        uc.reg_write(A.UC_ARM_REG_IPSR, 0)
        msp = self.read(FLASH_BASE, 4)  # B1.5.5: the vector table at 0 aliases flash (BOOT0 = 0)
        uc.reg_write(A.UC_ARM_REG_MSP, msp)
        uc.reg_write(A.UC_ARM_REG_LR, 0xFFFFFFFF)
        uc.reg_write(A.UC_ARM_REG_PC, self.read(FLASH_BASE + 4, 4) | 1)
        self.active = []
        self.entries = {}
        self.event = False
        self.sleeping = None
        self.stack_low = msp

    def system_reset(self, cause):
        """A system reset: every peripheral to its reset state, RAM and flash kept (RM0383 6.1, system reset)."""
        flags = {"IWDG": IWDGRSTF | PINRSTF, "SYSRESETREQ": SFTRSTF | PINRSTF}[cause]
        self.resets.append((self.now, cause))
        for label in QILING_PERIPHERALS + ["scb", "systick"]:
            self.hw.delete(label)
            self.hw.create(label)
        self.hw.entity["scb"].hook_write(self._scb_write)
        self.nvic.sys_priority = lambda exc, scb=self.hw.entity["scb"]: scb.instance.SHP[exc - 4]
        self.rcc.instance = Rcc(self.ql, "rcc").instance
        for model in (self.nvic, self.iwdg, self.usart1, self.exti, *self.tim.values(), *self.dma.values()):
            model.reset()
        for port in self.gpio.values():
            port.instance = type(port.instance)()
        history = (self.flash.erases, self.flash.programs, self.flash.rejected)
        self.flash.__init__(self, self.clock, SYSCLK)  # an erase in progress is cut short
        self.flash.erases, self.flash.programs, self.flash.rejected = history  # kept for the checks
        self.otg.reset()
        self.dwt.__init__(self.clock)
        self._cache.clear()
        self._cpu_reset()
        self.rcc.set_reset_flags(flags)

    def limit(self, cycles, wall_deadline):
        """Stops the run (as a fault: every later step returns at once) past `cycles` simulated or at the wall
        clock's `wall_deadline` (time.time()): a firmware that hangs the harness fails instead of running on."""
        self.sim_limit, self.wall_limit = cycles, wall_deadline

    def _check_limit(self):
        if self.sim_limit is not None and self.now > self.sim_limit:
            self.over_limit = f"past {self.sim_limit / SYSCLK:.0f} simulated s"
        elif self.wall_limit is not None and time.time() > self.wall_limit:
            self.over_limit = f"past the wall-clock limit at {self.now / SYSCLK:.1f} simulated s"
        if self.over_limit:
            self.fault = f"run limit: {self.over_limit}"

    # -- the scheduler --
    def advance(self):
        for model in self.timed:
            model.advance(self.now)

    def next_event(self):
        return min(model.next_event(self.now) for model in self.timed)

    def run(self, until):
        """Run up to time `until` (cycles)."""
        uc = self.uc
        observed = self.now
        while self.now < until and self.fault is None:
            self.advance()
            if self.reset_request:
                at, cause = self.reset_request
                self.reset_request = None
                self.now = max(self.now, at)
                self.system_reset(cause)
                continue
            if self.now - observed >= SYSCLK // 1000:
                observed = self.now
                self._check_limit()
                for observe in self.observers:
                    observe()
            held_until = max(self.flash.busy_until, self.cpu_held_until)
            if held_until > self.now:
                # RM0383 3.5: reading flash while a sector is erased stalls the bus; code and vectors are in flash,
                # so the CPU waits (interrupts stay pending) while the peripherals and the watchdog run on. A check
                # may hold the CPU so too (`cpu_held_until`): a board's hold-up of its own.
                self.now = max(self.now + 1, min(self.next_event(), held_until, until))
                continue
            try:
                if self.sleeping is not None:
                    if self.try_take(self.sleeping):
                        self.sleeping = None
                    else:
                        self.now = max(self.now + 1, min(self.next_event(), until))
                        continue
                else:
                    self.try_take(self.pc())
            except Fault as e:
                self.fault = str(e)
                break
            deadline = min(self.next_event(), until, self.now + self.max_chunk)
            if self.masked():
                # B5.2.1 CPS, B5.2.3 MSR: an interrupt held back by a critical section is taken within
                # UNMASK_CHUNK instructions of its end (at 921600 baud a received byte waits only ~1,000 cycles)
                deadline = min(deadline, self.now + UNMASK_CHUNK)
            n = max(1, int(deadline - self.now))
            try:
                Uc.emu_start(uc, self.pc() | 1, 0, 0, n)
            except UcError as e:
                # a WFE the hook stopped at may still be executed, and Unicorn calls it invalid
                if self.sleeping is None or self.pc() not in (self.sleeping, self.sleeping + 2):
                    self.fault = f"{e} at pc {self.pc():#010x}"
            if self.flash_fixups:
                self._apply_flash_fixups()
            self.now += n
            sp = self.reg(A.UC_ARM_REG_MSP)
            if sp < self.stack_low:
                self.stack_low = sp
