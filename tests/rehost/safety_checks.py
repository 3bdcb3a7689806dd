"""The supervisor's safety functions on the flashed binary, each read at the pins (the plant's `output_changes`, its
STEP edges and its switches) and in the device's own status:

- `supply-order`: the relays at power-up and shutdown (the jog check's `device enable` and `device disable`), read at
  PB13-PB15: LOGIC_EN first and POWER_EN `logic_settle_ms` later; the drivers (ENABLE low) only once power has
  settled (`power_settle_ms`); at shutdown ENABLE off before POWER_EN, and LOGIC_EN `discharge_ms` after POWER_EN
  (FIRMWARE.md's shutdown: drivers disabled, power relay off, wait discharge, logic relay off); and over the whole run
  so far, never the motor supply on without logic.
- `usart-silent` and `usb-silent`: the host gone mid-stream on each link (the CLI killed: the port stays, the USB
  cable stays in and the bus runs, nothing more comes): the last STEP edge within the stream timeout and braking
  after the last byte the host sent; then the rule for a host gone long (`safety::HostWatch`, `host_gone_ms` set to
  1,000 ms for the run): held, homed and powered until then (`usart-silent`: a host back within the time finds it
  Ready and homed); a host that asks for the status restarts the silence, and `host_gone_ms` after its last request
  the device powers down in the supervisor's order and delays, moving nothing (`usb-silent`: the host back finds it
  Off, not homed, no fault).
- `estop-states`: the e-stop chain opened in Off (nothing changes, `enable` is refused), PowerOn (a fault keeping
  logic alone), Jogging and Homing (the last STEP edge within the debounce and the step ring, as in Running, which
  the `estop` check covers): each time the fault is `EStop`, ENABLE high, POWER_EN low, LOGIC_EN kept.
- `jog-buzz-axes`: every axis jogged, then buzzed (ten cycles): only its own STEP pin moves the plant, and the
  device's step counts equal the STEP edges signed by DIR.
- `limit-switches`: each linear actuator's far-end switch (LIMIT 5 on PA7, LIMIT 6 on PA8) and home-end switch
  (HOME 5 on PA5, HOME 6 on PA6: an end-of-travel limit outside homing) closed by the plant where that axis's own jog
  takes it (the switch set 200 steps ahead, as an end stop on a shorter stroke): the device latches
  `Fault(Limit(axis))` naming that axis, the last STEP edge within the debounce and the ring, and its step count
  is the STEP edges its axis took (plus at most the ring's two periods the fault's disable cut).
"""

import json
from collections import Counter
import os
import re
import subprocess

from machine import SYSCLK
from plant import ENABLE_N, LOGIC_EN, POWER_EN
from serial_link import cli_env

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
# braking to rest at the acceleration limits from the demo motion's speed (as `usb-cable` allows)
BRAKE_MS = 150
# an input (e-stop, end switch) to the last STEP edge: 3 ms debounce, 1 ms sampling and tick, the ring's two 1 ms
# periods and a period of margin (board_checks.ESTOP_STOP_MS)
INPUT_STOP_MS = 7.0
# the time for a host gone that the run sets (the shortest the stream section takes): a few simulated seconds
GONE_MS = 1_000
# one control period: the supervisor counts its delays in whole periods from the event that started them (a
# command between two periods included), and a relay follows at the end of the period that switched it, so a delay
# at the pins is the configured one within two periods either way
TICK_MS = 1.0


def ms(cycles):
    return cycles * 1000 / SYSCLK


def supervisor_defaults():
    """The supervisor's delays (ms) as `SupervisorConfig::default` gives them: what the firmware compiles in."""
    text = open(os.path.join(REPO, "shared/src/safety/supervisor/config.rs")).read()
    body = text[text.index("impl Default for SupervisorConfig"):]
    return {name: int(re.search(rf"{name}: (\d+)", body).group(1))
            for name in ("logic_settle_ms", "power_settle_ms", "driver_off_ms", "discharge_ms")}


def _status(cli, port):
    try:
        return json.loads(cli.run("device", "status", *port).stdout)
    except ValueError:
        return {}


def _odr(m):
    odr = m.gpio["b"].instance.ODR
    return (odr >> ENABLE_N & 1, odr >> LOGIC_EN & 1, odr >> POWER_EN & 1)


