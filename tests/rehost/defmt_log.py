"""The firmware's defmt log, read as a debug probe would: from the RTT up buffer (`_SEGGER_RTT`, channel 0),
with the harness acting as the host that advances the read offset. Frames are rzcobs-encoded and 0-terminated;
each starts with the index of its format string, whose text and level are the name of a symbol in the ELF's
`.defmt` section. The timestamp and top-level integer arguments are decoded; nested `Format` values are shown
as `…`."""

import json
import re
import struct

from elftools.elf.elffile import ELFFile

_PARAM = re.compile(r"\{\{|\}\}|\{(?:=([^}:]*))?(?::[^}]*)?\}")
_INTS = {"u8": "<B", "i8": "<b", "u16": "<H", "i16": "<h", "u32": "<I", "i32": "<i", "u64": "<Q", "i64": "<q",
         "f32": "<f"}


def rzcobs_decode(data):
    """rzcobs (reverse zero-compressing COBS), as the defmt decoder undoes it."""
    out = []
    it = iter(reversed(data))
    for x in it:
        if x == 0:
            raise ValueError("zero inside a frame")
        if x < 0x80:
            for i in range(7):
                out.append(next(it) if not x & (1 << (6 - i)) else 0)
        elif x < 0xFF:
            out.append(0)
            out.extend(next(it) for _ in range((x & 0x7F) + 7))
        else:
            out.extend(next(it) for _ in range(134))
    out.reverse()
    return bytes(out)


class DefmtLog:
    def __init__(self, machine):
        self.m = machine
        self.rtt = machine.elf.address("_SEGGER_RTT")
        self.table = {}
        with open(machine.elf.path, "rb") as f:
            for sym in ELFFile(f).get_section_by_name(".symtab").iter_symbols():
                if sym.name.startswith('{"package"'):
                    self.table[sym["st_value"]] = json.loads(sym.name)
        self.pending = b""
        self.lines = []  # (time in cycles, level, text)

    def poll(self):
        uc = self.m.uc
        hdr = bytes(uc.mem_read(self.rtt, 48))
        if not hdr.startswith(b"SEGGER RTT"):
            return  # not initialised yet (or being initialised after a reset)
        _name, buf, size, wr, rd, _flags = struct.unpack("<6I", hdr[24:48])
        if wr == rd or size == 0 or wr >= size or rd >= size:
            return
        if wr > rd:
            data = bytes(uc.mem_read(buf + rd, wr - rd))
        else:
            data = bytes(uc.mem_read(buf + rd, size - rd)) + bytes(uc.mem_read(buf, wr))
        uc.mem_write(self.rtt + 40, struct.pack("<I", wr))  # the host read it all
        *frames, self.pending = (self.pending + data).split(b"\0")
        for frame in filter(None, frames):
            self.lines.append((self.m.now,) + self._decode(frame))

    def _decode(self, frame):
        try:
            data = rzcobs_decode(frame)
            entry = self.table[int.from_bytes(data[:2], "little")]
        except (ValueError, KeyError, StopIteration):
            return "?", f"undecodable frame {frame.hex()}"
        level = entry["tag"].removeprefix("defmt_")
        data = data[2:]
        stamp, data = (struct.unpack("<Q", data[:8])[0], data[8:]) if len(data) >= 8 else (None, data)
        return level, (f"{stamp / 1000:.3f} ms " if stamp is not None else "") + self._format(entry["data"], data)

    def _format(self, fmt, data):
        out, pos, i = [], 0, 0
        for m in _PARAM.finditer(fmt):
            out.append(fmt[pos : m.start()])
            pos = m.end()
            if m.group(0) in ("{{", "}}"):
                out.append(m.group(0)[0])
                continue
            kind = m.group(1) or "?"
            if kind == "?" and i + 2 <= len(data):
                nested = self.table.get(int.from_bytes(data[i : i + 2], "little"), {}).get("data", "")
                inner = re.fullmatch(r"\{=(\w+)\}", nested)
                if inner and inner.group(1) in _INTS:  # a primitive's Format impl: its own `{=u32}`
                    kind, i = inner.group(1), i + 2
            if kind in _INTS and i + struct.calcsize(_INTS[kind]) <= len(data):
                (value,) = struct.unpack_from(_INTS[kind], data, i)
                i += struct.calcsize(_INTS[kind])
                out.append(f"{value:g}" if kind == "f32" else str(value))
            else:
                out.append("…")
                out.append(_PARAM.sub("…", fmt[pos:]).replace("{{", "{").replace("}}", "}"))
                return "".join(out)
        out.append(fmt[pos:])
        return "".join(out)
