"""A USB host on the OTG FS model's bus side: what a PC's host controller and its CDC-ACM driver do with the board.

On attach (the device's D+ pull-up, `OtgFs.attached`) it waits the 100 ms debounce (USB 2.0 7.1.7.3), drives a
10 ms bus reset, then enumerates as Linux does: GET_DESCRIPTOR device (64 bytes, address 0), SET_ADDRESS,
GET_DESCRIPTOR device, configuration (9 bytes, then wTotalLength), string 0 and the three strings,
SET_CONFIGURATION 1, then the CDC-ACM requests of a port being opened: SET_LINE_CODING and SET_CONTROL_LINE_STATE
(DTR and RTS). Then bulk transfers: OUT packets of up to the endpoint's max packet size from what the pty's client
wrote, IN tokens whose packets go to the pty (a short or zero-length packet ends a transfer).

Time: a frame (SOF) every simulated millisecond, split in eight slots of 125 us; a transaction the device NAKs is
retried in the next slot, as a host controller retries within the frame. Several transactions may complete in one
slot. Not modelled: the interrupt IN endpoint's polling (the firmware never sends a notification), babble, bit
errors and CRC retries, data toggles, bandwidth limits within a frame beyond the slots, suspend/resume by the host.
The class is USART-shaped (`feed`, `on_tx`) so that `serial_link.PtyBridge` bridges it to a pty unchanged.
"""

import struct

from machine import SYSCLK
from models.base import NEVER

FRAME = SYSCLK // 1000
SLOT = FRAME // 8
ADDRESS = 5
DEBOUNCE, RESET, RECOVERY = 100 * FRAME, 10 * FRAME, 10 * FRAME  # USB 2.0 7.1.7.3, 7.1.7.5, 9.2.6.2
CONTROL_TIMEOUT = 5 * SYSCLK  # Linux's USB_CTRL_GET_TIMEOUT
LINE_CODING = struct.pack("<IBBB", 921_600, 0, 0, 8)  # CDC PSTN 6.3.11: 921,600 baud, 1 stop bit, no parity, 8 bits


class UsbError(Exception):
    pass