def _changes(plant, since, pin=None, level=None):
    return [(t, p, v) for t, p, v in plant.output_changes
            if t >= since and (pin is None or p == pin) and (level is None or v == level)]


def _first(plant, since, pin, level):
    found = _changes(plant, since, pin, level)
    return found[0][0] if found else None


def never_power_without_logic(plant):
    """The times (ms) at which POWER_EN was driven on while LOGIC_EN was off, over the whole run."""
    logic = power = 0
    bad = []
    for t, pin, level in plant.output_changes:
        if pin == LOGIC_EN:
            logic = level
        elif pin == POWER_EN:
            power = level
        if power and not logic:
            bad.append(round(ms(t), 1))
    return bad


def _periods_off(measured_ms, setting_ms):
    """Whole control periods between a wait as the pins show it and its setting. The supervisor counts its waits in
    periods (a late tick behind a link frame is caught up, so one period may pass early), and each relay is written
    after its tick's computation, whose time varies by tens of microseconds: the pins' interval is a whole number of
    periods give or take that."""
    return abs(round(measured_ms / TICK_MS) - setting_ms / TICK_MS)


def supply_order_check(checks, plant, enabled_at, disabled_at):
    """The relays from `device enable` (at `enabled_at`) to the end of `device disable` (at `disabled_at`)."""
    d = supervisor_defaults()
    logic_on = _first(plant, enabled_at, LOGIC_EN, 1)
    power_on = _first(plant, logic_on or enabled_at, POWER_EN, 1)
    drivers_on = _first(plant, power_on or enabled_at, ENABLE_N, 0)
    power_off = _first(plant, disabled_at, POWER_EN, 0)
    drivers_off = [t for t, _, _ in _changes(plant, enabled_at, ENABLE_N, 1) if power_off and t <= power_off]
    logic_off = _first(plant, power_off or disabled_at, LOGIC_EN, 0)
    settle = ms(power_on - logic_on) if logic_on and power_on else None
    settled = ms(drivers_on - power_on) if power_on and drivers_on else None
    discharge = ms(logic_off - power_off) if logic_off and power_off else None
    unpowered = never_power_without_logic(plant)
    ok = (settle is not None and _periods_off(settle, d["logic_settle_ms"]) <= 2
          and settled is not None and settled >= d["power_settle_ms"]
          and drivers_off and discharge is not None
          and _periods_off(discharge, d["discharge_ms"]) <= 2 and not unpowered)
    checks.check("supply-order", ok,
                 f"power-up: LOGIC_EN (PB14) on at {ms(logic_on or 0):.1f} ms, POWER_EN (PB15) "
                 f"{settle if settle is None else round(settle, 1)} ms later (logic_settle_ms {d['logic_settle_ms']}, "
                 f"within 2 periods), the drivers (PB13 low) {settled if settled is None else round(settled, 1)} "
                 f"ms after power (at least power_settle_ms {d['power_settle_ms']}); shutdown: ENABLE high before "
                 f"POWER_EN off ({bool(drivers_off)}), LOGIC_EN off {discharge if discharge is None else round(discharge, 1)} "
                 f"ms after POWER_EN (discharge_ms {d['discharge_ms']}, within 2 periods); motor supply on "
                 f"without logic at {unpowered or 'no time'} in the run so far")


class Motion:
    """When the plant's axes moved, and when the host's bytes last reached the board, watched every simulated ms."""

    def __init__(self, m, plant, bridge):
        self.m, self.plant, self.bridge = m, plant, bridge
        self.moves = []
        self.last = list(plant.position)
        self.rx_bytes = bridge.to_board
        self.rx_at = m.now
        m.observers.append(self.watch)

    def watch(self):
        if self.plant.position != self.last:
            self.last = list(self.plant.position)
            self.moves.append(self.m.now)
        if self.bridge.to_board != self.rx_bytes:
            self.rx_bytes = self.bridge.to_board
            self.rx_at = self.m.now

    def close(self):
        self.m.observers.remove(self.watch)


