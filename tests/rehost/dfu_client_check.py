"""The ROM bootloader's model checked against a published DfuSe client, and the image `ringpod flash` writes in the
run.

`dfu-client`: pydfuutil (a Python port of dfu-util, on PyPI, pinned in requirements.txt) is run as its own command
line (`dfu_client.py`) against `models/dfuse_rom.py` over USB/IP (`usbip.py`), on the wall clock, outside the
emulated chip: it lists the device (0483:df11, each alternate setting's memory layout string), writes the image
(`-s 0x08000000 -D`: the sectors it covers erased as the layout string says, the blocks written), and reads it back
(`-U`), then leaves DFU (`:leave`). The flash it leaves is kept.

`dfu-client-board`: the same on the emulated board, once its firmware jumped into the ROM: pydfuutil's URBs are
carried out by the harness's USB host (`HostOnWire`), on the emulator's clock; the chip then resets into what it
wrote. `flash-usb` compares what `ringpod flash` writes with both, byte for byte.

The image is the release ELF with its USB product string changed at the same length (`renamed_elf`): every address
stays, so that the harness's probes, which follow the ELF's symbols, still hold after it is flashed, while the
image's bytes, and so its CRC-32C, differ from the program the run started with, and the new program tells itself
apart when it enumerates.
"""

import os
import queue
import random
import re
import struct
import subprocess
import sys
import tempfile
import threading
import time

from elftools.elf.elffile import ELFFile

from models import dfuse_rom as D
from usbip import UsbipServer

HERE = os.path.dirname(os.path.abspath(__file__))
PRODUCT = b"ringpod motion controller"  # firmware/src/board/stm32f411/usb.rs: the USB product string
RENAMED = b"RINGPOD MOTION CONTROLLER"
# RM0383 3.3, table 5: the F411's sectors (start, size), as the check expects the client to erase them
F411_SECTORS = [(0x0800_0000 + 0x4000 * i, 0x4000) for i in range(4)] + [(0x0801_0000, 0x1_0000)] + [
    (0x0802_0000 + 0x2_0000 * i, 0x2_0000) for i in range(3)]
SETTINGS = (0x0804_0000, 0x0808_0000)  # sectors 6-7
SETTINGS_SPAN = (SETTINGS[0], SETTINGS[1] - SETTINGS[0])
# what a real STM32F411's ROM bootloader names its flash (its alternate setting 0, as dfu-util lists it): the sectors
# above in UM0424's layout syntax, written here apart from the model's
F411_LAYOUT = "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg"


def elf_image(path):
    """The bytes a programmer lays into flash from the ELF's load segments (each at its physical address; gaps
    0xFF), from the start of flash."""
    with open(path, "rb") as f:
        segments = [(s["p_paddr"], s.data()) for s in ELFFile(f).iter_segments()
                    if s["p_type"] == "PT_LOAD" and s["p_filesz"]]
    end = max(a + len(d) for a, d in segments) - D.FLASH
    image = bytearray(b"\xff" * end)
    for at, data in segments:
        image[at - D.FLASH:at - D.FLASH + len(data)] = data
    return bytes(image)


def renamed_elf(path, dest):
    """A copy of the ELF whose USB product string reads RENAMED: the same length, in the same place."""
    data = bytearray(open(path, "rb").read())
    with open(path, "rb") as f:
        loaded = [(s["p_offset"], s["p_offset"] + s["p_filesz"]) for s in ELFFile(f).iter_segments()
                  if s["p_type"] == "PT_LOAD"]
    at = [m.start() for m in re.finditer(re.escape(PRODUCT), data) if any(a <= m.start() < b for a, b in loaded)]
    if len(at) != 1:
        raise ValueError(f"the product string is in the loaded image {len(at)} times, not once")
    data[at[0]:at[0] + len(PRODUCT)] = RENAMED
    with open(dest, "wb") as f:
        f.write(data)
    return dest


def covered(image):
    """The sectors the image covers."""
    return [a for a, s in F411_SECTORS if a < D.FLASH + len(image) and a + s > D.FLASH]


def sectors_end(image):
    a, s = next((a, s) for a, s in F411_SECTORS if a <= D.FLASH + len(image) - 1 < a + s)
    return a + s


