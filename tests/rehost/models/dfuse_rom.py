"""The STM32F411's ROM bootloader as the USB host sees it: a DfuSe device (0483:df11) at the packet level of the
harness's host (`setup`, `out`, `in_`, as `otg.OtgFs` offers them), written from AN2606 (the F411's bootloader),
AN3156 (its USB DFU protocol) and UM0424 (DfuSe).

- Descriptors: device 0483:df11 bcdDevice 0x2200, one configuration whose interface 0 has four alternate settings
  (class 0xFE, subclass 1, protocol 2: DFU mode), each named by its memory's layout string (internal flash with the
  F411's sectors, option bytes, OTP, device feature), and the DFU functional descriptor (DfuSe 1.1a, transfer size
  2048, download and upload, will detach).
- DFU 1.1 requests on interface 0: DNLOAD (block 0: the DfuSe commands Set Address Pointer 0x21 and Erase 0x41;
  block >= 2: `pointer + (block - 2) x 2048`), UPLOAD (block >= 2), GETSTATUS with the poll timeout of the operation
  the download started (a sector erase as the datasheet's maximum: 500 ms for 16 KiB, 1,100 ms for 64 KiB,
  2,000 ms for 128 KiB; a write 16 us a word), the operation carried out once the poll timeout has passed (a
  GETSTATUS before then answers busy and is counted), CLRSTATUS, GETSTATE, ABORT; anything out of its state stalls
  and goes to dfuERROR.
- Flash through `read(address, n)` and `write(address, data)` (the machine's flash array): erased cells read 0xFF
  and programming only clears bits. Leave (a zero-length download, then GETSTATUS): `leave(address)` is called,
  the harness resets the chip into the new program.
"""

import struct

FLASH = 0x0800_0000
TRANSFER = 2048
SECTORS = [(FLASH + a, s) for a, s in ((0, 16), (0x4000, 16), (0x8000, 16), (0xC000, 16), (0x1_0000, 64),
                                       (0x2_0000, 128), (0x4_0000, 128), (0x6_0000, 128))]
SECTORS = [(a, s * 1024) for a, s in SECTORS]
ERASE_MS = {16 * 1024: 500, 64 * 1024: 1_100, 128 * 1024: 2_000}  # datasheet t_ERASE16KB/64KB/128KB, x32, max
LAYOUTS = ["@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg", "@Option Bytes  /0x1FFFC000/01*016 e",
           "@OTP Memory /0x1FFF7800/01*512 e,01*016 e", "@Device Feature/0xFFFF0000/01*004 e"]
STRINGS = {1: "STMicroelectronics", 2: "STM32  BOOTLOADER", 3: "357A35523335"}
# DFU 1.1 6.1.2: states; table 6.1: statuses
APP_IDLE, DFU_IDLE, DNLOAD_SYNC, DNBUSY, DNLOAD_IDLE, MANIFEST, UPLOAD_IDLE, ERROR = 0, 2, 3, 4, 5, 7, 9, 10
OK, ERR_TARGET, ERR_ADDRESS, ERR_STALLEDPKT = 0x00, 0x01, 0x08, 0x0F


def _string(text):
    raw = text.encode("utf-16-le")
    return bytes([len(raw) + 2, 3]) + raw


def descriptors():
    """(device, configuration) descriptors."""
    device = struct.pack("<BBHBBBBHHHBBBB", 18, 1, 0x0200, 0, 0, 0, 64, 0x0483, 0xDF11, 0x2200, 1, 2, 3, 1)
    body = b""
    for alt in range(len(LAYOUTS)):
        body += struct.pack("<BBBBBBBBB", 9, 4, 0, alt, 0, 0xFE, 1, 2, 4 + alt)
    body += struct.pack("<BBBHHH", 9, 0x21, 0x0B, 255, TRANSFER, 0x011A)
    config = struct.pack("<BBHBBBBB", 9, 2, 9 + len(body), 1, 1, 0, 0xC0, 50) + body
    return device, config


