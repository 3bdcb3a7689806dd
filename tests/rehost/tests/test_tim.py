import unittest

from models import tim as T
from tests.helpers import Clock, Lines


class Requests:
    """A DMA stream's request line as the timer sees it: the requests it took, in `got[key]`, and its horizon."""

    def __init__(self, got, key, horizon=None):
        self.got, self.key, self.h = got, key, horizon

    def __call__(self, n):
        self.got[self.key] = self.got.get(self.key, 0) + n

    def horizon(self):
        return self.h


def timer(bits=16):
    clock, lines = Clock(), Lines()
    return T.Tim("tim", clock, lines, irq_up=25, irq_cc=27, bits=bits), clock, lines


class TimTest(unittest.TestCase):
    def test_counts_from_the_clock_through_the_prescaler(self):
        t, clock, _ = timer()
        t.write(T.Tim.PSC, 4, 95)
        t.write(T.Tim.EGR, 4, 1)  # UG loads PSC
        t.write(T.Tim.CR1, 4, T.CEN)
        clock.now = 96 * 1000
        self.assertEqual(t.read(T.Tim.CNT, 4), 1000)

    def test_psc_is_preloaded_until_an_update_event(self):
        t, clock, _ = timer()
        t.write(T.Tim.PSC, 4, 9)
        t.write(T.Tim.CR1, 4, T.CEN)
        clock.now = 100
        self.assertEqual(t.read(T.Tim.CNT, 4), 100)  # still divide by 1

    def test_sr_is_rc_w0(self):
        t, clock, _ = timer()
        t.write(T.Tim.ARR, 4, 9)
        t.write(T.Tim.CCR[0], 4, 5)
        t.write(T.Tim.CR1, 4, T.CEN)
        clock.now = 20
        self.assertEqual(t.read(T.Tim.SR, 4) & 0x3, 0x3)  # UIF and CC1IF
        t.write(T.Tim.SR, 4, ~T.UIF & 0xFFFF)  # write 0 to UIF only
        self.assertEqual(t.read(T.Tim.SR, 4) & 0x3, T.CCIF[0])
        t.write(T.Tim.SR, 4, 0xFFFF)  # writing 1 changes nothing
        self.assertEqual(t.read(T.Tim.SR, 4) & 0x3, T.CCIF[0])

    def test_ug_with_urs_loads_registers_without_a_flag(self):
        t, clock, _ = timer()
        t.write(T.Tim.CR1, 4, T.URS)
        t.write(T.Tim.PSC, 4, 1)
        t.write(T.Tim.EGR, 4, 1)
        self.assertEqual(t.psc_act, 1)
        self.assertEqual(t.read(T.Tim.SR, 4), 0)
        t.write(T.Tim.CR1, 4, 0)
        t.write(T.Tim.EGR, 4, 1)
        self.assertEqual(t.read(T.Tim.SR, 4), T.UIF)

    def test_compare_interrupt_and_next_event(self):
        # embassy's time driver: ARR 0xFFFF, CCR1 0x8000 half-period, CC2 alarms
        t, clock, lines = timer(bits=32)
        t.write(T.Tim.ARR, 4, 0xFFFF)
        t.write(T.Tim.CCR[1], 4, 1234)
        t.write(T.Tim.DIER, 4, T.CCIE[1])
        t.write(T.Tim.CR1, 4, T.CEN)
        self.assertEqual(t.next_event(0), 1234)
        clock.now = 1233
        t.advance(clock.now)
        self.assertEqual(lines.pended, [])
        clock.now = 1234
        t.advance(clock.now)
        self.assertEqual(lines.pended, [27])
        self.assertTrue(t.read(T.Tim.SR, 4) & T.CCIF[1])

    def test_overflow_wraps_and_counts_updates(self):
        t, clock, lines = timer()
        t.write(T.Tim.ARR, 4, 239)
        t.write(T.Tim.DIER, 4, T.UIE)
        t.write(T.Tim.CR1, 4, T.CEN)
        clock.now = 240 * 1000 + 7
        self.assertEqual(t.read(T.Tim.CNT, 4), 7)
        self.assertEqual(t.updates, 1000)
        self.assertEqual(lines.pended[-1], 25)

    def test_update_requests_go_to_the_dma_in_bulk(self):
        t, clock, _ = timer()
        got = {}
        t.update_dma.append(Requests(got, "up", 1200))
        t.write(T.Tim.ARR, 4, 239)
        t.write(T.Tim.DIER, 4, T.UDE)
        t.write(T.Tim.CR1, 4, T.CEN)
        self.assertEqual(t.next_event(0), 240 * 1200)  # the DMA's next interrupt, not every update
        clock.now = 240 * 500
        t.advance(clock.now)
        self.assertEqual(got["up"], 500)
        self.assertEqual(t.dma_requests, 500)

    def test_compare_requests_keep_step_with_the_updates(self):
        # the step generator's spare rings: CCR1 = CCR2 = ARR, one request per slot each, in the slot of the update's
        t, clock, _ = timer()
        got = {"up": 0, 0: 0, 1: 0}
        t.update_dma.append(Requests(got, "up"))
        t.cc_dma[0].append(Requests(got, 0, 1200))
        t.cc_dma[1].append(Requests(got, 1))
        t.write(T.Tim.ARR, 4, 239)
        t.write(T.Tim.CCR[0], 4, 239)
        t.write(T.Tim.CCR[1], 4, 239)
        t.write(T.Tim.DIER, 4, T.UDE | T.CCDE[0] | T.CCDE[1])
        t.write(T.Tim.CR1, 4, T.CEN)
        # the 1200th compare 1 match: one timer clock before the 1200th update
        self.assertEqual(t.next_event(0), 240 * 1199 + 239)
        for now in (239, 240, 240 * 7 + 100, 240 * 500 + 239, 240 * 1000 + 5):
            clock.now = now
            t.advance(now)
            self.assertEqual((got[0], got[1]), (now // 240 + (now % 240 >= 239),) * 2, now)
            self.assertEqual(got["up"], now // 240)
        self.assertEqual(t.cc_requests[:2], [1000, 1000])

    def test_compare_without_ccde_makes_no_request(self):
        t, clock, _ = timer()
        got = {}
        t.cc_dma[0].append(Requests(got, 0))
        t.write(T.Tim.ARR, 4, 239)
        t.write(T.Tim.CCR[0], 4, 239)
        t.write(T.Tim.CR1, 4, T.CEN)
        clock.now = 240 * 100
        t.advance(clock.now)
        self.assertEqual(got, {})
        self.assertTrue(t.read(T.Tim.SR, 4) & T.CCIF[0])


if __name__ == "__main__":
    unittest.main()