class ModelOnWire:
    """The ROM model, at its packet level, as one control transfer at a time (what the USB/IP server needs), over a
    flash array of its own filled with noise (programming only clears bits: a block written without its erase
    shows)."""

    def __init__(self):
        self.flash = bytearray(random.Random(411).randbytes(512 * 1024))
        self.left = []  # the addresses DFU was left for
        self.rom = D.DfuseRom(lambda: int(time.monotonic() * 96_000_000), 96_000_000, self._read, self._write,
                              leave=self.left.append)
        self.control(struct.pack("<BBHHH", 0, 5, 7, 0, 0), b"")  # SET_ADDRESS, as the exporting host did

    def _read(self, at, n):
        return bytes(self.flash[at - D.FLASH:at - D.FLASH + n])

    def _write(self, at, data):
        self.flash[at - D.FLASH:at - D.FLASH + len(data)] = data

    def descriptors(self):
        return self.rom.device, self.rom.config

    def control(self, setup, data):
        rom, addr = self.rom, self.rom.address
        rt, _req, _value, _index, length = struct.unpack("<BBHHH", setup)
        if rom.setup(addr, setup) != "ACK":
            return None
        if rt & 0x80:
            got = b""
            while len(got) < length:
                packet = rom.in_(addr, 0)
                if not isinstance(packet, bytes):
                    return None
                got += packet
                if len(packet) < 64:
                    break
            return got if rom.out(addr, 0, b"") == "ACK" else None
        for i in range(0, len(data), 64):
            if rom.out(addr, 0, data[i:i + 64]) != "ACK":
                return None
        return b"" if rom.in_(addr, 0) == b"" else None


def _client(port, *args):
    t0 = time.time()
    r = subprocess.run([sys.executable, os.path.join(HERE, "dfu_client.py"), str(port), *args],
                       capture_output=True, text=True, timeout=120)
    return r, time.time() - t0


def client_check(checks, image, scratch):
    """pydfuutil lists, writes and reads back `image` on the model; returns the model's flash after the write."""
    model = ModelOnWire()
    server = UsbipServer(model.descriptors, model.control)
    before = bytes(model.flash)
    path, back = os.path.join(scratch, "image.bin"), os.path.join(scratch, "read-back.bin")
    with open(path, "wb") as f:
        f.write(image)
    listed, t_list = _client(server.port, "-l")
    found = [line for line in listed.stdout.splitlines() if line.startswith("Found DFU: [0483:df11]")]
    layout = f'alt=0, name="{F411_LAYOUT}"'
    wrote, t_write = _client(server.port, "-a", "0", "-s", "0x08000000", "-D", path)
    written = bytes(model.flash)
    erased = list(model.rom.erased)
    # read back, then leave DFU (UM0424 6.1.4: the address pointer set to the program, a zero-length download, the
    # status request that starts the manifestation)
    read, t_read = _client(server.port, "-a", "0", "-s", f"0x08000000:leave:{len(image)}", "-U", back)
    got = open(back, "rb").read() if os.path.exists(back) else b""
    server.close()
    end = sectors_end(image) - D.FLASH
    tail = written[len(image):end]
    blank = tail == b"\xff" * len(tail)
    kept = written[SETTINGS[0] - D.FLASH:] == before[SETTINGS[0] - D.FLASH:]
    want = covered(image)
    checks.check("dfu-client", listed.returncode == 0 and len(found) == 4 and any(layout in f for f in found)
                 and wrote.returncode == 0 and erased == want and written[:len(image)] == image
                 and blank and kept and read.returncode == 0 and got == image
                 and model.left == [D.FLASH] and not model.rom.attached() and not server.errors,
                 f"pydfuutil over USB/IP: `-l` exit {listed.returncode} ({t_list:.1f} s), {len(found)} alternate "
                 f"settings of 0483:df11 found, alt 0 named {F411_LAYOUT!r}: {any(layout in f for f in found)}; "
                 f"`-s 0x08000000 -D` of {len(image):,} B exit {wrote.returncode} ({t_write:.1f} s): sectors erased "
                 f"{[hex(a) for a in erased]} (want {[hex(a) for a in want]}), the image in flash: "
                 f"{written[:len(image)] == image}, the rest of its last sector erased: "
                 f"{blank}, sectors 6-7 untouched: {kept}; `-U` exit {read.returncode} "
                 f"({t_read:.1f} s): {len(got):,} B read back, the same: {got == image}, then DFU left for "
                 f"{[hex(a) for a in model.left]} (want 0x8000000), the device off the bus: "
                 f"{not model.rom.attached()}; {server.urbs} URBs, {server.stalls} stalled, "
                 f"{model.rom.early_polls} status polls before their timeout"
                 + "".join(f"; {r.stderr.strip().splitlines()[-1]}" for r in (listed, wrote, read)
                           if r.returncode and r.stderr.strip())
                 + (f"; server: {server.errors}" if server.errors else ""))
    return written


