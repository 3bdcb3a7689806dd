import struct
import unittest

from models import dfuse_rom as D
from models.dfuse_rom import DfuseRom
from tests.helpers import Clock

HZ = 96_000_000


class Host:
    """Control transfers to the model as the harness's host makes them (SETUP, data packets, status)."""

    def __init__(self, rom, clock):
        self.rom, self.clock = rom, clock

    def control(self, rt, req, value, index=0, length=0, data=b""):
        setup = struct.pack("<BBHHH", rt, req, value, index, length or len(data))
        assert self.rom.setup(self.rom.address, setup) == "ACK"
        if rt & 0x80:
            got = b""
            while True:
                packet = self.rom.in_(self.rom.address, 0)
                if packet == "STALL":
                    return "STALL"
                got += packet
                if len(packet) < 64 or len(got) >= length:
                    break
            assert self.rom.out(self.rom.address, 0, b"") == "ACK"
            return got
        for i in range(0, len(data), 64):
            assert self.rom.out(self.rom.address, 0, data[i:i + 64]) == "ACK"
        return self.rom.in_(self.rom.address, 0)

    def status(self):
        raw = self.control(0xA1, 3, 0, length=6)
        return raw[0], int.from_bytes(raw[1:4], "little"), raw[4]

    def settle(self):
        while True:
            status, poll, state = self.status()
            if state != D.DNBUSY:
                return status, state
            self.clock.now += poll * HZ // 1000

    def command(self, cmd, address):
        assert self.control(0x21, 1, 0, data=bytes([cmd]) + struct.pack("<I", address)) == b""
        return self.settle()


def rom():
    flash = bytearray(b"\xff" * (512 * 1024))
    clock = Clock()
    left = []

    def read(at, n):
        return bytes(flash[at - D.FLASH:at - D.FLASH + n])

    def write(at, data):
        flash[at - D.FLASH:at - D.FLASH + len(data)] = data

    r = DfuseRom(clock, HZ, read, write, leave=left.append)
    return r, Host(r, clock), flash, clock, left


class DfuseRomTest(unittest.TestCase):
    def test_descriptors_name_the_bootloader_and_the_f411_sectors(self):
        r, host, _, _, _ = rom()
        device = host.control(0x80, 6, 0x0100, length=18)
        self.assertEqual(struct.unpack_from("<HH", device, 8), (0x0483, 0xDF11))
        config = host.control(0x80, 6, 0x0200, length=255)
        self.assertEqual(struct.unpack_from("<H", config, 2)[0], len(config))
        # four alternate settings of interface 0 in DFU mode, then the DfuSe functional descriptor
        alts = [config[i:i + 9] for i in range(9, 9 + 36, 9)]
        self.assertEqual([(a[2], a[3], a[5], a[6], a[7]) for a in alts], [(0, n, 0xFE, 1, 2) for n in range(4)])
        functional = config[45:54]
        self.assertEqual(struct.unpack("<BBBHHH", functional), (9, 0x21, 0x0B, 255, 2048, 0x011A))
        layout = host.control(0x80, 6, 0x0304, 0x0409, 255)
        self.assertEqual(layout[2:].decode("utf-16-le"), "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg")

    def test_erase_write_read_back_and_leave(self):
        r, host, flash, clock, left = rom()
        flash[0x4_0000:0x4_0010] = b"\x3c" * 16  # the settings' sector holds a record
        flash[0x0:0x10] = b"\x00" * 16  # an old program
        self.assertEqual(host.command(0x41, 0x0800_0000), (0, D.DNLOAD_IDLE))
        self.assertEqual(r.early_polls, 0)
        self.assertGreaterEqual(clock.now, 500 * HZ // 1000, "a 16 KiB sector: 500 ms")
        self.assertEqual(flash[:16], b"\xff" * 16)
        image = bytes(range(256)) * 12  # 3,072 B: two blocks
        self.assertEqual(host.command(0x21, 0x0800_0000), (0, D.DNLOAD_IDLE))
        for block, at in ((2, 0), (3, 2048)):
            self.assertEqual(host.control(0x21, 1, block, data=image[at:at + 2048]), b"")
            self.assertEqual(host.settle(), (0, D.DNLOAD_IDLE))
        self.assertEqual(bytes(flash[:len(image)]), image)
        self.assertEqual(bytes(flash[0x4_0000:0x4_0010]), b"\x3c" * 16, "sector 6 untouched")
        # read back: the pointer, ABORT to dfuIDLE, uploads from block 2
        host.command(0x21, 0x0800_0000)
        self.assertEqual(host.control(0x21, 6, 0), b"")
        self.assertEqual(host.control(0xA1, 2, 2, length=2048) + host.control(0xA1, 2, 3, length=1024), image)
        # leave: the pointer, a zero-length download, GETSTATUS: gone from the bus
        host.control(0x21, 6, 0)
        host.command(0x21, 0x0800_0000)
        self.assertEqual(host.control(0x21, 1, 2), b"")
        self.assertEqual(host.status()[2], D.MANIFEST)
        self.assertEqual(left, [0x0800_0000])
        self.assertFalse(r.attached())

    def test_programming_clears_bits_only_and_early_polls_are_counted(self):
        r, host, flash, clock, _ = rom()
        flash[0:4] = b"\x0f\x0f\x0f\x0f"  # not erased
        host.command(0x21, 0x0800_0000)
        host.control(0x21, 1, 2, data=b"\xf0\xff\xff\xff")
        self.assertEqual(host.status()[2], D.DNBUSY)
        self.assertEqual(host.status()[2], D.DNBUSY, "polled before its timeout: still busy")
        self.assertEqual(r.early_polls, 1)
        host.settle()
        self.assertEqual(bytes(flash[0:4]), b"\x00\x0f\x0f\x0f")

    def test_a_request_out_of_state_stalls_and_is_cleared(self):
        r, host, flash, clock, _ = rom()
        self.assertEqual(host.control(0xA1, 2, 0, length=64), "STALL", "upload block 0 is no read")
        self.assertEqual(host.status()[:1] + host.status()[2:], (D.ERR_STALLEDPKT, D.ERROR))
        self.assertEqual(host.control(0x21, 4, 0), b"")
        self.assertEqual(host.status(), (0, 0, D.DFU_IDLE))
        self.assertEqual(host.command(0x41, 0x0900_0000), (D.ERR_ADDRESS, D.ERROR))


if __name__ == "__main__":
    unittest.main()