class DfuseRom:
    def __init__(self, clock, hz, read, write, leave=lambda address: None):
        self.clock, self.hz = clock, hz
        self.read, self.write = read, write
        self.on_leave = leave
        self.on = True  # the D+ pull-up: the ROM attaches once started
        self.device, self.config = descriptors()
        self.address = 0
        self.state, self.status = DFU_IDLE, OK
        self.pointer = FLASH
        self.pending = None  # the operation a download started
        self.busy_until = 0
        self.alt = 0
        self.erased = []  # sector start addresses, in order
        self.written = 0  # bytes programmed
        self.early_polls = 0
        self.requests = []  # (bmRequestType, bRequest, wValue) of every SETUP
        self._setup = None
        self._in = b""
        self._out = bytearray()
        self._leaving = False

    # -- the bus side (the harness's host) --
    def attached(self):
        return self.on

    def bus_reset(self):
        self.address = 0

    def enumerated(self):
        pass

    def sof(self):
        pass

    def setup(self, addr, packet):
        if not self.on or addr != self.address:
            return None
        rt, req, value, index, length = struct.unpack("<BBHHH", packet)
        self.requests.append((rt, req, value))
        self._setup = (rt, req, value, index, length)
        self._out = bytearray()
        self._in = None
        if rt & 0x80:
            self._in = self._control_in(rt, req, value, index, length)
        return "ACK"

    def out(self, addr, ep, data):
        if not self.on or addr != self.address or ep != 0 or self._setup is None:
            return None
        rt, req, value, index, length = self._setup
        if rt & 0x80:  # the status stage of an IN transfer
            self._setup = None
            if self._leaving:
                self.on = False
                self.on_leave(self.pointer)
            return "ACK"
        self._out += data
        return "ACK"

    def in_(self, addr, ep):
        if not self.on or addr != self.address or ep != 0 or self._setup is None:
            return None
        rt, req, value, index, length = self._setup
        if rt & 0x80:
            if self._in is None:
                return "STALL"
            packet, self._in = self._in[:64], self._in[64:]
            return packet
        # the status stage of an OUT transfer: the request is carried out now, with its data
        self._setup = None
        ok = self._control_out(rt, req, value, bytes(self._out[:length]))
        return b"" if ok else "STALL"

    # -- standard requests --
    def _control_in(self, rt, req, value, index, length):
        if rt == 0x80 and req == 6:  # GET_DESCRIPTOR
            kind, n = value >> 8, value & 0xFF
            if kind == 1:
                return self.device[:length]
            if kind == 2:
                return self.config[:length]
            if kind == 3:
                if n == 0:
                    return bytes([4, 3, 0x09, 0x04])[:length]
                text = STRINGS.get(n) or (LAYOUTS[n - 4] if 4 <= n < 4 + len(LAYOUTS) else None)
                return _string(text)[:length] if text else None
            return None
        if rt == 0xA1:
            return self._dfu_in(req, value, length)
        return None

    def _control_out(self, rt, req, value, data):
        if rt == 0x00 and req == 5:  # SET_ADDRESS: taken after the status stage
            self.address = value & 0x7F
            return True
        if rt == 0x00 and req == 9:  # SET_CONFIGURATION
            return value in (0, 1)
        if rt == 0x01 and req == 11:  # SET_INTERFACE
            if value >= len(LAYOUTS):
                return False
            self.alt = value
            return True
        if rt == 0x21:
            return self._dfu_out(req, value, data)
        return False

    # -- DFU --
    def _ms(self):
        return self.clock() * 1000 // self.hz

    def _fail(self, status):
        self.state, self.status, self.pending = ERROR, status, None
        return False

    def _dfu_out(self, req, block, data):
        if req == 1:  # DNLOAD
            if self.state not in (DFU_IDLE, DNLOAD_IDLE):
                return self._fail(ERR_STALLEDPKT)
            if not data:
                self.pending = ("leave", self.pointer)
            elif block == 0 and len(data) == 5 and data[0] in (0x21, 0x41):
                self.pending = ("address" if data[0] == 0x21 else "erase", struct.unpack_from("<I", data, 1)[0])
            elif block >= 2:
                self.pending = ("write", self.pointer + (block - 2) * TRANSFER, data)
            else:
                return self._fail(ERR_TARGET)
            self.state = DNLOAD_SYNC
            return True
        if req == 4:  # CLRSTATUS
            self.state, self.status = DFU_IDLE, OK
            return True
        if req == 6:  # ABORT
            if self.state in (DNLOAD_SYNC, DNBUSY):
                return False
            self.state = DFU_IDLE
            return True
        return self._fail(ERR_STALLEDPKT)

    def _dfu_in(self, req, block, length):
        if req == 3:  # GETSTATUS
            return self._status()[:length]
        if req == 5:  # GETSTATE
            return bytes([self.state])
        if req == 2:  # UPLOAD
            if self.state not in (DFU_IDLE, UPLOAD_IDLE) or block < 2:
                self._fail(ERR_STALLEDPKT)
                return None
            at = self.pointer + (block - 2) * TRANSFER
            if not FLASH <= at < FLASH + 512 * 1024:
                self._fail(ERR_ADDRESS)
                return None
            self.state = UPLOAD_IDLE
            return self.read(at, length)
        return None

    def _poll_ms(self, op):
        if op[0] == "erase":
            sector = next((s for s in SECTORS if s[0] <= op[1] < s[0] + s[1]), None)
            return ERASE_MS[sector[1]] if sector else 1
        if op[0] == "write":
            us = len(op[2]) // 4 * 16  # t_PROG: 16 us a word
            return max(1, -(-us // 1000))
        return 1

    def _status(self):
        poll = 0
        if self.state == DNLOAD_SYNC and self.pending and self.pending[0] == "leave":
            # UM0424 6.1.4: the device manifests: it answers this request, then leaves the bus
            self.state, self.pending, self._leaving = MANIFEST, None, True
        elif self.state == DNLOAD_SYNC:
            poll = self._poll_ms(self.pending)
            self.busy_until = self._ms() + poll
            self.state = DNBUSY
        elif self.state == DNBUSY and self._ms() < self.busy_until:
            self.early_polls += 1
            poll = self.busy_until - self._ms()
        elif self.state == DNBUSY:
            op, self.pending = self.pending, None
            self.state = DNLOAD_IDLE
            self._carry_out(op)
        return struct.pack("<B", self.status) + poll.to_bytes(3, "little") + bytes([self.state, 0])

    def _carry_out(self, op):
        if op[0] == "address":
            self.pointer = op[1]
        elif op[0] == "erase":
            sector = next((s for s in SECTORS if s[0] <= op[1] < s[0] + s[1]), None)
            if sector is None:
                self._fail(ERR_ADDRESS)
                return
            self.write(sector[0], b"\xff" * sector[1])
            self.erased.append(sector[0])
        elif op[0] == "write":
            at, data = op[1], op[2]
            if not (FLASH <= at and at + len(data) <= FLASH + 512 * 1024):
                self._fail(ERR_ADDRESS)
                return
            old = self.read(at, len(data))
            self.write(at, bytes(a & b for a, b in zip(old, data)))
            self.written += len(data)
