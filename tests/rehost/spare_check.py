"""`spare-axes`: the spare stepper axes 7 and 8 on the board's pins, over USB (fitting one takes USART1's pins).

- Refused beside a sensed supply, by its key (`spare[0].enabled`, naming LOGIC_OK): the pins are the senses'.
- With the senses off, both axes fitted (`device config set spare.N`), and `device restart`: the firmware takes
  PA9/PA10/PA15/PC14 as outputs (STEP7, DIR7, STEP8, DIR8) and leaves USART1 off (CR1.UE 0) and EXTI lines 9 and 14
  masked; TIM1's compares 1 and 2 sit at the slot's last count (CCRx = ARR) with CCxDE set, and DMA2 streams 1 and
  2 (channel 6, RM0383 9.3.3 table 28) play rings of the platform ring's length into GPIOA.BSRR and GPIOC.BSRR.
- Homed over USB, a pose file with `axis7` and `axis8` columns streamed (the platform rising 4 mm as axis 7 goes
  to 10, both on one smoothstep; axis 8 out to about 2.5 and back to -2): the STEP rises on PA9 and PA15, signed by
  the level PA10 and PC14 drive, end at the columns' last values times 400 steps per unit (4,000 and -800), as the
  device counts; every STEP high, DIR set-up and hold within the platform's limits (2.5 us, 5 us), DIR 8 reversed;
  the three rings' words in step (the same slot count on GPIOA, GPIOB and GPIOC); axis 7 half way within 10 ms of
  the platform axis that moved most (the same rows, which the emulator's slowness compresses into about a third of
  their time).
- A second stream (axis 7 toward 30 units over 4 s) stopped by SIGINT (the CLI sends STOP, exit 130) once axis 7
  has moved: every axis at rest within the braking time, no STEP edge on PA9/PA15 nor a platform step for 0.5 s
  after, axis 7 short of its target, the device's counts equal to the edges.
- Put back: disabled, the spare axes off, the senses on, restarted: USART1 answers again. The plant is put back
  where the check found it (as by hand, drivers off): homing after a restart searches only 40 mm.
"""

import json
import math
import os
import signal
import subprocess
import tempfile

from machine import SYSCLK
from models import dma as D
from models import tim as T
from models.gpio import OUTPUT
from serial_link import cli_env

STEP7, DIR7, STEP8 = 9, 10, 15  # PA9, PA10, PA15 (board::resources::SPARE_MAP)
DIR8 = 14  # PC14
STEPS_PER_UNIT = 400.0
GPIOA_BSRR, GPIOC_BSRR = 0x4002_0018, 0x4002_0818
USART_UE = 1 << 13  # RM0383 19.6.4 USART_CR1.UE
AXIS = {"enabled": True, "steps_per_unit": STEPS_PER_UNIT, "velocity": 100.0, "acceleration": 4000.0,
        "travel": [-5.0, 40.0]}
NONE = {"enabled": False, "steps_per_unit": 1000.0, "velocity": 1.0, "acceleration": 1.0, "travel": [0.0, 0.0]}


class SparePins:
    """The spare axes as their drivers see them: each STEP rise on PA9/PA15 a step, forward when DIR (PA10, PC14) is
    driven high; times in slots (each port's DMA word index: the rings start together, so the same slot on both)."""

    def __init__(self, m):
        self.m = m
        self.a, self.c = m.gpio["a"], m.gpio["c"]
        self.net = [0, 0]
        self.rises = [0, 0]
        self.undriven = 0
        self.rise_at = [None, None]
        self.dir_at = [None, None]
        self.high_at = [None, None]
        self.widths, self.setups, self.holds = set(), set(), set()
        self.reversals = [0, 0]
        self.times = [[], []]  # simulated time of each rise
        self.a.on_change = self._port_a
        self.c.on_change = self._port_c

    def close(self):
        self.a.on_change = self.c.on_change = None

    def _dir(self, axis, slot):
        if self.rise_at[axis] is not None:
            self.holds.add(slot - self.rise_at[axis])
        self.dir_at[axis] = slot

    def _port_c(self, old, new, slot):
        if (old ^ new) >> DIR8 & 1:
            self._dir(1, slot)

    def _port_a(self, old, new, slot):
        changed = old ^ new
        if changed >> DIR7 & 1:
            self._dir(0, slot)
        for axis, pin in ((0, STEP7), (1, STEP8)):
            if not changed >> pin & 1:
                continue
            if not new >> pin & 1:
                if self.high_at[axis] is not None:
                    self.widths.add(slot - self.high_at[axis])
                self.high_at[axis] = None
                continue
            self.high_at[axis] = slot
            level = self.a.driven(DIR7, new) if axis == 0 else self.c.driven(DIR8)
            if level is None:
                self.undriven += 1
            self.net[axis] += 1 if level else -1
            self.rises[axis] += 1
            self.times[axis].append(self.m.now)
            if self.dir_at[axis] is not None and (self.rise_at[axis] is None or self.dir_at[axis] > self.rise_at[axis]):
                self.setups.add(slot - self.dir_at[axis])
                self.reversals[axis] += 1
            self.rise_at[axis] = slot


