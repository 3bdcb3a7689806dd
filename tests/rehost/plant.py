"""The machine on the board's pins, as the QEMU board's `sim::Plant` (trainer model, parked) but in Python.

- Each STEP rising edge on PB0-PB5 (board::resources::PORT_MAP) moves its axis one step, forward when its DIR pin
  (PB6-PB10, PB12) is high (`dir_forward_low` 0); the edges are seen word by word as the DMA writes GPIOB.BSRR,
  so pulse widths and DIR set-up times are measured in TIM1 slots (2.5 us).
- Switches at positions, as `Plant::trainer_model`: carriages 1-4 have an index flag 60 steps wide from 0, the
  linear actuators 5-6 a home end switch at 0 and below, and a far end at 240,000 steps. Switches close to ground
  (pull-ups, active low: PA1-PA6 home, PA7/PA8 far ends); the e-stop chain (PA0) stays closed (low).
- Supply sense follows the relays at once: LOGIC_OK (PA9) = LOGIC_EN (PB14), POWER_OK (PC14) = POWER_EN (PB15).
- A switch or sense pin that changes is an edge for the EXTI model (its line, if the firmware routed it there).
"""

TRAINER_MODEL_PARKED = [-500, -400, -300, -200, 8_000, 9_000]  # shared/src/model.rs
# shared/src/model.rs, CARRIAGE_HOMING and LINEAR_HOMING: where the firmware puts each axis when its switch trips on
# the slow approach (the carriages' index at 0 rad; the end switch at -66.31 mm x 1,600 steps/mm), the slow
# approach's speed (steps/s) and its direction
HOME_POSITION = [0, 0, 0, 0, -106_096, -106_096]
SLOW_RATE = [500, 500, 500, 500, 4_000, 4_000]
TOWARD = [1, 1, 1, 1, -1, -1]
STEP = [0, 1, 2, 3, 4, 5]
DIR = [6, 7, 8, 9, 10, 12]
LOGIC_EN, POWER_EN = 14, 15
FLAG_WIDTH, FAR_LIMIT = 60, 240_000
PORT_A, PORT_C = 0, 2


class Plant:
    def __init__(self, m, start=TRAINER_MODEL_PARKED):
        self.m = m
        self.gpio = m.gpio
        self.position = list(start)
        self.steps = [0] * 6  # STEP rising edges per axis
        self.net = [0] * 6  # signed steps per axis
        self.high_at = [None] * 6
        self.dir_at = [None] * 6
        self.widths = [set() for _ in range(6)]  # STEP high times seen, in slots
        self.setups = [set() for _ in range(6)]  # slots from a DIR change to the next STEP rise
        self.levels = {}
        self.switch_edges = [0] * 6  # changes of each home switch
        m.gpio["b"].on_change = self._portb
        self._update()

    def reset_counts(self):
        self.steps = [0] * 6
        self.net = [0] * 6

    def _portb(self, old, new, slot):
        changed = old ^ new
        for a in range(6):
            d = DIR[a]
            if changed >> d & 1:
                self.dir_at[a] = slot
            s = STEP[a]
            if changed >> s & 1:
                if new >> s & 1:
                    step = 1 if new >> d & 1 else -1
                    self.position[a] += step
                    self.net[a] += step
                    self.steps[a] += 1
                    self.high_at[a] = slot
                    if self.dir_at[a] is not None:
                        self.setups[a].add(slot - self.dir_at[a])
                        self.dir_at[a] = None
                elif self.high_at[a] is not None:
                    self.widths[a].add(slot - self.high_at[a])
                    self.high_at[a] = None
        if changed & ((1 << 6) - 1 | 1 << LOGIC_EN | 1 << POWER_EN):
            self._update(new)

    def _drive(self, port, pin, level):
        key = (port, pin)
        if self.levels.get(key) == level:
            return
        was = self.levels.get(key)
        self.levels[key] = level
        self.gpio["ac"[port // 2]].drive(pin, level)
        if port == PORT_A and 1 <= pin <= 6 and was is not None:
            self.switch_edges[pin - 1] += 1
        if was is not None and self.m.exti:
            self.m.exti.edge(port, pin, bool(level))

    def _update(self, odr=None):
        if odr is None:
            odr = self.gpio["b"].instance.ODR
        for a in range(6):
            p = self.position[a]
            home = 0 <= p < FLAG_WIDTH if a < 4 else p <= 0
            self._drive(PORT_A, 1 + a, 0 if home else 1)
        for a, pin in ((4, 7), (5, 8)):
            self._drive(PORT_A, pin, 0 if self.position[a] >= FAR_LIMIT else 1)
        self._drive(PORT_A, 0, 0)
        self._drive(PORT_A, 9, odr >> LOGIC_EN & 1)
        self._drive(PORT_C, 14, odr >> POWER_EN & 1)
