"""The ROM bootloader entered from the firmware (`device bootloader`, which `ringpod flash` sends first): refused
while the platform runs, with nothing moving at the pins; from Off, the firmware resets (SYSRESETREQ, the USB
device leaves the bus), and the next start takes the system memory's stack pointer and reset vector before
anything else (AN2606: the STM32F411's bootloader at 0x1FFF_0000, entered with system memory mapped at 0).

System memory holds a stand-in for the ROM: its vector table and a reset handler that sleeps (WFI in a loop), so
that the jump is seen and the machine idles cheaply; once it runs, the USB host finds the ROM's DfuSe device
(`models/dfuse_rom.py`, writing the machine's flash) on the bus in the firmware's place, and `dfu_bridge.py` serves
it to `ringpod flash --dfu`. Leaving it is a reset (as the ROM's leave request does), after which the program in
flash starts: the marker was cleared before the jump.

`flash-usb`: `ringpod flash` from the running firmware, as a user runs it (the board asked over its link, the image
written into the ROM model over the bridge, read back, DFU left), then the firmware back, naming the image, with
the settings stored before still there."""

import json
import struct

from unicorn import UC_HOOK_CODE
from unicorn import arm_const as A

from dfu_client_check import RENAMED, crc32c, elf_image, sectors_end
from models.dfuse_rom import DfuseRom
from plant import ENABLE_N, LOGIC_EN, POWER_EN

SYSCLK_HZ = 96_000_000
SYSTEM_MEMORY = 0x1FFF_0000  # AN2606, STM32F411xx: system memory (30 KB)
SYSTEM_MEMORY_SIZE = 0x7800
ROM_SP = 0x2000_3000  # the stand-in's initial stack pointer (any word-aligned RAM address the firmware's is not)
ROM_RESET = SYSTEM_MEMORY + 0x200
WFI_LOOP = bytes.fromhex("30bf" "fde7")  # wfi; b.n back to the wfi
SYSCFG_MEMRMP = 0x4001_3800  # RM0383 7.2.1: MEM_MODE, bits 1:0 (01: system memory at 0)
RCC_APB2ENR = 0x4002_3844  # RM0383 6.3.12: SYSCFGEN, bit 14


class SystemMemory:
    """The ROM stand-in in system memory, and every entry into its reset handler: (time, MSP, MEMRMP, resets)."""

    def __init__(self, m, host=None):
        self.m, self.host = m, host
        self.dfu = None  # the ROM's DfuSe device while it runs
        try:
            m.uc.mem_write(SYSTEM_MEMORY, b"\x00")
        except Exception:  # the profile did not map it
            m.uc.mem_map(SYSTEM_MEMORY, 0x8000)
        m.uc.mem_write(SYSTEM_MEMORY, b"\xff" * SYSTEM_MEMORY_SIZE)
        m.uc.mem_write(SYSTEM_MEMORY, struct.pack("<II", ROM_SP, ROM_RESET | 1))
        m.uc.mem_write(ROM_RESET, WFI_LOOP)
        self.entries = []
        # One hook: the entry is recorded, then the WFI sleeps (a hook that stops the CPU, as the WFI's does, ends
        # the instruction's hooks there: Unicorn runs no later hook of the same instruction).
        m.uc.hook_add(UC_HOOK_CODE, self._reset_handler, None, ROM_RESET, ROM_RESET)

    def _reset_handler(self, uc, addr, size, ud):
        if not self.entries or self.entries[-1][3] != len(self.m.resets):  # not the loop going round again
            self._entered(uc)
        self.m._wfe(uc, addr, size, ud)

    def _entered(self, uc):
        msp = uc.reg_read(A.UC_ARM_REG_MSP)
        self.entries.append((self.m.now, msp, self.m.read(SYSCFG_MEMRMP, 4) & 3, len(self.m.resets)))
        m = self.m
        self.dfu = DfuseRom(m.clock, SYSCLK_HZ, lambda at, n: bytes(m.uc.mem_read(at, n)), m.uc.mem_write,
                            leave=lambda address: self.leave())
        if self.host is not None:  # the ROM's USB device on the bus (AN3156), enumerated afresh
            self.host.dev = self.dfu
            self.host.reset_state()
            self.host.task = self.host._attach()
            self.host.next_at = m.now

    def leave(self):
        """The ROM leaves DFU: a reset into the program in flash; the firmware's USB core is the device again (the
        host sees the ROM go and waits for the firmware to attach)."""
        self.m.reset_request = (self.m.now, "SYSRESETREQ")
        if self.host is not None:
            self.host.dev = self.m.otg
        self.dfu = None