# -- the same client on the emulated board's bus --

class HostOnWire:
    """The device the harness's USB host enumerated (the ROM's, once the firmware jumped into it), for the USB/IP
    server: each transfer is handed from the server's thread to the machine's and carried out by the host's control
    transfers, on the emulator's clock (polled once a simulated millisecond, as `dfu_bridge.DfuBridge` is)."""

    def __init__(self, m, host):
        self.m, self.host = m, host
        self.queue = queue.Queue()
        self.busy = None
        m.observers.append(self.poll)

    def close(self):
        self.m.observers.remove(self.poll)

    def descriptors(self):
        return (self.host.device, self.host.config) if self.host.configured else None

    def control(self, setup, data):
        done, box = threading.Event(), {}
        self.queue.put((setup, data, box, done))
        done.wait(60)
        return box.get("data")

    def poll(self):
        if self.busy is not None:
            result, box, done = self.busy
            if result:
                box["data"] = result.get("data")
                self.busy = None
                done.set()
            return
        if self.host.task is not None or self.queue.empty():
            return  # the host enumerates, or nothing is asked
        setup, data, box, done = self.queue.get_nowait()
        if not self.host.configured:
            done.set()  # no device: the transfer fails as a stall
            return
        from usb_host import UsbError  # the machine's modules, loaded with it

        rt, req, value, index, length = struct.unpack("<BBHHH", setup)
        result = {}

        def run():
            try:
                result["data"] = yield from self.host.control(rt, req, value, index, length, data)
            except UsbError:
                result["error"] = True

        self.host.task = run()
        self.host.next_at = self.m.now
        self.busy = (result, box, done)


