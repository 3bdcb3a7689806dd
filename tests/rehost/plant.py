"""The machine on the board's pins, as the QEMU board's `sim::Plant` (trainer model, parked) but in Python, read
electrically (the pins as `models.gpio.Gpio` says the chip drives them, not its output register).

- Each STEP rising edge on PB0-PB5 (board::resources::PORT_MAP) moves its axis one step, forward when its DIR pin
  (PB6-PB10, PB12) is high (`dir_forward_low` 0), but only when the chip drives STEP (a push-pull output), the
  drivers are enabled (ENABLE, PB13, driven low) and the motor supply is on (POWER_EN, PB15, driven high): an edge
  the drivers cannot see is counted in `ignored` by reason, and a step taken with DIR undriven in `dir_undriven`.
  The edges are seen word by word as the DMA writes GPIOB.BSRR, so times are in TIM1 slots (2.5 us): every STEP
  high time (`widths`), DIR set-up (a DIR change to the next STEP rise, `setups`) and hold (a STEP rise to the next
  DIR change, `holds`), and the DIR changes a step followed (`reversals`).
- Switches at positions, as `Plant::trainer_model`: carriages 1-4 have an index flag 60 steps wide from 0, the
  linear actuators 5-6 a home end switch at 0 and below, and a far end at 240,000 steps. A switch is a contact to
  ground: closed it pulls the pin low, open it leaves the pin to the pull the firmware configured (PA1-PA6 home,
  PA7/PA8 far ends; a floating read is counted by the GPIO model). A home switch's contact bounces as a
  microswitch's does: after each change of its position's state it returns to the old level and back twice
  (`BOUNCE_US` after the first edge; 1.6 ms in all, within the 1-5 ms such switches are specified for), so that the
  firmware's debounce, not the plant, decides where it latched. The e-stop chain (PA0, normally closed, an
  external pull-up on the board) reads high when opened (`open_estop`).
- Every pin of the step port (GPIOB) is watched: an edge on a pin that is none of the STEP, DIR, ENABLE and relay
  pins above is counted in `stray_edges` by pin (nothing is wired there: a pulse on it is a step lost). Every change
  of ENABLE and the relays is kept with its time (`output_changes`), for the supplies' order and delays.
- Each linear actuator's far-end switch sits at `far_limit[a]` (240,000 steps), which a check may move near the
  axis (as an end stop is set on a shorter stroke) to close it with a short move; `home_end` likewise.
- Supply sense follows the relays at once: LOGIC_OK (PA9) is driven high while LOGIC_EN (PB14) is, POWER_OK (PC14)
  while POWER_EN (PB15) is; otherwise they are left to their pull-downs. With `senses` off (a board whose spare
  axes take those pins) nothing drives them.
- A pin whose level changes is an edge for the EXTI model (its line, if the firmware routed it there).
"""

from collections import Counter

from machine import SYSCLK

TRAINER_MODEL_PARKED = [-500, -400, -300, -200, 8_000, 9_000]  # shared/src/model.rs
# shared/src/model.rs, CARRIAGE_HOMING and LINEAR_HOMING: where the firmware puts each axis when its switch trips on
# the slow approach (the carriages' index at 0 rad; the end switch at -66.31 mm x 1,600 steps/mm), the slow
# approach's speed (steps/s) and its direction
HOME_POSITION = [0, 0, 0, 0, -106_096, -106_096]
SLOW_RATE = [500, 500, 500, 500, 4_000, 4_000]
TOWARD = [1, 1, 1, 1, -1, -1]
STEP = [0, 1, 2, 3, 4, 5]
DIR = [6, 7, 8, 9, 10, 12]
ENABLE_N, LOGIC_EN, POWER_EN = 13, 14, 15
FLAG_WIDTH, FAR_LIMIT = 60, 240_000
# board::resources::PORT_MAP: the pins of GPIOB something is wired to; an edge on another is a fault
UNWIRED_B = 0xFFFF & ~sum(1 << p for p in {*STEP, *DIR, ENABLE_N, LOGIC_EN, POWER_EN})
OUTPUTS_B = 1 << ENABLE_N | 1 << LOGIC_EN | 1 << POWER_EN
BOUNCE_US = (150, 400, 900, 1_600)  # a contact's changes after its first edge: old, new, old, new level
CYCLES_PER_US = SYSCLK // 1_000_000
PORT_A, PORT_C = 0, 2
ESTOP, LOGIC_OK, POWER_OK = 0, 9, 14  # PA0, PA9, PC14
WIRED_A = {ESTOP, 1, 2, 3, 4, 5, 6, 7, 8, LOGIC_OK}  # the switches and LOGIC_OK on port A
WIRED_C = {POWER_OK}
# board::resources: the pins each wired input must read through (None: an external pull-up, the e-stop chain's)
PULLS = {("a", ESTOP): None, **{("a", p): 1 for p in range(1, 9)}, ("a", LOGIC_OK): 0, ("c", POWER_OK): 0}


