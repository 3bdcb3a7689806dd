"""`ringpod flash`'s way to the emulated board's ROM bootloader: the DfuSe device the harness's USB host enumerated
(`models/dfuse_rom.py`), served over TCP (`ringpod flash --dfu tcp://127.0.0.1:PORT`), one request a line, so that
the CLI's own DfuSe code drives the model through the host's control transfers, on the machine's clock:

    FIND                            -> NONE | FOUND <transfer size> <layout string of alternate setting 0>
    IN <request> <value> <length>   -> OK <hex> | STALL | GONE    (class request to interface 0, bmRequestType 0xA1)
    OUT <request> <value> <hex>     -> OK | STALL | GONE          (bmRequestType 0x21)
    SLEEP <ms>                      -> OK, once that much simulated time has passed

Polled between the machine's steps (an observer, once a simulated millisecond)."""

import socket
import struct

from machine import SYSCLK
from usb_host import UsbError

ROM_ID = (0x0483, 0xDF11)


class DfuBridge:
    def __init__(self, m, host):
        self.m, self.host = m, host
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(1)
        self.server.setblocking(False)
        self.address = "tcp://127.0.0.1:%d" % self.server.getsockname()[1]
        self.conn = None
        self.buf = b""
        self.busy = None  # the request in progress
        self.served = 0  # requests answered
        m.observers.append(self.poll)

    def _rom(self):
        d = self.host.device
        return self.host.configured and d is not None and len(d) >= 12 and struct.unpack_from("<HH", d, 8) == ROM_ID

    def _reply(self, text):
        try:
            self.conn.sendall(text.encode() + b"\n")
        except OSError:
            self.conn = None
        self.served += 1
        self.busy = None

    def poll(self):
        if self.conn is None:
            try:
                self.conn, _ = self.server.accept()
                self.conn.setblocking(False)
                self.buf = b""
            except (BlockingIOError, OSError):
                return
        if self.busy is not None:
            self._progress()
            return
        try:
            data = self.conn.recv(65536)
            if data == b"":
                self.conn = None
                return
            self.buf += data
        except (BlockingIOError, OSError):
            pass
        if b"\n" in self.buf:
            line, self.buf = self.buf.split(b"\n", 1)
            self._start(line.decode().split())

    def _control(self, rt, req, value, length=0, data=b"", then=None, index=0):
        result = {}

        def run():
            try:
                result["data"] = yield from self.host.control(rt, req, value, index, length, data)
            except UsbError as e:
                result["error"] = "STALL" if "STALL" in str(e) else "GONE"

        self.host.task = run()
        self.host.next_at = self.m.now
        self.busy = ("control", result, then)

    def _start(self, words):
        kind = words[0] if words else ""
        if kind == "SLEEP":
            self.busy = ("sleep", self.m.now + int(words[1]) * SYSCLK // 1000)
        elif not self._rom() or self.host.task is not None:
            self._reply("NONE" if kind == "FIND" else "GONE")
        elif kind == "FIND":
            # alternate setting 0's string (the internal flash) and the DFU functional descriptor's transfer size
            alt0 = next((d for k, d in self.host.descriptors() if k == 4 and d[3] == 0), None)
            func = next((d for k, d in self.host.descriptors() if k == 0x21), None)
            size = struct.unpack_from("<H", func, 5)[0] if func else 2048
            self._control(0x80, 6, 0x0300 | (alt0[8] if alt0 else 4), 255, index=0x0409,
                          then=lambda raw: f"FOUND {size} " + raw[2:raw[0]].decode("utf-16-le"))
        elif kind == "IN":
            self._control(0xA1, int(words[1]), int(words[2]), int(words[3]), then=lambda raw: "OK " + raw.hex())
        elif kind == "OUT":
            data = bytes.fromhex(words[3]) if len(words) > 3 else b""
            self._control(0x21, int(words[1]), int(words[2]), 0, data, then=lambda raw: "OK")
        else:
            self._reply("ERROR unknown request")

    def _progress(self):
        if self.busy[0] == "sleep":
            if self.m.now >= self.busy[1]:
                self._reply("OK")
            return
        _, result, then = self.busy
        if "error" in result:
            self._reply(result["error"])
        elif "data" in result:
            self._reply(then(result["data"]))
