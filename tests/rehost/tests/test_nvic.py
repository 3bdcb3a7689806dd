import unittest

from models.nvic import Nvic


class NvicTest(unittest.TestCase):
    def test_the_scb_between_its_windows_is_not_the_nvics(self):
        # PM0214 4.4: the SCB (ACTLR..., CPUID at 0xE000_ED00, AIRCR at ED0C) lies between IPR and STIR
        scb = [0xE000_ED00 - 0xE000_E100 + off for off in (0x00, 0x08, 0x0C, 0x18, 0x20)]
        for off in scb:
            self.assertFalse(any(lo <= off < hi for lo, hi in Nvic().region), hex(off))
        for off in (Nvic.ISER, Nvic.IPR + 239, Nvic.STIR):
            self.assertTrue(any(lo <= off < hi for lo, hi in Nvic().region), hex(off))

    def test_stir_pends_an_interrupt(self):
        n = Nvic()
        n.write(Nvic.ISER + 8, 4, 1 << (71 - 64))  # USART6
        n.write(Nvic.STIR, 4, 71)
        self.assertEqual(n.best_pending(), (0, 16 + 71))
        self.assertEqual(n.read(Nvic.ISPR + 8, 4), 1 << 7)

    def test_pending_survives_masking(self):
        # PRIMASK is the CPU's business: a disabled interrupt stays pending until it is enabled
        n = Nvic()
        n.set_pending(50)
        self.assertIsNone(n.best_pending())
        n.write(Nvic.ISER + 4, 4, 1 << (50 - 32))
        self.assertEqual(n.best_pending(), (0, 66))

    def test_priority_orders_then_number(self):
        n = Nvic()
        n.write(Nvic.ISER, 4, 0xFFFFFFFF)
        n.write(Nvic.IPR + 3, 1, 0x10)
        n.write(Nvic.IPR + 5, 1, 0x00)
        n.write(Nvic.IPR + 4, 1, 0x0F)  # the low nibble is not implemented
        for irq in (3, 4, 5):
            n.set_pending(irq)
        self.assertEqual(n.best_pending(), (0, 16 + 4))
        self.assertEqual(n.read(Nvic.IPR, 4), 0x1000_0000)  # IRQ3's byte
        self.assertEqual(n.read(Nvic.IPR + 4, 4), 0)

    def test_clear_pending_and_held_lines(self):
        n = Nvic()
        n.write(Nvic.ISER, 4, 1 << 3)
        n.set_pending(3)
        n.write(Nvic.ICPR, 4, 1 << 3)
        self.assertIsNone(n.best_pending())
        n.held.add(3)
        n.set_pending(3)
        self.assertIsNone(n.best_pending())


if __name__ == "__main__":
    unittest.main()