def _status(cli, port):
    try:
        return json.loads(cli.run("device", "status", *port).stdout)
    except ValueError:
        return {}


def _restart_usb(m, link, *args):
    """`device restart` over USB, then the port the host's next enumeration makes."""
    enumerations = link.host.enumerations
    r = link.cli.run("device", "restart", "--port", link.bridge.path, *args, expect=None)
    start = m.now
    while link.host.enumerations == enumerations and m.now - start < 3 * SYSCLK:
        m.run(m.now + SYSCLK // 100)
    m.observers.remove(link.bridge.poll)
    link.bridge.hang_up()
    return r, link.open_port()


def _pose_file(rows):
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        f.write("t,x,y,z,alpha,beta,gamma,axis7,axis8\n")
        for t, z, a7, a8 in rows:
            f.write(f"{t:.2f},0,0,{0.227 + z:.6f},0,0,0,{a7:.5f},{a8:.5f}\n")
    return f.name


def _platform_moves(m, plant):
    """(time, positions) at each change of the platform's positions, and the observer recording them."""
    moves, last = [], [list(plant.position)]

    def watch():
        if plant.position != last[0]:
            last[0] = list(plant.position)
            moves.append((m.now, last[0]))
    m.observers.append(watch)
    return moves, watch


def _half_way(track, start, end):
    """When a position going from `start` to `end` first got half way, from (time, position) pairs."""
    half = (start + end) / 2
    return next((t for t, p in track if (p - half) * (end - start) >= 0), None)


def _ms(cycles):
    return cycles * 1000 / SYSCLK


def _taken(m):
    """What a start with the spare axes fitted must leave: the pins as outputs, USART1 and the senses' EXTI lines
    off, and the spare rings beside the platform's. Each item's name, and the names of those not so."""
    a, c = m.gpio["a"], m.gpio["c"]
    tim1, dma2 = m.tim["tim1"], m.dma["dma2"]
    main = dma2.streams[5]
    want = {
        "PA9/PA10/PA15 outputs": all(a.mode(p) == OUTPUT for p in (STEP7, DIR7, STEP8)),
        "PC14 output": c.mode(DIR8) == OUTPUT,
        "USART1 off (CR1.UE 0)": not m.usart1.cr1 & USART_UE,
        "EXTI 9, 14 masked": not m.exti.imr & (1 << 9 | 1 << 14),
        "TIM1 CCR1 = CCR2 = ARR, CC1DE+CC2DE": tim1.ccr[0] == tim1.ccr[1] == tim1.arr
        and tim1.dier & T.CCDE[0] and tim1.dier & T.CCDE[1],
    }
    for s, par in ((1, GPIOA_BSRR), (2, GPIOC_BSRR)):
        st = dma2.streams[s]
        want[f"DMA2 S{s} CHSEL 6, PAR {par:#x}, circular, NDTR {main.reload}"] = (
            st.cr & D.EN and st.channel == 6 and st.par == par and st.cr & D.CIRC and st.reload == main.reload)
    return list(want), [k for k, ok in want.items() if not ok]


def _both_columns(m, cli, usb, plant, pins, slot_us):
    """A pose file with both columns: axis 7 to 10 on the smoothstep the platform rises 4 mm on, axis 8 out to about
    2.5 and back to -2. (ok, what was seen)."""
    rows = []
    for i in range(76):
        t = min(i / 50, 1.0)
        s = t * t * (3 - 2 * t)  # at rest at both ends
        rows.append((i / 50, 0.004 * s, 10 * s, 4 * math.sin(math.pi * t) - 2 * s))
    path = _pose_file(rows)
    def words():
        return [m.gpio[port].dma_words for port in "abc"]

    words0 = words()
    before = _status(cli, usb)
    pins.net, pins.rises, pins.times = [0, 0], [0, 0], [[], []]
    start_position = list(plant.position)
    moves, watch = _platform_moves(m, plant)
    st = cli.run("stream", *usb, "--input", path, "--report-json", "--quiet", sim_limit_s=30)
    m.run(m.now + SYSCLK // 10)
    m.observers.remove(watch)
    os.unlink(path)
    after = _status(cli, usb)
    moved = [x - y for x, y in zip(after.get("spare_steps", [0, 0]), before.get("spare_steps", [0, 0]))]
    want = [round(10 * STEPS_PER_UNIT), round(-2 * STEPS_PER_UNIT)]
    # axis 7 and the platform's heave follow the same smoothstep: each is half way at the stream's middle row
    spare_half = pins.times[0][len(pins.times[0]) // 2] if len(pins.times[0]) > 1 else None
    deltas = [abs(p - q) for p, q in zip(plant.position, start_position)]
    ax = deltas.index(max(deltas))  # the platform axis that moved most
    platform_half = _half_way([(t, p[ax]) for t, p in moves], start_position[ax], plant.position[ax])
    lag_ms = _ms(spare_half - platform_half) if spare_half and platform_half else None
    dw = [w - w0 for w, w0 in zip(words(), words0)]
    width = min(pins.widths, default=0) * slot_us
    setup = min(pins.setups, default=0) * slot_us
    hold = min(pins.holds, default=0) * slot_us
    ok = (st.code == 0 and pins.net == want == moved and pins.rises[1] > abs(want[1])
          and width >= 2.5 and setup >= 5.0 and hold >= 5.0 and pins.reversals[1] >= 1 and not pins.undriven
          and lag_ms is not None and abs(lag_ms) <= 10 and max(dw) - min(dw) <= 2)
    return ok, (f"`stream` of axis7/axis8 exit {st.code} ({st.sim_s:.2f} simulated s): STEP rises on PA9/PA15 signed "
                f"by PA10/PC14 {pins.net} ({pins.rises} rises), the device's spare steps moved {moved}, the "
                f"columns' last values x 400 {want}; platform steps {before.get('steps')} -> {after.get('steps')}; "
                f"shortest STEP high {width} us, DIR set-up {setup} us, hold {hold} us, DIR reversals "
                f"{pins.reversals}, {pins.undriven} steps with DIR undriven; DMA words GPIOA/GPIOB/GPIOC {dw}; axis 7 "
                f"half way (its 2,000th step) {lag_ms if lag_ms is None else round(lag_ms, 2)} ms after platform "
                f"axis {ax + 1} (at most 10 ms apart)")


def _stopped(m, ringpod, cli, usb, plant, pins):
    """A stream toward axis 7 = 30 over 4 s interrupted by SIGINT (the CLI sends STOP) once axis 7 moved 400 steps.
    (ok, what was seen)."""
    rows = [(i / 50, 0.004 + 0.002 * min(i / 50, 1.0), 10 + 20 * i / 200, 0.0) for i in range(201)]
    path = _pose_file(rows)
    pins.net, pins.rises, pins.times = [0, 0], [0, 0], [[], []]
    before = _status(cli, usb)
    moves, watch = _platform_moves(m, plant)  # the platform's steps: none may come after the brake either
    proc = subprocess.Popen([ringpod, "stream", *usb, "--input", path, "--quiet"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, env=cli_env())
    t0, interrupted = m.now, None
    while proc.poll() is None and m.now - t0 < 30 * SYSCLK and m.fault is None:
        m.run(m.now + SYSCLK // 200)
        if interrupted is None and pins.rises[0] >= 400:
            proc.send_signal(signal.SIGINT)
            interrupted = m.now
    if proc.poll() is None:
        proc.kill()
    code = proc.wait()
    os.unlink(path)
    exited = m.now
    # braking from at most 100 units/s at 4,000 units/s^2: 25 ms, and the platform's own; 0.3 s is past both
    m.run(m.now + int(0.3 * SYSCLK))
    rises_then, platform_then = list(pins.rises), len(moves)
    m.run(m.now + SYSCLK // 2)
    m.observers.remove(watch)
    quiet = pins.rises == rises_then and len(moves) == platform_then
    stopped = _status(cli, usb)
    moved = [x - y for x, y in zip(stopped.get("spare_steps", [0, 0]), before.get("spare_steps", [0, 0]))]
    last = max((ts[-1] for ts in pins.times if ts), default=None)
    ok = (interrupted is not None and code == 130 and quiet and pins.net == moved
          and 400 <= moved[0] < 20 * STEPS_PER_UNIT and stopped.get("state") == "Ready")
    since = interrupted or t0
    return ok, (f"a stream toward axis7 = 30 interrupted (SIGINT) {_ms(since - t0):.0f} ms in, after "
                f"{rises_then[0]} rises: exit {code} (130), exited {_ms(exited - since):.0f} ms after the signal, the "
                f"last spare STEP rise {f'{_ms(last - since):.1f}' if last else '-'} ms after it; no STEP edge on PA9/PA15 "
                f"nor a platform step in the 0.5 s after the brake: {quiet}; STEP rises signed {pins.net}, the "
                f"device's spare steps moved {moved} (short of 8,000); state {stopped.get('state')}")


def spare_check(checks, m, cli, port, link, plant, slot_us):
    """After `links-both`: both links up, nothing homed. Ends with the board as it found it (restarted, USART1 up)."""
    # refused while the supervisor senses a supply (the compiled-in default)
    refused = cli.run("device", "config", "set", "spare.0", json.dumps(AXIS), *port, expect=(1,))
    sets = [cli.run("device", "config", "set", f"supervisor.{k}", "false", *port) for k in ("logic_sense", "power_sense")]
    sets += [cli.run("device", "config", "set", f"spare.{i}", json.dumps(AXIS), *port) for i in (0, 1)]
    restarts, found_at = len(m.resets), list(plant.position)
    plant.senses = False  # the senses' pins become outputs: the plant no longer drives them
    r, usb = _restart_usb(m, link)  # over USB: the board comes back without USART1
    plant.refresh()
    taken, bad = _taken(m)

    pins = SparePins(m)
    en = link.cli.run("device", "enable", *usb)
    m.run(m.now + int(0.6 * SYSCLK))
    home = link.cli.run("device", "home", *usb, sim_limit_s=30)
    m.run(m.now + SYSCLK // 20)
    followed, stream_said = _both_columns(m, link.cli, usb, plant, pins, slot_us)
    stop_ok, stop_said = _stopped(m, link.ringpod, link.cli, usb, plant, pins)
    pins.close()

    # put back: no spare axes, the senses on, USART1 up (a restart only with the supplies off)
    off = link.cli.run("device", "disable", *usb)
    m.run(m.now + int(0.6 * SYSCLK))
    back = [link.cli.run("device", "config", "set", f"spare.{i}", json.dumps(NONE), *usb) for i in (0, 1)]
    back += [link.cli.run("device", "config", "set", f"supervisor.{k}", "true", *usb)
             for k in ("logic_sense", "power_sense")]
    # The machine moved back by hand, the drivers off, to where the check found it: after a restart homing searches
    # 40 mm, less than the home pose's height above the linear actuators' end switches, so the next check's homing
    # needs them as low as they were.
    plant.position = found_at
    plant.senses = True
    rs, usb = _restart_usb(m, link)
    plant.refresh()
    serial = _status(cli, port)
    checks.check("spare-axes",
                 refused.code == 1 and "spare[0].enabled" in refused.stderr and "LOGIC_OK" in refused.stderr
                 and all(x.code == 0 for x in [r, rs, off, en, home, *sets, *back])
                 and len(m.resets) == restarts + 2 and not bad and followed and stop_ok
                 and "state" in serial and m.usart1.cr1 & USART_UE,
                 f"fitting axis 7 beside a sensed supply: exit {refused.code}, {refused.stderr.strip()[:160]!r}; "
                 f"senses off and both fitted, restarted: {', '.join(taken)}"
                 + (f"; wrong: {', '.join(bad)}" if bad else "")
                 + f"; homed over USB exit {home.code} ({home.sim_s:.1f} simulated s); {stream_said}; {stop_said}; "
                 f"put back and restarted ({len(m.resets) - restarts} resets in the check): USART1 answers (state "
                 f"{serial.get('state')})" + "".join(f"; {x}" for x in [r, rs, off, en, home, *sets, *back] if x.code != 0))