def _state(r):
    try:
        return json.loads(r.stdout).get("state")
    except ValueError:
        return None


def _supplies(m):
    odr = m.gpio["b"].instance.ODR
    return (odr >> ENABLE_N & 1, odr >> LOGIC_EN & 1, odr >> POWER_EN & 1)


def bootloader_refused_check(checks, m, cli, port, plant, rom):
    """Homed and Ready: `device start`, then `device bootloader` refused while Running, nothing moving at the pins;
    `device stop` leaves it Ready."""
    from machine import SYSCLK

    resets0 = len(m.resets)
    start = cli.run("device", "start", *port)
    plant.reset_counts()
    pins0 = _supplies(m)
    refused = cli.run("device", "bootloader", *port, expect=(1,))
    m.run(m.now + SYSCLK // 10)
    pins1 = _supplies(m)
    after = cli.run("device", "status", *port)
    checks.check("bootloader-refused", _state(start) == "Running" and refused.code == 1
                 and "not possible in the current state" in refused.stderr and plant.steps == [0] * 6
                 and pins0 == pins1 == (0, 1, 1) and len(m.resets) == resets0 and not rom.entries,
                 f"`device start`: {_state(start)}; {refused}; STEP edges since {plant.steps}; ENABLE, LOGIC, POWER "
                 f"{pins0} -> {pins1} (want 0, 1, 1 throughout: drivers enabled, supplies on); resets "
                 f"{len(m.resets) - resets0}, system memory entered {len(rom.entries)} times; state after: "
                 f"{_state(after)}")
    cli.run("device", "stop", *port)
    m.run(m.now + SYSCLK // 2)


def bootloader_entry_checks(checks, m, cli, port, rom, log, usb=None):
    """The supplies off, `device bootloader` taken: the reset, the jump into system memory, USB gone; then the
    bootloader left by a reset and the firmware back."""
    from machine import SYSCLK

    resets0 = len(m.resets)
    # Off already when the e-stop check's `device clear` left it so (then refused, exit 1)
    cli.run("device", "disable", *port, expect=(0, 1))
    m.run(m.now + SYSCLK // 2)  # drivers, power, logic off
    off = cli.run("device", "status", *port)
    lines = len(log.lines)
    enumerations = usb.host.enumerations if usb else 0
    usb_log = len(usb.host.log) if usb else 0
    asked = m.now
    enter = cli.run("device", "bootloader", *port)
    m.run(m.now + SYSCLK // 2)  # the settings task's 100 ms poll, 20 ms for the answer to leave, the reset
    log.poll()
    restarted = [cause for _, cause in m.resets[resets0:]]
    starts = [t for _, _, t in log.lines[lines:] if "firmware up" in t]
    said = [t for _, _, t in log.lines[lines:] if "restarting into" in t]
    entry = rom.entries[0] if rom.entries else None
    left = [what for _, what in usb.host.log[usb_log:]] if usb else []
    rom_id = struct.unpack_from("<HH", usb.host.device, 8) if usb and usb.host.device else None
    usb_ok = usb is None or ("device detached" in left and usb.host.configured and rom_id == (0x0483, 0xDF11))
    checks.check("bootloader-entered", _state(off) == "Off" and enter.code == 0 and restarted == ["SYSRESETREQ"]
                 and entry is not None and entry[1] == ROM_SP and entry[2] == 1 and not starts and said and usb_ok,
                 f"state {_state(off)}; {enter}; the firmware: {said}; resets {restarted}; system memory's reset "
                 f"handler entered {(entry[0] - asked) * 1000 / SYSCLK if entry else '-'} ms after the request, MSP "
                 f"{entry[1] if entry else 0:#010x} (the ROM's {ROM_SP:#010x}), SYSCFG_MEMRMP {entry[2] if entry else '-'} "
                 f"(1: system memory at 0); firmware starts since: {len(starts)}; USB: {left[:6]}, "
                 f"{usb.host.enumerations - enumerations if usb else '-'} enumerations since, the device now "
                 f"{'%04x:%04x' % rom_id if rom_id else '-'} (the ROM's DfuSe device: 0483:df11)")

    # Leaving the bootloader resets the chip: the firmware starts again (the marker was cleared before the jump).
    rom.leave()
    m.run(m.now + int(0.3 * SYSCLK))
    back = cli.run("device", "status", *port)
    log.poll()
    starts = [t for _, _, t in log.lines[lines:] if "firmware up" in t]
    checks.check("bootloader-left", back.code == 0 and _state(back) == "Off" and len(starts) == 1
                 and len(rom.entries) == 1,
                 f"a reset out of the bootloader: firmware starts {len(starts)}, system memory entered "
                 f"{len(rom.entries)} times in all; {back}")


SETTINGS = (0x0804_0000, 0x0808_0000)  # sectors 6-7


def flash_check(checks, m, cli, port, rom, log, bridge, elf, clients=()):
    """`ringpod flash --image ELF` from the running firmware (Off): the board asked over its link to enter its
    bootloader, the image written into the ROM model over the bridge (only sectors 0-5 erased), read back, DFU left;
    the firmware back, answering with the image's CRC-32C, the setting stored before still there. The image is the
    run's program renamed (`dfu_client_check.renamed_elf`), which `dfu-client-board` wrote before with the published
    client: the program that comes back enumerates with the new product string and names the image's CRC-32C; the
    sectors the image covers, erased and written again, hold byte for byte what that client wrote (`clients`: the
    flash it left on the board and in the model alone)."""
    from machine import SYSCLK

    settings = bytes(m.uc.mem_read(SETTINGS[0], SETTINGS[1] - SETTINGS[0]))
    lines, entries = len(log.lines), len(rom.entries)
    roms = []
    grab = lambda: roms.append(rom.dfu) if rom.dfu is not None and rom.dfu not in roms else None  # noqa: E731
    m.observers.append(grab)
    r = cli.run("flash", *port, "--image", elf, "--dfu", bridge.address, sim_limit_s=60)
    m.observers.remove(grab)
    m.run(m.now + SYSCLK // 5)
    got = cli.run("device", "config", "get", "stream.timeout_ms", *port)
    status = cli.run("device", "status", *port)
    log.poll()
    try:
        value = json.loads(got.stdout)["value"]
    except (ValueError, KeyError, TypeError):
        value = None
    image = _image(status)
    host = bridge.host
    product = host.strings.get(host.device[15]) if host.device and len(host.device) > 15 else None
    dfu = roms[0] if roms else None
    erased = [hex(a) for a in dfu.erased] if dfu else []
    want = [hex(0x0800_0000 + a) for a in (0, 0x4000, 0x8000, 0xC000, 0x1_0000, 0x2_0000)]
    starts = [t for _, _, t in log.lines[lines:] if "firmware up" in t]
    kept = bytes(m.uc.mem_read(SETTINGS[0], SETTINGS[1] - SETTINGS[0])) == settings
    flashed = elf_image(elf)
    end = sectors_end(flashed) - 0x0800_0000
    ours = bytes(m.uc.mem_read(0x0800_0000, end))
    differ = {name: [i for i in range(end) if ours[i] != flash[i]] for name, flash in clients}
    same = bool(clients) and not any(differ.values())
    crc = f"{crc32c(flashed):08x}"
    checks.check("flash-usb", r.code == 0 and "verified" in r.stdout and len(rom.entries) == entries + 1
                 and erased == want and dfu.early_polls == 0 and kept and value == 250 and len(starts) == 1
                 and image is not None and image.get("crc32c") == crc and crc in r.stdout
                 and image.get("size") == len(flashed) and product == RENAMED.decode() and same,
                 f"{r} after {r.sim_s:.1f} simulated s; the ROM model: erased {erased} (want sectors 0-5), "
                 f"{dfu.written if dfu else 0} B programmed, {dfu.early_polls if dfu else '-'} polls before their "
                 f"timeout, {bridge.served} bridge requests; sectors 6-7 unchanged: {kept}; firmware starts since: "
                 f"{len(starts)}; {got}; the image the firmware names: {image} (the image's CRC-32C {crc}), its USB "
                 f"product string {product!r} (want {RENAMED.decode()!r}); flash 0x08000000..{0x0800_0000 + end:#010x} "
                 f"(the sectors the {len(flashed):,} B image covers) the same as the published client wrote: {same} ("
                 + ", ".join(f"{name}: {len(d)} bytes differ"
                             + (f", the first at {0x0800_0000 + d[0]:#010x}" if d else "")
                             for name, d in differ.items())
                 + ")")


def _image(status):
    try:
        return json.loads(status.stdout)["firmware"]["image"]
    except (ValueError, KeyError, TypeError):
        return None