def _killed_stream(m, cli, port, motion, moving=20):
    """`ringpod stream --motion demo` started, and killed (SIGKILL: the host gone, its port left as it was) once the
    platform has moved in `moving` simulated ms; the time it was killed, or None."""
    proc = subprocess.Popen([cli.ringpod, "stream", *port, "--motion", "demo", "--duration", "4", "--rate", "50",
                             "--quiet"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            stdin=subprocess.DEVNULL, env=cli_env())
    start, killed = m.now, None
    while proc.poll() is None and m.now - start < 30 * SYSCLK and m.fault is None:
        m.run(m.now + SYSCLK // 200)
        if len(motion.moves) > moving:
            proc.kill()
            killed = m.now
            break
    if proc.poll() is None:
        proc.kill()
    proc.wait()
    return killed


def silent_check(checks, m, cli, port, plant, bridge, name, power_down):
    """Homed and Ready: a stream whose host is killed mid-stream on this link, and what the device does after."""
    timeout = cli.run("device", "config", "get", "stream.timeout_ms", *port)
    gone = cli.run("device", "config", "set", "stream.host_gone_ms", str(GONE_MS), *port)
    try:
        timeout_ms = json.loads(timeout.stdout)["value"]
    except (ValueError, KeyError):
        timeout_ms = None
    motion = Motion(m, plant, bridge)
    killed = _killed_stream(m, cli, port, motion)
    m.run(m.now + SYSCLK // 20)  # what the host had written before it died, read from its port
    last_rx = motion.rx_at
    lost = last_rx + int((timeout_ms or 0) * SYSCLK / 1000)  # where the device's stream timeout runs out
    said = []
    ok = killed is not None and timeout_ms is not None and gone.code == 0
    if not ok:
        motion.close()
        checks.check(name, False, f"no stream to take the host from: killed at {killed}; {timeout}; {gone}")
        return
    # the stop: the last STEP edge after the host's last byte
    m.run(lost + int(0.5 * GONE_MS * SYSCLK / 1000))
    stopped_ms = ms(max(motion.moves) - last_rx)
    held = _odr(m)
    ok &= stopped_ms <= timeout_ms + BRAKE_MS and held == (0, 1, 1)
    said.append(f"the host killed {ms(killed - last_rx):.1f} ms after its last byte reached the board; the last "
                f"STEP edge {stopped_ms:.1f} ms after that byte (stream timeout {timeout_ms} ms + braking, at most "
                f"{BRAKE_MS} ms); ENABLE, LOGIC, POWER {held} half the time for a host gone after the loss "
                f"(want 0, 1, 1: braked, holding, powered)")
    if not power_down:
        # held until just before the time, then the host is back
        m.run(lost + int(0.8 * GONE_MS * SYSCLK / 1000))
        still = _odr(m)
        moves = len(motion.moves)
        status = _status(cli, port)
        back_ms = ms(m.now - lost)
        ok &= still == (0, 1, 1) and status.get("state") == "Ready" and status.get("homed") is True
        ok &= not [t for t in motion.moves[moves:]]
        said.append(f"still {still} {0.8 * GONE_MS:.0f} ms after the loss (host_gone_ms {GONE_MS}); the host back "
                    f"{back_ms:.0f} ms after the loss: state {status.get('state')}, homed {status.get('homed')}")
    else:
        # a host that asks once within the time, then is gone for good
        m.run(lost + int(0.6 * GONE_MS * SYSCLK / 1000))
        moves_then = len(motion.moves)
        status = _status(cli, port)
        asked = motion.rx_at  # the status request's last byte
        again = _odr(m)
        m.run(asked + int((GONE_MS + 650) * SYSCLK / 1000))
        drivers_off = _first(plant, asked, ENABLE_N, 1)
        power_off = _first(plant, asked, POWER_EN, 0)
        logic_off = _first(plant, asked, LOGIC_EN, 0)
        # the silence is counted in whole periods from the request, as the supervisor's delays are
        due = asked + int((GONE_MS - 2 * TICK_MS) * SYSCLK / 1000)
        early = [t for t in (drivers_off, power_off, logic_off) if t is not None and t < due]
        d = supervisor_defaults()
        after = ms(drivers_off - asked) if drivers_off else None
        order = (drivers_off and power_off and logic_off
                 and abs(ms(power_off - drivers_off) - d["driver_off_ms"]) <= 2 * TICK_MS
                 and abs(ms(logic_off - power_off) - d["discharge_ms"]) <= 2 * TICK_MS)
        moved = len(motion.moves) - moves_then
        back = _status(cli, port)
        ok &= (status.get("state") == "Ready" and status.get("homed") is True and again == (0, 1, 1) and not early
               and after is not None and GONE_MS - 2 * TICK_MS <= after <= GONE_MS + 10 and order and moved == 0
               and back.get("state") == "Off" and back.get("homed") is False and _odr(m) == (1, 0, 0))
        said.append(f"a status {ms(asked - lost):.0f} ms after the loss: {status.get('state')}, homed "
                    f"{status.get('homed')}, outputs {again}; then silence: ENABLE high "
                    f"{after if after is None else round(after, 1)} ms after that request (host_gone_ms {GONE_MS}, "
                    f"at most 2 periods early, 10 ms late), POWER_EN off {ms(power_off - drivers_off) if power_off and drivers_off else '-'} "
                    f"ms later (driver_off_ms {d['driver_off_ms']}), LOGIC_EN off "
                    f"{ms(logic_off - power_off) if logic_off and power_off else '-'} ms after that (discharge_ms "
                    f"{d['discharge_ms']}); {moved} plant moves meanwhile; the host back: state {back.get('state')}, "
                    f"homed {back.get('homed')}, ENABLE, LOGIC, POWER {_odr(m)}"
                    + (f"; an output changed before the time at {[round(ms(t - asked), 1) for t in early]} ms" if early else ""))
    motion.close()
    said.append(f"(`device config get stream.timeout_ms` {timeout_ms}, `device config set stream.host_gone_ms "
                f"{GONE_MS}` exit {gone.code})")
    checks.check(name, ok, "; ".join(said))


def _fault_state(status):
    return json.dumps(status.get("state"))


def _enable(m, cli, port):
    r = cli.run("device", "enable", *port)
    m.run(m.now + int(0.35 * SYSCLK))  # logic, then power, each settled
    return r


def _opened_while(m, cli, port, plant, args, motion_needed):
    """`ringpod device ARGS` started; the e-stop opened once the plant moves (or at once); the command ended or
    killed; then the time the chain opened, the last STEP edge after it (ms) and the device's state."""
    moves, last = [], [list(plant.position)]

    def watch():
        if plant.position != last[0]:
            last[0] = list(plant.position)
            moves.append(m.now)

    m.observers.append(watch)
    proc = subprocess.Popen([cli.ringpod, "device", *args, *port], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, env=cli_env())
    # the command may return as soon as the device took it (a jog) or poll until it ends (homing)
    start, opened = m.now, None
    # steps of 2 ms: the machine calls its observers (the pty bridges, `watch`) once a simulated ms within a run
    while m.now - start < 5 * SYSCLK and opened is None and m.fault is None:
        m.run(m.now + SYSCLK // 500)
        if not motion_needed or len(moves) > 10:
            opened = m.now
            plant.open_estop(True)
    m.run(m.now + SYSCLK // 20)
    while proc.poll() is None and m.now - start < 10 * SYSCLK and m.fault is None:
        m.run(m.now + SYSCLK // 200)
    if proc.poll() is None:
        proc.kill()
    proc.wait()
    m.observers.remove(watch)
    after = [t for t in moves if opened and t > opened]
    return opened, (ms(max(after) - opened) if after else 0.0), len(moves)


def estop_states_check(checks, m, cli, port, plant):
    """Off (after the power-down): the e-stop chain opened in Off, PowerOn, Jogging, Homing and Ready."""
    said, ok = [], True
    # Off: nothing to stop; enable is refused while the chain is open
    plant.open_estop(True)
    m.run(m.now + SYSCLK // 50)
    off = _status(cli, port)
    refused = cli.run("device", "enable", *port, expect=None)
    m.run(m.now + SYSCLK // 10)
    outputs = _odr(m)
    ok &= off.get("state") == "Off" and refused.code != 0 and outputs == (1, 0, 0)
    said.append(f"Off: state {off.get('state')}, `device enable` exit {refused.code} (refused), ENABLE, LOGIC, POWER "
                f"{outputs}")
    plant.open_estop(False)
    m.run(m.now + SYSCLK // 50)
    for state, args, moving in (("PowerOn", None, False), ("Jogging", ["jog", "5", "2"], True),
                                ("Homing", ["home"], True)):
        en = _enable(m, cli, port)
        if args is None:
            opened = m.now
            plant.open_estop(True)
            m.run(m.now + SYSCLK // 50)
            stop_ms, moved = 0.0, 0
        else:
            opened, stop_ms, moved = _opened_while(m, cli, port, plant, args, moving)
        outputs = _odr(m)
        status = _status(cli, port)
        fault = _fault_state(status)
        good = (en.code == 0 and opened is not None and "EStop" in fault and outputs == (1, 1, 0)
                and stop_ms <= INPUT_STOP_MS and (not moving or moved > 10))
        ok &= good
        said.append(f"{state}: opened after {moved} plant moves, the last STEP edge {stop_ms:.1f} ms after (at most "
                    f"{INPUT_STOP_MS}), state {fault}, ENABLE, LOGIC, POWER {outputs} (want 1, 1, 0)"
                    + ("" if good else f"; {en}"))
        plant.open_estop(False)
        m.run(m.now + SYSCLK // 50)
        cli.run("device", "clear", *port)  # logic alone kept: back to Off
        m.run(m.now + SYSCLK // 50)
    ok &= _estop_ready(m, cli, port, plant, said)
    checks.check("estop-states", ok, "; ".join(said))


def _estop_ready(m, cli, port, plant, said):
    """Ready: homed to the end and holding, the chain opened: no STEP edge after it, the drivers and the motor
    supply off, the logic kept, the homing lost (a fault's rule); then closed and cleared back to Off."""
    en = _enable(m, cli, port)
    home = cli.run("device", "home", *port)
    m.run(m.now + SYSCLK // 20)  # the steps still in the ring
    ready = _status(cli, port)
    plant.reset_counts()
    plant.open_estop(True)
    m.run(m.now + SYSCLK // 20)
    outputs, edges = _odr(m), list(plant.steps)
    status = _status(cli, port)
    fault = _fault_state(status)
    good = (en.code == 0 and home.code == 0 and ready.get("state") == "Ready" and ready.get("homed") is True
            and "EStop" in fault and outputs == (1, 1, 0) and edges == [0] * 6 and status.get("homed") is False)
    said.append(f"Ready: `device home` exit {home.code}, state {ready.get('state')}, homed {ready.get('homed')}; "
                f"opened: STEP edges after {edges}, state {fault}, homed {status.get('homed')}, ENABLE, LOGIC, POWER "
                f"{outputs} (want 1, 1, 0)")
    plant.open_estop(False)
    m.run(m.now + SYSCLK // 50)
    cli.run("device", "clear", *port)
    m.run(m.now + SYSCLK // 50)
    return good


def limit_check(checks, m, cli, port, plant):
    """Powered, not homed: each linear actuator jogged into its far-end switch, then into its home-end switch
    (outside homing an end-of-travel limit too), each set just ahead of it."""
    said, ok = [], True
    en = _enable(m, cli, port)
    ok &= en.code == 0
    for axis, end, pin, sign in ((4, "far", "PA7", 1), (4, "home", "PA5", -1), (5, "far", "PA8", 1),
                                 (5, "home", "PA6", -1)):
        before = _status(cli, port).get("steps")
        start = list(plant.position)
        far, home = list(plant.far_limit), list(plant.home_end)
        if end == "far":
            far[axis] = start[axis] + 200
        else:
            home[axis] = start[axis] - 200
        plant.set_switches(far_limit=far, home_end=home)
        closed, moves, last = [], [], [list(plant.position)]

        def watch(axis=axis, far=far, home=home, end=end):
            if plant.position != last[0]:
                last[0] = list(plant.position)
                moves.append(m.now)
                reached = plant.position[axis] >= far[axis] if end == "far" else plant.position[axis] <= home[axis]
                if not closed and reached:
                    closed.append(m.now)

        m.observers.append(watch)
        plant.reset_counts()
        jog = cli.run("device", "jog", str(axis + 1), str(sign), *port, expect=None)  # 1 mm: 1,600 steps
        waited = m.now
        while not closed and m.now - waited < SYSCLK // 2:
            m.run(m.now + SYSCLK // 100)
        m.run(m.now + SYSCLK // 20)
        m.observers.remove(watch)
        status = _status(cli, port)
        fault = _fault_state(status)
        after = status.get("steps")
        moved = [b - a for a, b in zip(before, after)] if before and after else None
        stop_ms = ms(max(moves) - closed[0]) if closed and moves else None
        named = f'"Limit": {axis}' in fault
        # the device counts the steps it planned; those the ring played after the fault disabled the drivers
        # (at most its two periods at the jog's rate) reached no driver
        unseen = (moved[axis] - plant.net[axis]) * sign if moved else None
        good = (closed and named and stop_ms is not None and stop_ms <= INPUT_STOP_MS
                and plant.net[axis] * sign >= 200 and unseen is not None and 0 <= unseen <= 12
                and all(n == 0 for a, n in enumerate(plant.net) if a != axis)
                and all(n == 0 for a, n in enumerate(moved) if a != axis))
        ok &= bool(good)
        said.append(f"axis {axis + 1} jogged toward its {end} end, its switch ({pin}) set 200 steps ahead: closed "
                    f"{'at ' + format(ms(closed[0]), '.1f') + ' ms' if closed else 'never'}, the last STEP edge "
                    f"{stop_ms if stop_ms is None else round(stop_ms, 1)} ms after (at most {INPUT_STOP_MS}); state "
                    f"{fault}; device steps moved {moved}, STEP edges {plant.net}" + ("" if good else f"; {jog}"))
        plant.set_switches()  # the axis moved off its switch by hand, as after a real one
        m.run(m.now + SYSCLK // 50)
        clear = cli.run("device", "clear", *port, expect=None)
        ok &= clear.code == 0
        m.run(m.now + SYSCLK // 50)
    checks.check("limit-switches", ok, "; ".join(said))


def _until_still(m, plant, quiet_ms=20, limit_s=2.0):
    """Runs until the plant has not moved for `quiet_ms` (at most `limit_s`)."""
    start, last, still_since = m.now, list(plant.position), m.now
    while m.now - start < limit_s * SYSCLK:
        m.run(m.now + SYSCLK // 1000)
        if plant.position != last:
            last, still_since = list(plant.position), m.now
        elif m.now - still_since >= quiet_ms * SYSCLK // 1000:
            return


def jog_buzz_check(checks, m, cli, port, plant):
    """Powered (after the limit check): every axis jogged and buzzed: only that axis's STEP pin moves the plant,
    and the device's counts equal the STEP edges."""
    said, ok = [], True
    for axis in range(6):
        before = _status(cli, port).get("steps")
        plant.reset_counts()
        ignored0, undriven0, at0 = Counter(plant.ignored), plant.dir_undriven, len(plant.ignored_at)
        jog = cli.run("device", "jog", str(axis + 1), "0.5" if axis < 4 else "0.1", *port)
        _until_still(m, plant)
        jogged = list(plant.net)
        buzz = cli.run("device", "buzz", str(axis + 1), *port)  # the CLI waits for its ten cycles
        _until_still(m, plant)
        after = _status(cli, port)
        moved = [b - a for a, b in zip(before, after.get("steps", []))] if before else None
        others = [n for a, n in enumerate(plant.steps) if a != axis]
        good = (jog.code == 0 and buzz.code == 0 and moved == plant.net and jogged[axis] != 0
                and plant.steps[axis] > abs(jogged[axis]) and not any(others)
                and "PowerOn" in json.dumps(after.get("state")))
        ok &= good
        said.append(f"axis {axis + 1}: jogged {jogged[axis]} steps, then {plant.steps[axis] - abs(jogged[axis])} "
                    f"buzz edges; device moved {moved}, STEP edges {plant.net}, other axes' edges {others}"
                    + ("" if good else f"; {jog}; {buzz}; state {after.get('state')}; STEP rises no driver saw "
                       f"{dict(plant.ignored - ignored0)} (first at {plant.ignored_at[at0:]}), steps with DIR undriven "
                       f"{plant.dir_undriven - undriven0}"))
    cli.run("device", "disable", *port)
    m.run(m.now + int(0.6 * SYSCLK))
    checks.check("jog-buzz-axes", ok, "; ".join(said))

