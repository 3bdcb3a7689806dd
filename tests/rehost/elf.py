"""What the harness reads from the release ELF: symbols (legacy Rust mangling undone), the loadable segments,
and the addresses of WFE/WFI/SEV instructions."""

import re

from elftools.elf.elffile import ELFFile

_ESCAPES = {"$LT$": "<", "$GT$": ">", "$RF$": "&", "$BP$": "*", "$C$": ",", "$u20$": " ", "$u7b$": "{",
            "$u7d$": "}", "$u5b$": "[", "$u5d$": "]", "$u27$": "'", "$u3b$": ";", "$u7e$": "~", "$SP$": "@"}


def demangle(name):
    """Rust's legacy mangling (`_ZN...E` with a trailing `17h<hash>`), enough to match paths by name."""
    if not name.startswith("_ZN"):
        return name
    parts, i = [], 3
    while i < len(name) and name[i] != "E":
        m = re.match(r"\d+", name[i:])
        if not m:
            return name
        n = int(m.group())
        i += len(m.group())
        part = name[i : i + n]
        parts.append(part[1:] if part.startswith("_$") else part)  # `_` guards an identifier starting with `$`
        i += n
    if parts and re.fullmatch(r"h[0-9a-f]{16}", parts[-1]):
        parts.pop()
    text = "::".join(parts)
    for k, v in _ESCAPES.items():
        text = text.replace(k, v)
    return text.replace("..", "::")


class Elf:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            elf = ELFFile(f)
            self.segments = [(s["p_paddr"], s.data()) for s in elf.iter_segments() if s["p_type"] == "PT_LOAD"]
            self.symbols = []  # (demangled, address, size, raw)
            for sym in elf.get_section_by_name(".symtab").iter_symbols():
                if sym.name and sym["st_info"]["type"] in ("STT_FUNC", "STT_OBJECT", "STT_NOTYPE"):
                    self.symbols.append((demangle(sym.name), sym["st_value"], sym["st_size"], sym.name))
            text = elf.get_section_by_name(".text")
            self.text_addr, self.text = text["sh_addr"], text.data()

    def find(self, pattern):
        """Symbols whose demangled name matches the regular expression."""
        rx = re.compile(pattern)
        return [(name, addr, size) for name, addr, size, _ in self.symbols if rx.search(name)]

    def one(self, pattern):
        found = self.find(pattern)
        if len(found) != 1:
            raise KeyError(f"{pattern!r} names {len(found)} symbols")
        return found[0]

    def address(self, name):
        for n, addr, _size, raw in self.symbols:
            if n == name or raw == name:
                return addr
        raise KeyError(name)

    def hint_sites(self, opcode):
        """Addresses of every half-word equal to a 16-bit Thumb hint (WFE 0xBF20, WFI 0xBF30, SEV 0xBF40).

        A half-word inside a 32-bit instruction or a literal is listed too: a hook there never fires."""
        return [self.text_addr + i for i in range(0, len(self.text) - 1, 2)
                if self.text[i] == opcode & 0xFF and self.text[i + 1] == opcode >> 8]


def memory_x(path):
    """ORIGIN and LENGTH of each region of a linker script's MEMORY block."""
    units = {"K": 1024, "M": 1024 * 1024, "": 1}
    regions = {}
    for name, origin, length, unit in re.findall(
        r"(\w+)\s*(?:\([^)]*\))?\s*:\s*ORIGIN\s*=\s*(0x[0-9A-Fa-f_]+|\d+)\s*,\s*LENGTH\s*=\s*(0x[0-9A-Fa-f]+|\d+)\s*([KM]?)",
        open(path).read(),
    ):
        regions[name] = (int(origin.replace("_", ""), 0), int(length, 0) * units[unit])
    return regions
