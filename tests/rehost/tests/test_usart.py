import unittest

from models import dma as D
from models.exti import Exti
from models.usart import CR1, CR3, DMAR, DMAT, DR, IDLE, IDLEIE, ORE, RE, RXNE, RXNEIE, SR, TC, TE, TXE, UE, Usart
from tests.helpers import Memory

USART1 = 0x4001_1000
RING = 0x2000_0100


class Bus(Memory):
    """RAM with USART1's registers mapped where the DMA streams' PAR points."""

    def __init__(self, usart):
        super().__init__()
        self.usart = usart

    def read(self, addr, size):
        if USART1 <= addr < USART1 + 0x400:
            return self.usart.read(addr - USART1, size)
        return super().read(addr, size)

    def write(self, addr, size_or_data, value=None):
        if USART1 <= addr < USART1 + 0x400:
            return self.usart.write(addr - USART1, size_or_data, value)
        return super().write(addr, size_or_data, value)


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


class UsartDmaTest(unittest.TestCase):
    """19.3.13: with DMAR the receiver's bytes go to memory as they arrive, whatever the CPU does (an erase stalls
    it); with DMAT the transmitter takes its bytes from memory, one per TXE."""

    def setUp(self):
        self.clock, self.pended, self.sent = Clock(), [], []
        self.u = Usart("usart1", self.clock, self.pended.append, 37)
        self.u.on_tx = self.sent.append
        self.bus = Bus(self.u)
        self.dma = D.Dma("dma2", self.bus, self.pended.append, [56, 57, 58, 59, 60, 68, 69, 70])
        self.u.rx_dma = [D.RequestLine(self.dma, 2, 4)]
        self.u.tx_dma = [D.RequestLine(self.dma, 7, 4)]
        self.dma.on_enable.append(lambda s: self.u.serve_dma())
        self.u.write(0x08, 4, 104)
        self.u.write(CR1, 4, UE | TE | RE | IDLEIE)

    def stream(self, s, par, m0ar, n, direction, extra=0):
        base = 0x10 + s * 0x18
        self.dma.write(base + 4, 4, n)
        self.dma.write(base + 8, 4, par)
        self.dma.write(base + 12, 4, m0ar)
        self.dma.write(base, 4, (4 << 25) | D.MINC | (direction << 6) | extra | D.EN)

    def run_to(self, t):
        self.clock.t = t
        self.u.advance(t)

    def test_receive_into_a_ring_without_the_cpu(self):
        self.stream(2, USART1 + DR, RING, 8, 0, D.CIRC | D.HTIE | D.TCIE)
        self.u.write(CR3, 4, DMAR)
        self.u.feed(b"0123456789")  # more than the ring: it wraps
        self.run_to(10 * 10 * 104)  # no register read by the CPU meanwhile
        self.assertEqual(bytes(self.bus.read(RING + i, 1) for i in range(8)), b"89234567")
        self.assertEqual((self.u.overruns, self.u.received), (0, 10))
        self.assertFalse(self.u.read(SR, 4) & (RXNE | ORE))
        self.assertEqual(self.dma.read(0x10 + 2 * 0x18 + 4, 4), 6)  # NDTR: 2 of the second lap moved
        self.assertIn(58, self.pended)  # DMA2 stream 2's half and complete interrupts

    def test_receive_without_dma_overruns(self):
        self.stream(2, USART1 + DR, RING, 8, 0, D.CIRC)
        self.u.feed(b"01")  # DMAR clear: nobody takes the bytes
        self.run_to(2 * 10 * 104)
        self.assertEqual(self.u.overruns, 1)
        self.assertEqual(self.bus.read(RING, 1), 0)

    def test_held_request_served_when_the_stream_is_enabled(self):
        self.u.write(CR3, 4, DMAR)
        self.u.feed(b"a")
        self.run_to(10 * 104)
        self.assertTrue(self.u.read(SR, 4) & RXNE)  # no stream yet: the byte waits in DR
        self.stream(2, USART1 + DR, RING, 8, 0, D.CIRC)
        self.assertEqual(self.bus.read(RING, 1), ord("a"))
        self.assertFalse(self.u.read(SR, 4) & RXNE)

    def test_transmit_from_memory(self):
        for i, b in enumerate(b"hello"):
            self.bus.write(RING + i, 1, b)
        self.u.write(CR3, 4, DMAT)
        self.stream(7, USART1 + DR, RING, 5, 1, D.TCIE)
        self.run_to(5 * 10 * 104)
        self.assertEqual(bytes(self.sent), b"hello")
        self.assertTrue(self.u.read(SR, 4) & TC)
        self.assertFalse(self.dma.streams[7].cr & D.EN)  # NDTR reached 0: the stream is off
        self.assertIn(70, self.pended)


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
