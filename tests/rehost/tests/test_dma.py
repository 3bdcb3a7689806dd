import unittest

from models import dma as D
from tests.helpers import Lines, Memory

BSRR = 0x4002_0418


def stream5(mem, n=8, cr_extra=D.HTIE | D.TCIE | D.CIRC):
    lines = Lines()
    dma = D.Dma("dma2", mem, lines, [56, 57, 58, 59, 60, 68, 69, 70])
    for i in range(n):
        mem.write(0x2000_0000 + 4 * i, 4, i + 1)
    base = 0x10 + 5 * 0x18
    dma.write(base + 4, 4, n)  # NDTR
    dma.write(base + 8, 4, BSRR)  # PAR
    dma.write(base + 12, 4, 0x2000_0000)  # M0AR
    cr = (6 << 25) | (2 << 13) | (2 << 11) | D.MINC | (1 << 6) | cr_extra | D.EN
    dma.write(base, 4, cr)
    return dma, lines


class DmaTest(unittest.TestCase):
    def test_moves_one_word_per_request_of_its_channel(self):
        mem = Memory()
        dma, _ = stream5(mem)
        dma.request(5, 6, 3)
        self.assertEqual(mem.words[BSRR], [1, 2, 3])
        self.assertEqual(dma.read(0x10 + 5 * 0x18 + 4, 4), 5)  # NDTR counts down
        dma.request(5, 7, 3)  # another channel's request: ignored
        self.assertEqual(len(mem.words[BSRR]), 3)

    def test_half_and_complete_flags_and_circular_reload(self):
        mem = Memory()
        dma, lines = stream5(mem)
        self.assertEqual(dma.horizon(5), 4)
        dma.request(5, 6, 4)
        self.assertEqual(dma.read(D.Dma.HISR, 4) >> 6 & 0x3D, D.HTIF)  # stream 5 flags start at bit 6
        self.assertEqual(lines.pended, [68])
        dma.request(5, 6, 6)  # through the end: TC, reload, and on
        self.assertEqual(dma.read(D.Dma.HISR, 4) >> 6 & D.TCIF, D.TCIF)
        self.assertEqual(mem.words[BSRR], [1, 2, 3, 4, 5, 6, 7, 8, 1, 2])
        self.assertEqual(dma.read(0x10 + 5 * 0x18 + 4, 4), 6)
        dma.write(D.Dma.HIFCR, 4, (D.TCIF | D.HTIF) << 6)
        self.assertEqual(dma.read(D.Dma.HISR, 4), 0)

    def test_stream_4_is_the_low_bits_of_hisr(self):
        mem = Memory()
        dma, _ = stream5(mem)
        dma.streams[4].flags = D.TCIF
        self.assertEqual(dma.read(D.Dma.HISR, 4) & 0x3F, D.TCIF)
        self.assertEqual(dma.read(D.Dma.LISR, 4), 0)

    def test_normal_mode_stops_at_the_end(self):
        mem = Memory()
        dma, _ = stream5(mem, n=2, cr_extra=D.TCIE)
        dma.request(5, 6, 5)
        self.assertEqual(mem.words[BSRR], [1, 2])
        self.assertFalse(dma.read(0x10 + 5 * 0x18, 4) & D.EN)

    def test_config_is_read_only_while_enabled(self):
        mem = Memory()
        dma, _ = stream5(mem)
        dma.write(0x10 + 5 * 0x18 + 8, 4, 0x1234)
        self.assertEqual(dma.streams[5].par, BSRR)


if __name__ == "__main__":
    unittest.main()
