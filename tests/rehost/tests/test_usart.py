import unittest

from models.exti import Exti
from models.usart import CR1, DR, IDLE, IDLEIE, ORE, RE, RXNE, RXNEIE, SR, TC, TE, TXE, UE, Usart


class Clock:
    def __init__(self):
        self.t = 0

    def __call__(self):
        return self.t


class UsartTest(unittest.TestCase):
    def setUp(self):
        self.clock, self.pended, self.sent = Clock(), [], []
        self.u = Usart("usart1", self.clock, self.pended.append, 37)
        self.u.on_tx = self.sent.append
        self.u.write(0x08, 4, 104)  # BRR: 96 MHz / 104
        self.u.write(CR1, 4, UE | TE | RE | RXNEIE | IDLEIE)

    def run_to(self, t):
        self.clock.t = t
        self.u.advance(t)

    def test_receive_paced_idle_and_overrun(self):
        self.u.feed(b"ab")
        frame = 10 * 104
        self.assertEqual(self.u.next_event(0), frame)
        self.run_to(frame)
        self.assertTrue(self.u.read(SR, 4) & RXNE)
        self.assertIn(37, self.pended)
        self.assertEqual(self.u.read(DR, 1), ord("a"))
        self.assertFalse(self.u.read(SR, 4) & RXNE)
        self.run_to(3 * frame)  # "b" arrives, then an idle frame
        self.assertEqual(self.u.read(SR, 4) & (RXNE | IDLE), RXNE | IDLE)
        self.assertEqual(self.u.read(DR, 1), ord("b"))
        self.assertEqual(self.u.read(SR, 4) & (RXNE | IDLE), 0)
        self.u.feed(b"cd")  # not read in time: the second is lost
        self.run_to(6 * frame)
        self.assertTrue(self.u.read(SR, 4) & ORE)
        self.assertEqual(self.u.read(DR, 1), ord("c"))
        self.assertEqual(self.u.overruns, 1)

    def test_transmit(self):
        self.u.read(SR, 4)
        self.u.write(DR, 1, 0x41)  # to the shift register at once: TXE again, TC cleared
        self.assertEqual(self.u.read(SR, 4) & (TXE | TC), TXE)
        self.u.write(DR, 1, 0x42)
        self.assertFalse(self.u.read(SR, 4) & TXE)
        self.run_to(1040)
        self.assertEqual(self.sent, [0x41])
        self.run_to(2080)
        self.assertEqual(self.sent, [0x41, 0x42])
        self.assertTrue(self.u.read(SR, 4) & TC)


class ExtiTest(unittest.TestCase):
    def test_edge_routed_and_masked(self):
        pended = []
        e = Exti(pended.append, lambda line: 2 if line == 14 else 0)
        e.write(0x08, 4, 1 << 14)  # RTSR
        e.edge(0, 14, True)  # port A is not routed to line 14
        self.assertEqual(e.read(0x14, 4), 0)
        e.edge(2, 14, True)
        self.assertEqual(e.read(0x14, 4), 1 << 14)
        self.assertEqual(pended, [])  # masked
        e.write(0x00, 4, 1 << 14)  # IMR
        self.assertEqual(pended, [40])
        e.write(0x14, 4, 1 << 14)  # PR: write 1 to clear
        self.assertEqual(e.read(0x14, 4), 0)


if __name__ == "__main__":
    unittest.main()