class UsbHost:
    def __init__(self, otg, clock):
        self.dev, self.clock = otg, clock
        self.on_tx = None  # each byte the device sent on its bulk IN endpoint
        self.out = bytearray()  # bytes for the bulk OUT endpoint
        self.next_at = NEVER
        self.plugged = False
        self.task = None
        self.reset_state()
        self.log = []  # (time, what) of the bus: attaches, resets, enumerations, errors
        self.enumerations = 0
        self.in_sizes = {}  # bulk IN packet size -> count
        self.out_packets = 0
        self.stalls = []

    def reset_state(self):
        self.addr = 0
        self.configured = False
        self.device = self.config = None
        self.strings = {}
        self.ep_in = self.ep_out = None
        self.mps = 64
        self.sof_at = NEVER  # SOFs start with the first bus reset

    # -- the cable --
    def plug(self):
        self.plugged = True
        self.dev.vbus = True
        self.task = self._attach()
        self.next_at = self.clock()
        self.log.append((self.clock(), "plugged"))

    def unplug(self):
        """The cable pulled: VBUS low, no SOF; the device's core sees an idle bus (suspend)."""
        self.plugged = False
        self.dev.vbus = False
        self.dev.suspend()
        self.task = None
        self.reset_state()
        self.out.clear()
        self.next_at = NEVER
        self.log.append((self.clock(), "unplugged"))

    def feed(self, data):
        if self.plugged:  # bytes written to a port whose cable is out are lost with it
            self.out += data

    # -- the scheduler's interface --
    def advance(self, now):
        while self.next_at <= now:
            t = self.next_at
            self.next_at = t + SLOT
            self._slot(t)

    def next_event(self, now):
        return self.next_at

    def _slot(self, t):
        if self.configured and not self.dev.attached():
            self.log.append((t, "device detached"))
            self.reset_state()
            self.task = self._attach()
        if self.sof_at <= t:
            self.sof_at = t + FRAME
            self.dev.sof()
        if self.task is not None:
            try:
                wait = next(self.task)
            except StopIteration:
                self.task = None
                wait = 0
            except UsbError as e:
                self.log.append((t, f"error: {e}"))
                self.task = self._attach()
                wait = FRAME
            if wait:
                self.next_at = t + wait
            return
        if self.configured:
            self._bulk()

    # -- enumeration --
    def _attach(self):
        while not self.dev.attached():
            yield FRAME
        self.log.append((self.clock(), "attached"))
        yield DEBOUNCE
        yield from self._bus_reset()
        self.addr = 0
        self.device = yield from self.control(0x80, 6, 0x0100, 0, 64)
        yield from self._bus_reset()
        yield from self.control(0x00, 5, ADDRESS, 0)
        self.addr = ADDRESS
        yield 2 * FRAME  # USB 2.0 9.2.6.3: 2 ms for the address to take
        self.device = yield from self.control(0x80, 6, 0x0100, 0, 18)
        head = yield from self.control(0x80, 6, 0x0200, 0, 9)
        total = struct.unpack_from("<H", head, 2)[0]
        self.config = yield from self.control(0x80, 6, 0x0200, 0, total)
        langs = yield from self.control(0x80, 6, 0x0300, 0, 255)
        lang = struct.unpack_from("<H", langs, 2)[0] if len(langs) >= 4 else 0x0409
        self.strings = {0: langs}
        for index in self.device[14:17]:
            if index:
                raw = yield from self.control(0x80, 6, 0x0300 | index, lang, 255)
                self.strings[index] = raw[2:raw[0]].decode("utf-16-le", errors="replace")
        self._endpoints()
        yield from self.control(0x00, 9, 1, 0)
        comm = self.comm_interface()
        if comm is not None:  # a CDC-ACM port (not the ROM bootloader's DFU device)
            yield from self.control(0x21, 0x20, 0, comm, data=LINE_CODING)  # SET_LINE_CODING
            yield from self.control(0x21, 0x22, 0x0003, comm)  # SET_CONTROL_LINE_STATE: DTR and RTS
        self.configured = True
        self.enumerations += 1
        self.log.append((self.clock(), "configured"))

    def _bus_reset(self):
        self.log.append((self.clock(), "bus reset"))
        self.dev.bus_reset()
        yield RESET
        self.dev.enumerated()
        self.sof_at = self.clock()
        yield RECOVERY

    def control(self, request_type, request, value, index, length=0, data=b""):
        """One control transfer on endpoint 0: SETUP, the data stage, the status stage. Returns the IN data."""
        setup = struct.pack("<BBHHH", request_type, request, value, index, length or len(data))
        start = self.clock()
        yield from self._transact(lambda: self.dev.setup(self.addr, setup), start)
        got = bytearray()
        if request_type & 0x80:
            while True:
                packet = yield from self._transact(lambda: self.dev.in_(self.addr, 0), start, setup)
                got += packet
                if len(packet) < self.device_mps() or len(got) >= length:
                    break
            yield from self._transact(lambda: self.dev.out(self.addr, 0, b""), start, setup)
        else:
            for i in range(0, len(data), 64):
                yield from self._transact(lambda i=i: self.dev.out(self.addr, 0, data[i:i + 64]), start, setup)
            yield from self._transact(lambda: self.dev.in_(self.addr, 0), start, setup)
        return bytes(got)

    def _transact(self, fn, start, setup=b""):
        while True:
            r = fn()
            if r == "STALL":
                self.stalls.append(setup.hex())
                raise UsbError(f"STALL on control request {setup.hex()}")
            if r not in ("NAK", None):
                return r
            if self.clock() - start > CONTROL_TIMEOUT:
                raise UsbError(f"no answer within 5 s to control request {setup.hex()} ({r or 'no handshake'})")
            yield SLOT

    def device_mps(self):
        return self.device[7] if self.device and len(self.device) > 7 else 64  # Linux guesses 64 at full speed

    # -- the configuration descriptor --
    def descriptors(self):
        """The configuration descriptor split into its descriptors: (bDescriptorType, bytes)."""
        out, i, c = [], 0, self.config or b""
        while i + 2 <= len(c) and c[i]:
            out.append((c[i + 1], c[i:i + c[i]]))
            i += c[i]
        return out

    def comm_interface(self):
        for kind, d in self.descriptors():
            if kind == 4 and d[5:7] == b"\x02\x02":  # interface, CDC, ACM
                return d[2]
        return None

    def _endpoints(self):
        for kind, d in self.descriptors():
            if kind == 5 and d[3] & 3 == 2:  # a bulk endpoint
                if d[2] & 0x80:
                    self.ep_in = d[2] & 0xF
                else:
                    self.ep_out = d[2] & 0xF
                self.mps = struct.unpack_from("<H", d, 4)[0]

    # -- bulk transfers --
    def _bulk(self):
        if self.ep_out is None or self.ep_in is None:
            return
        while self.out:
            chunk = bytes(self.out[:self.mps])
            r = self.dev.out(self.addr, self.ep_out, chunk)
            if r != "ACK":
                if r == "STALL":
                    self.stalls.append(f"bulk OUT {self.ep_out}")
                break
            del self.out[:len(chunk)]
            self.out_packets += 1
        for _ in range(8):
            r = self.dev.in_(self.addr, self.ep_in)
            if not isinstance(r, bytes):
                if r == "STALL":
                    self.stalls.append(f"bulk IN {self.ep_in}")
                break
            self.in_sizes[len(r)] = self.in_sizes.get(len(r), 0) + 1
            if self.on_tx:
                for b in r:
                    self.on_tx(b)
