"""A clock and an interrupt line recorder for the model tests."""


class Clock:
    def __init__(self):
        self.now = 0

    def __call__(self):
        return self.now


class Lines:
    def __init__(self):
        self.pended = []

    def __call__(self, irq):
        self.pended.append(irq)


class Memory:
    """A flat byte store standing in for the bus."""

    def __init__(self):
        self.mem = {}
        self.words = {}  # peripheral address -> words written in bulk

    def read(self, addr, size):
        return int.from_bytes(bytes(self.mem.get(addr + i, 0) for i in range(size)), "little")

    def write(self, addr, size_or_data, value=None):
        data = bytes(size_or_data) if value is None else value.to_bytes(size_or_data, "little")
        for i, b in enumerate(data):
            self.mem[addr + i] = b

    def read_words(self, addr, n):
        return [self.read(addr + 4 * i, 4) for i in range(n)]

    def write_words(self, addr, words):
        self.words.setdefault(addr, []).extend(words)
