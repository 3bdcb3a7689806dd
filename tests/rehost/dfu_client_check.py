"""The ROM bootloader's model checked against a published DfuSe client, and the image `ringpod flash` writes in the
run.

`dfu-client`: pydfuutil (a Python port of dfu-util, on PyPI, pinned in requirements.txt) is run as its own command
line (`dfu_client.py`) against `models/dfuse_rom.py` over USB/IP (`usbip.py`), on the wall clock, outside the
emulated chip: it lists the device (0483:df11, each alternate setting's memory layout string), writes the image
(`-s 0x08000000 -D`: the sectors it covers erased as the layout string says, the blocks written), and reads it back
(`-U`), then leaves DFU (`:leave`). The flash it leaves is kept: `flash-usb` compares what `ringpod flash` writes
into the emulated board with it, byte for byte.

The image is the release ELF with its USB product string changed at the same length (`renamed_elf`): every address
stays, so that the harness's probes, which follow the ELF's symbols, still hold after it is flashed, while the
image's bytes, and so its CRC-32C, differ from the program the run started with, and the new program tells itself
apart when it enumerates.
"""

import os
import random
import re
import struct
import subprocess
import sys
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
