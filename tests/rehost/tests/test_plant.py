import logging
import unittest

from models.gpio import BSRR, Gpio
from plant import ENABLE_N, FAR_LIMIT, LOGIC_EN, POWER_EN, Plant


class FakeQl:
    log = logging.getLogger("fake-ql")


class FakeMachine:
    """The parts of `machine.Machine` the plant uses: the GPIO ports, the timed models, no EXTI, a clock."""

    def __init__(self):
        self.gpio = {port: Gpio(FakeQl(), f"gpio{port}") for port in "abc"}
        self.timed = []
        self.exti = None
        self.now = 0


def outputs(g, pins):
    moder = 0
    for pin in pins:
        moder |= 1 << (2 * pin)
    g.write(0x00, 4, moder)


class PlantTest(unittest.TestCase):
    def setUp(self):
        self.m = FakeMachine()
        self.plant = Plant(self.m)
        self.b = self.m.gpio["b"]
        # every wired pin of the step port an output, and PB11 too (nothing is wired there)
        outputs(self.b, [*range(0, 11), 11, 12, ENABLE_N, LOGIC_EN, POWER_EN])

    def test_an_edge_on_an_unwired_pin_of_the_step_port_is_counted(self):
        self.b.bsrr_words([1 << 11, 1 << 27, 1 << 0, 1 << 16])
        self.assertEqual(dict(self.plant.stray_edges), {11: 2})

    def test_the_outputs_changes_are_kept_with_their_times(self):
        self.m.now = 100
        self.b.write(BSRR, 4, 1 << LOGIC_EN)
        self.m.now = 200
        self.b.write(BSRR, 4, 1 << POWER_EN | 1 << (16 + ENABLE_N))
        self.m.now = 300
        self.b.write(BSRR, 4, 1 << (16 + POWER_EN))
        self.assertEqual(self.plant.output_changes,
                         [(100, LOGIC_EN, 1), (200, POWER_EN, 1), (300, POWER_EN, 0)])

    def test_a_far_switch_moved_ahead_closes_where_the_axis_reaches_it(self):
        a = 4  # linear actuator 5: STEP PB4, DIR PB10, LIMIT 5 on PA7
        start = self.plant.position[a]
        self.plant.set_switches(far_limit=[FAR_LIMIT] * 4 + [start + 2, FAR_LIMIT])
        self.b.write(BSRR, 4, 1 << POWER_EN | 1 << LOGIC_EN | 1 << (16 + ENABLE_N) | 1 << 10)  # DIR 5 forward
        a_port = self.m.gpio["a"]
        self.b.bsrr_words([1 << 4, 1 << 20])
        self.assertEqual(self.plant.position[a], start + 1)
        self.assertIsNone(a_port.external.get(7))
        self.b.bsrr_words([1 << 4, 1 << 20])
        self.assertEqual(self.plant.position[a], start + 2)
        self.assertEqual(a_port.external.get(7), 0, "closed: the contact pulls PA7 low")
        self.assertIsNone(a_port.external.get(8), "LIMIT 6 stays open")
        self.plant.set_switches()
        self.assertIsNone(a_port.external.get(7), "moved back: open again")


if __name__ == "__main__":
    unittest.main()
