import unittest

from models.flash import BSY, FLASH_BASE, LOCK, PG, SER, STRT, FlashInterface, sector_of
from tests.helpers import Clock, Memory


class FlashTest(unittest.TestCase):
    def setUp(self):
        self.mem = Memory()
        self.clock = Clock()
        self.f = FlashInterface(self.mem, self.clock, cycles_per_s=1000)

    def unlock(self):
        self.f.write(FlashInterface.KEYR, 4, 0x4567_0123)
        self.f.write(FlashInterface.KEYR, 4, 0xCDEF_89AB)

    def test_locked_until_the_key_sequence(self):
        self.f.write(FlashInterface.CR, 4, PG)
        self.assertEqual(self.f.read(FlashInterface.CR, 4), LOCK)
        self.unlock()
        self.f.write(FlashInterface.CR, 4, PG)
        self.assertEqual(self.f.read(FlashInterface.CR, 4), PG)

    def test_wrong_key_locks_until_reset(self):
        self.f.write(FlashInterface.KEYR, 4, 0x1234)
        self.unlock()
        self.assertTrue(self.f.read(FlashInterface.CR, 4) & LOCK)

    def test_sector_erase_fills_ff(self):
        self.unlock()
        self.f.write(FlashInterface.CR, 4, SER | (6 << 3) | STRT)
        self.assertEqual(self.f.erases, [6])
        self.assertEqual(self.mem.read(0x0804_0000, 4), 0xFFFFFFFF)
        self.assertEqual(self.mem.read(0x0805_FFFC, 4), 0xFFFFFFFF)
        self.assertNotIn(0x0806_0000, self.mem.mem)

    def test_a_128k_sector_erase_is_busy_for_2_s(self):
        # DS10314: t_ERASE128KB at x32 parallelism, 2 s maximum; BSY (FLASH_SR) reads 1 until then
        self.unlock()
        self.clock.now = 500
        self.f.write(FlashInterface.CR, 4, SER | (7 << 3) | STRT)
        self.assertEqual((self.f.busy_from, self.f.busy_until), (500, 2500))
        self.clock.now = 2499
        self.assertTrue(self.f.read(FlashInterface.SR, 4) & BSY)
        self.clock.now = 2500
        self.assertFalse(self.f.read(FlashInterface.SR, 4) & BSY)

    def test_program_only_clears_bits_and_needs_pg(self):
        old = b"\xff\xff\x0f\xff"
        self.assertEqual(self.f.cpu_write(0x0804_0000, 4, 0x12345678, old), old)  # locked: rejected
        self.unlock()
        self.f.write(FlashInterface.CR, 4, PG)
        self.assertEqual(self.f.cpu_write(0x0804_0000, 4, 0x12345678, old), bytes([0x78, 0x56, 0x04, 0x12]))
        self.assertEqual(self.f.programs, [(0x0804_0000, 4)])

    def test_sector_map(self):
        self.assertEqual(sector_of(FLASH_BASE), 0)
        self.assertEqual(sector_of(0x0801_0000), 4)
        self.assertEqual(sector_of(0x0804_0000), 6)
        self.assertEqual(sector_of(0x0807_FFFF), 7)
        self.assertIsNone(sector_of(0x0808_0000))


if __name__ == "__main__":
    unittest.main()
