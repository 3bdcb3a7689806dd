import logging
import unittest

from models.gpio import BSRR, IDR, ODR, Gpio
from models.rcc import IWDGRSTF, PINRSTF, RMVF, Rcc


class FakeQl:
    log = logging.getLogger("fake-ql")


class GpioTest(unittest.TestCase):
    def test_bsrr_set_wins_over_reset(self):
        g = Gpio(FakeQl(), "gpiob")
        g.write(BSRR, 4, (1 << 16) | 1)
        self.assertEqual(g.read(ODR, 4), 1)

    def test_bulk_words_count_edges(self):
        g = Gpio(FakeQl(), "gpiob")
        g.bsrr_words([0b11, 0, 0b11 << 16, 0b01, 0])
        self.assertEqual(g.bsrr_writes, 5)
        self.assertEqual(g.edges(0, g.rises), 2)
        self.assertEqual(g.edges(1, g.rises), 1)
        self.assertEqual(g.edges(1, g.falls), 1)

    def test_inputs_read_their_pull_or_external_level(self):
        g = Gpio(FakeQl(), "gpioa")
        g.write(0x0C, 4, 0b01 << 2 | 0b10 << 4)  # PA1 pull-up, PA2 pull-down
        self.assertEqual(g.read(IDR, 4) & 0b110, 0b010)
        g.drive(1, 0)
        g.drive(2, 1)
        self.assertEqual(g.read(IDR, 4) & 0b110, 0b100)


    def test_an_output_drives_its_level_and_nothing_else_does(self):
        g = Gpio(FakeQl(), "gpiob")
        g.write(ODR, 4, 0b111)
        self.assertEqual([g.driven(p) for p in range(3)], [None] * 3)  # inputs after reset
        g.write(0x00, 4, 0b01 | 0b01 << 2 | 0b11 << 4)  # PB0, PB1 outputs, PB2 analog
        g.write(0x04, 4, 0b10)  # PB1 open drain
        self.assertEqual([g.driven(p) for p in range(3)], [1, None, None])
        g.write(ODR, 4, 0)
        self.assertEqual([g.driven(p) for p in range(3)], [0, 0, None])

    def test_a_floating_wired_input_is_counted_and_reads_low(self):
        g = Gpio(FakeQl(), "gpioa")
        g.wired.add(3)
        self.assertEqual(g.read(IDR, 4) >> 3 & 1, 0)
        self.assertEqual(g.floating_reads[3], 1)
        g.drive(3, 1)  # an external pull-up
        self.assertEqual(g.read(IDR, 4) >> 3 & 1, 1)
        g.drive(3, None)  # released
        g.write(0x0C, 4, 0b01 << 6)  # pull-up
        self.assertEqual(g.read(IDR, 4) >> 3 & 1, 1)
        self.assertEqual(g.floating_reads[3], 1)
        self.assertEqual(sum(g.floating_reads.values()), 1)  # unwired pins float uncounted

class RccTest(unittest.TestCase):
    def test_hse_ready_follows_hseon(self):
        r = Rcc(FakeQl(), "rcc")
        r.write(0x00, 4, r.read(0x00, 4) | (1 << 16))
        self.assertTrue(r.read(0x00, 4) & (1 << 17))

    def test_rmvf_clears_reset_flags(self):
        r = Rcc(FakeQl(), "rcc")
        r.set_reset_flags(IWDGRSTF | PINRSTF)
        self.assertTrue(r.read(0x74, 4) & IWDGRSTF)
        r.write(0x74, 4, r.read(0x74, 4) | RMVF)
        self.assertEqual(r.read(0x74, 4) & 0xFF00_0000, 0)

    def test_sysclk_from_the_pll(self):
        r = Rcc(FakeQl(), "rcc")
        r.instance.PLLCFGR = 25 | (384 << 6) | (1 << 16) | (1 << 22) | (8 << 24)
        r.instance.CFGR = 2 << 2
        self.assertEqual(r.sysclk_hz(), 96_000_000)


if __name__ == "__main__":
    unittest.main()
