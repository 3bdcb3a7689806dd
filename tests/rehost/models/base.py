"""A register block with 32-bit registers; byte and half-word accesses are folded into word accesses."""

NEVER = float("inf")


class Block:
    """Subclasses implement `read32(offset)` and `write32(offset, value)` on word-aligned offsets.

    A narrower write keeps the other bytes at what the register reads now (RM0383 ch. 2 and each register's description: the peripherals accept
    byte, half-word and word accesses); for write-1-to-clear registers, which read 0, that writes 0 there.
    """

    size = 0x400

    @property
    def region(self):
        return [(0, self.size)]

    def read(self, offset, size):
        word = self.read32(offset & ~3)
        shift = (offset & 3) * 8
        return (word >> shift) & ((1 << (size * 8)) - 1)

    def write(self, offset, size, value):
        if size == 4 and not offset & 3:
            self.write32(offset, value & 0xFFFFFFFF)
            return
        shift = (offset & 3) * 8
        mask = ((1 << (size * 8)) - 1) << shift
        cur = self.read32(offset & ~3)
        self.write32(offset & ~3, (cur & ~mask) | ((value << shift) & mask))

    def read32(self, offset):
        raise NotImplementedError

    def write32(self, offset, value):
        raise NotImplementedError

    # The scheduler's interface: bring the state up to `now`, and say when something next needs the CPU.
    def advance(self, now):
        pass

    def next_event(self, now):
        return NEVER