class Plant:
    def __init__(self, m, start=TRAINER_MODEL_PARKED):
        self.m = m
        self.gpio = m.gpio
        self.gpio["a"].wired |= WIRED_A
        self.gpio["c"].wired |= WIRED_C
        self.position = list(start)
        self.senses = True  # the supply senses wired; False: their pins are spare axes' STEP/DIR (spare_check.py)
        self.estop_open = False
        self.steps = [0] * 6  # STEP rising edges per axis that moved it
        self.net = [0] * 6  # signed steps per axis
        self.ignored = Counter()  # STEP rises the drivers could not see, by why
        self.dir_undriven = 0  # steps taken while the chip did not drive that axis's DIR
        self.ignored_at = []  # (time, axis, why) of the first ignored rises
        self.enable_changes = []  # (time, ENABLE's ODR bit) of every change
        self.output_changes = []  # (time, pin, level) of every change of ENABLE, LOGIC_EN and POWER_EN
        self.stray_edges = Counter()  # GPIOB pin -> edges on it, for the pins nothing is wired to
        self.far_limit = [FAR_LIMIT] * 6  # where each linear actuator's far-end switch closes (steps)
        self.home_end = [0] * 6  # where each linear actuator's home-end switch closes (steps, at and below)
        self.high_at = [None] * 6
        self.rise_at = [None] * 6  # the slot of each axis's last STEP rise
        self.dir_at = [None] * 6  # the slot of each axis's last DIR change
        self.clear_timing()
        self.levels = {}  # (port letter, pin) -> the level last seen on it
        self.switch_edges = [0] * 6  # changes of each home switch
        self.contact = [None] * 6  # each home switch closed (True) or open, as its axis's position puts it
        self.bouncing = [[] for _ in range(6)]  # each home switch's bounce still to come: (time, level)
        self.bounces = 0  # contact changes that bounced
        m.gpio["b"].on_change = self._portb
        self._update()
        m.timed.append(self)

    # -- a timed model of the machine's scheduler: the contacts' bounce --
    def advance(self, now):
        for a, events in enumerate(self.bouncing):
            while events and events[0][0] <= now:
                self._drive("a", 1 + a, events.pop(0)[1])

    def next_event(self, now):
        return min((events[0][0] for events in self.bouncing if events), default=now + (1 << 40))

    def reset_counts(self):
        self.steps = [0] * 6
        self.net = [0] * 6

    def clear_timing(self):
        """Starts a new record of the step signals' timing (in slots), each a set per axis."""
        self.widths = [set() for _ in range(6)]  # STEP high times
        self.setups = [set() for _ in range(6)]  # a DIR change to the next STEP rise
        self.holds = [set() for _ in range(6)]  # a STEP rise to the next DIR change
        self.reversals = [0] * 6  # DIR changes a step followed

    def timing(self, slot_us):
        """(shortest STEP high, DIR set-up, DIR hold over every axis, in us (None: none seen), reversals)."""
        def shortest(sets):
            values = set().union(*sets)
            return min(values) * slot_us if values else None
        return shortest(self.widths), shortest(self.setups), shortest(self.holds), sum(self.reversals)

    def open_estop(self, is_open):
        """Opens (or closes again) the e-stop chain."""
        self.estop_open = is_open
        self._update()

    def _why_not(self, b, odr, axis):
        """Why a STEP rise on `axis` does not reach its driver (None: it does)."""
        if b.driven(STEP[axis], odr) is None:
            return "STEP not driven"
        if b.driven(ENABLE_N, odr) != 0:
            return "drivers not enabled"
        if b.driven(POWER_EN, odr) != 1:
            return "motor power off"
        return None

    def _portb(self, old, new, slot):
        b = self.gpio["b"]
        changed = old ^ new
        for a in range(6):
            d, s = DIR[a], STEP[a]
            if changed >> d & 1:
                if self.rise_at[a] is not None:
                    self.holds[a].add(slot - self.rise_at[a])
                self.dir_at[a] = slot
            if not changed >> s & 1:
                continue
            if new >> s & 1:
                why = self._why_not(b, new, a)
                self.high_at[a] = slot
                if why:
                    self.ignored[why] += 1
                    if len(self.ignored_at) < 8:
                        self.ignored_at.append((self.m.now, a, why))
                    continue
                level = b.driven(d, new)
                if level is None:
                    self.dir_undriven += 1
                step = 1 if level else -1  # an undriven DIR: the driver's opto-coupler off, as a low
                self.position[a] += step
                self.net[a] += step
                self.steps[a] += 1
                if self.dir_at[a] is not None and (self.rise_at[a] is None or self.dir_at[a] > self.rise_at[a]):
                    self.setups[a].add(slot - self.dir_at[a])
                    self.reversals[a] += 1
                self.rise_at[a] = slot
            elif self.high_at[a] is not None:
                self.widths[a].add(slot - self.high_at[a])
                self.high_at[a] = None
        if changed >> ENABLE_N & 1:
            self.enable_changes.append((self.m.now, new >> ENABLE_N & 1))
        if changed & OUTPUTS_B:
            for pin in (ENABLE_N, LOGIC_EN, POWER_EN):
                if changed >> pin & 1:
                    self.output_changes.append((self.m.now, pin, new >> pin & 1))
        if changed & UNWIRED_B:
            for pin in range(16):
                if (changed & UNWIRED_B) >> pin & 1:
                    self.stray_edges[pin] += 1
        if changed & ((1 << 6) - 1 | 1 << LOGIC_EN | 1 << POWER_EN):
            self._update(new)

    def _drive(self, port, pin, level):
        """Drives `pin` from outside (None: released); an edge of what the pin then reads goes to the EXTI model."""
        g = self.gpio[port]
        g.drive(pin, level)
        key = (port, pin)
        now = g.level(pin)
        was = self.levels.get(key, now)
        self.levels[key] = now
        if now == was or now is None or was is None:
            return
        if port == "a" and 1 <= pin <= 6:
            self.switch_edges[pin - 1] += 1
        if self.m.exti:
            self.m.exti.edge(PORT_A if port == "a" else PORT_C, pin, bool(now))

    def _update(self, odr=None):
        b = self.gpio["b"]
        for a in range(6):
            p = self.position[a]
            home = 0 <= p < FLAG_WIDTH if a < 4 else p <= self.home_end[a]
            level, old = (0 if home else None), (None if home else 0)
            if home == self.contact[a]:
                if not self.bouncing[a]:  # driven again (a reset or a pull set since), unless it is bouncing
                    self._drive("a", 1 + a, level)
                continue
            if self.contact[a] is not None:  # a change of the contact, not the state it was found in
                now = self.m.now
                self.bouncing[a] = [(now + t * CYCLES_PER_US, old if k % 2 == 0 else level)
                                    for k, t in enumerate(BOUNCE_US)]
                self.bounces += 1
            self.contact[a] = home
            self._drive("a", 1 + a, level)
        for a, pin in ((4, 7), (5, 8)):
            self._drive("a", pin, 0 if self.position[a] >= self.far_limit[a] else None)
        self._drive("a", ESTOP, 1 if self.estop_open else 0)
        self._drive("a", LOGIC_OK, 1 if self.senses and b.driven(LOGIC_EN, odr) == 1 else None)
        self._drive("c", POWER_OK, 1 if self.senses and b.driven(POWER_EN, odr) == 1 else None)

    def set_switches(self, far_limit=None, home_end=None):
        """Moves the linear actuators' end switches (None: back where the trainer model has them)."""
        self.far_limit = list(far_limit or [FAR_LIMIT] * 6)
        self.home_end = list(home_end or [0] * 6)
        self._update()

    def refresh(self):
        """The pins' levels again after the firmware configured them (a pull set makes an edge of its own)."""
        self._update()
