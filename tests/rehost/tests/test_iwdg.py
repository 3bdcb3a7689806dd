import unittest

from models.iwdg import Iwdg
from tests.helpers import Clock

MS = 96_000


class IwdgTest(unittest.TestCase):
    def setUp(self):
        self.clock = Clock()
        self.timeouts = []
        self.w = Iwdg(self.clock, self.timeouts.append)

    def configure(self, pr, rlr):
        # board::watchdog::set: wait for PVU/RVU, unlock, PR, RLR, reload
        self.w.write(Iwdg.KR, 4, 0x5555)
        self.w.write(Iwdg.PR, 4, pr)
        self.w.write(Iwdg.RLR, 4, rlr)
        self.assertEqual(self.w.read(Iwdg.SR, 4), 3)  # PVU, RVU busy
        self.clock.now += self.w.update_time()
        self.assertEqual(self.w.read(Iwdg.SR, 4), 0)
        self.w.write(Iwdg.KR, 4, 0xAAAA)

    def test_default_timeout_is_512_ms(self):
        self.w.write(Iwdg.KR, 4, 0xCCCC)
        self.assertEqual(self.w.deadline(), 4095 * 4 * 3000)  # 4095 counts of 4/32 kHz

    def test_fed_watchdog_does_not_reset_and_starved_one_does(self):
        self.w.write(Iwdg.KR, 4, 0xCCCC)
        self.configure(6, 6)  # /256, 6 counts: 48 ms
        for _ in range(100):
            self.clock.now += MS
            self.w.advance(self.clock.now)
            self.w.write(Iwdg.KR, 4, 0xAAAA)
        self.assertEqual(self.timeouts, [])
        last = self.clock.now
        self.clock.now += 100 * MS
        self.w.advance(self.clock.now)
        self.assertEqual(self.timeouts, [last + 48 * MS])

    def test_a_reload_that_ends_a_configuration_is_told_apart(self):
        self.w.write(Iwdg.KR, 4, 0xCCCC)
        self.configure(6, 6)
        self.w.write(Iwdg.KR, 4, 0xAAAA)
        self.w.write(Iwdg.KR, 4, 0xAAAA)
        self.assertEqual(len(self.w.reloads), 3)
        self.assertEqual(len(self.w.config_reloads), 1)

    def test_registers_are_protected_without_the_access_key(self):
        self.w.write(Iwdg.PR, 4, 6)
        self.assertEqual(self.w.read(Iwdg.PR, 4), 0)


if __name__ == "__main__":
    unittest.main()