def run_client(m, port, *args, sim_limit_s=20):
    """pydfuutil run to its end while the machine runs, never ahead of the wall clock: the client waits each poll
    timeout in wall time, and the chip idling in the ROM's WFI loop runs about ten times faster than real time, so
    unpaced its waits would last ten times longer in simulated time. (result, simulated s, wall s)."""
    from machine import SYSCLK

    start, t0 = m.now, time.time()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen([sys.executable, os.path.join(HERE, "dfu_client.py"), str(port), *args],
                                stdout=out, stderr=err, stdin=subprocess.DEVNULL)
        while proc.poll() is None and m.now - start < sim_limit_s * SYSCLK and m.fault is None:
            ahead = (m.now - start) / SYSCLK - (time.time() - t0)
            if ahead > 0:
                time.sleep(min(ahead, 0.005))
                continue
            m.run(m.now + SYSCLK // 200)  # observers (the USB/IP bridge among them) run once a simulated ms
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        out.seek(0)
        err.seek(0)
        r = subprocess.CompletedProcess(args, proc.returncode, out.read().decode(errors="replace"),
                                        err.read().decode(errors="replace"))
    return r, (m.now - start) / SYSCLK, time.time() - t0


def crc32c(data):
    """CRC-32C (Castagnoli: reflected polynomial 0x82F63B78, initial and final XOR 0xFFFFFFFF), the checksum the
    firmware names its image by; computed here apart from the core's."""
    table = _CRC_TABLE
    crc = 0xFFFF_FFFF
    for b in data:
        crc = table[(crc ^ b) & 0xFF] ^ (crc >> 8)
    return crc ^ 0xFFFF_FFFF


def _crc_table():
    table = []
    for n in range(256):
        c = n
        for _ in range(8):
            c = (c >> 1) ^ 0x82F6_3B78 if c & 1 else c >> 1
        table.append(c)
    return table


_CRC_TABLE = _crc_table()


def board_client_check(checks, m, cli, port, rom, host, image, scratch, alone):
    """`dfu-client-board`: the board at rest asked into its bootloader (`device bootloader`), then pydfuutil over
    USB/IP to the ROM's DfuSe device as the harness's USB host enumerated it, on the emulator's clock: it lists it,
    writes `image`, reads it back and leaves DFU; the chip resets into the new program, which enumerates under the
    renamed product string and names the image's CRC-32C. Returns the flash it wrote (the sectors the image covers),
    which must equal what the same client wrote into the model alone (`alone`)."""
    from machine import SYSCLK

    before = _image_of(cli.run("device", "status", *port))
    settings = bytes(m.uc.mem_read(*SETTINGS_SPAN))
    entries = len(rom.entries)
    asked = cli.run("device", "bootloader", *port)
    start = m.now
    while m.now - start < 2 * SYSCLK and not (host.configured and host.device[8:12] == bytes.fromhex("8304" "11df")):
        m.run(m.now + SYSCLK // 100)
    dfu = rom.dfu
    wire = HostOnWire(m, host)
    server = UsbipServer(wire.descriptors, wire.control)
    path, back = os.path.join(scratch, "board-image.bin"), os.path.join(scratch, "board-read-back.bin")
    with open(path, "wb") as f:
        f.write(image)
    listed, sim_list, _ = run_client(m, server.port, "-l")
    found = [line for line in listed.stdout.splitlines() if line.startswith("Found DFU: [0483:df11]")]
    wrote, sim_write, wall_write = run_client(m, server.port, "-a", "0", "-s", "0x08000000", "-D", path)
    end = sectors_end(image) - D.FLASH
    written = bytes(m.uc.mem_read(D.FLASH, end))
    read, sim_read, _ = run_client(m, server.port, "-a", "0", "-s", f"0x08000000:leave:{len(image)}", "-U", back)
    got = open(back, "rb").read() if os.path.exists(back) else b""
    wire.close()
    server.close()
    m.run(m.now + SYSCLK * 3 // 10)  # the reset, the new program's boot and enumeration
    after = _image_of(cli.run("device", "status", *port))
    kept = bytes(m.uc.mem_read(*SETTINGS_SPAN)) == settings
    product = host.strings.get(host.device[15]) if host.configured and host.device else None
    erased = list(dfu.erased) if dfu else []
    want = covered(image)
    same = alone is not None and written == alone[:end]
    crc = f"{crc32c(image):08x}"
    checks.check("dfu-client-board", asked.code == 0 and len(rom.entries) == entries + 1 and len(found) == 4
                 and wrote.returncode == 0 and erased == want and same and read.returncode == 0 and got == image
                 and after is not None and after.get("crc32c") == crc and after.get("size") == len(image)
                 and before is not None and before.get("crc32c") != crc and product == RENAMED.decode() and kept
                 and not server.errors,
                 f"{asked}; pydfuutil over USB/IP to the ROM's device on the emulated bus: `-l` exit "
                 f"{listed.returncode} ({sim_list:.2f} simulated s), {len(found)} alternate settings of 0483:df11; "
                 f"`-D` exit {wrote.returncode} after {sim_write:.1f} simulated s ({wall_write:.0f} wall s): sectors "
                 f"erased {[hex(a) for a in erased]} (want {[hex(a) for a in want]}), "
                 f"{dfu.written if dfu else 0:,} B programmed, {dfu.early_polls if dfu else '-'} polls before their "
                 f"timeout; flash 0x08000000..{D.FLASH + end:#010x} the same as the client wrote into the model alone "
                 f"(`dfu-client`): {same}; `-U` and leave exit {read.returncode} ({sim_read:.2f} simulated s): the "
                 f"same bytes read back: {got == image}; the program that started: USB product {product!r}, image "
                 f"{after} (CRC-32C of the image {crc}; before: {before}); sectors 6-7 (the settings) unchanged: "
                 f"{kept}; {server.urbs} URBs"
                 + "".join(f"; {r.stderr.strip().splitlines()[-1]}" for r in (listed, wrote, read)
                           if r.returncode and r.stderr.strip()))
    return written


def _image_of(status):
    import json

    try:
        return json.loads(status.stdout)["firmware"]["image"]
    except (ValueError, KeyError, TypeError):
        return None
