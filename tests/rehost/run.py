"""Runs the release firmware ELF, exactly as flashed, on Qiling's stm32f411 model with the harness's peripheral
models, and checks what it does. Prints `PASS name: detail` / `FAIL name: detail` per check and finally
`N passed, M failed`; exits 1 when a check failed.

    python run.py [--elf PATH] [--memory-x PATH] [--config PATH] [--seconds S]
"""

import argparse
import atexit
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
REPO = os.path.dirname(os.path.dirname(HERE))

from unicorn import UC_HOOK_MEM_READ  # noqa: E402
from unicorn import arm_const as A  # noqa: E402

from defmt_log import DefmtLog  # noqa: E402
from elf import memory_x  # noqa: E402
from bootloader_checks import (SystemMemory, bootloader_entry_checks, bootloader_refused_check,  # noqa: E402
                               flash_check)
from dfu_bridge import DfuBridge  # noqa: E402
from dfu_client_check import board_client_check, client_check, elf_image, renamed_elf  # noqa: E402
from board_checks import estop_check, inputs_check, pins_check, priority_check, timing  # noqa: E402
from hold_up import hold_up_checks  # noqa: E402
from machine import SYSCLK, Machine  # noqa: E402
from models import dma as D  # noqa: E402
from models import tim as T  # noqa: E402
from models.flash import sector_of  # noqa: E402
from models.rcc import IWDGRSTF  # noqa: E402
from plant import FLAG_WIDTH, HOME_POSITION, SLOW_RATE, TOWARD, Plant  # noqa: E402
from seqstore import used_up_page  # noqa: E402
from spare_check import spare_check  # noqa: E402
from serial_link import Cli, PtyBridge  # noqa: E402
from usb_checks import UsbLink, cable_check, usb_full_checks, usb_link_checks, usb_stream_checks  # noqa: E402
from safety_checks import (estop_states_check, jog_buzz_check, limit_check, silent_check,  # noqa: E402
                           supply_order_check)

CLI_BAUD = 921_600  # host/src/link: the serial ports' rate (USART_BAUD in firmware/src/board/stm32f411/uart.rs)
SETTINGS = (0x0804_0000, 0x0808_0000)  # sectors 6-7 (firmware/src/board/stm32f411/settings.rs, SETTINGS)
GPIOB_BSRR = 0x4002_0418
STEP_PINS, ENABLE_N, LOGIC_RELAY, POWER_RELAY = range(6), 13, 14, 15  # board::resources::PORT_MAP, pin table


class Enough(Exception):
    """The check `--until` names has run."""


class Checks:
    """The checks' tally; one instance, `CHECKS`, so that a harness error still reports the count so far."""

    def __init__(self):
        self.passed = self.failed = 0
        self.until = None

    def check(self, name, ok, detail):
        print(f"{'PASS' if ok else 'FAIL'} {name}: {detail}", flush=True)
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        if name == self.until:
            raise Enough


CHECKS = Checks()


def ms(cycles):
    return cycles * 1000 / SYSCLK


class Probes:
    """Breakpoints and watches on the firmware, by the ELF's symbols."""

    def __init__(self, m):
        self.m = m
        elf = m.elf
        self.pools = {name.split("::")[-2]: (addr, size) for name, addr, size in elf.find(r"::POOL$")}
        self.polled = {}  # task -> set of IPSR values it was polled in
        self.task_hooks = [m.add_breakpoint(addr, self._poll) for _name, addr, _size in
                           elf.find(r"TaskStorage<F>::poll$")]
        self.reached = {}
        self.inlined = []  # labels with no symbol of their own: LTO inlined them into their caller
        for label, pattern in (("Executor::run", r"thread::Executor::run$"),
                               ("board::start", r"board::start::\{\{closure\}\}$")):
            found = list(elf.find(pattern))
            if not found:
                self.inlined.append(label)
            for _name, addr, _size in found:
                self.task_hooks.append(
                    m.add_breakpoint(addr, lambda mm, label=label: self.reached.setdefault(label, mm.now)))
        self.faults = []
        for pattern in (r"^HardFault_?$", r"^DefaultHandler_?$", r"rust_begin_unwind", r"^_defmt_panic$"):
            for name, addr, _size in elf.find(pattern):
                m.add_breakpoint(addr, lambda mm, name=name: self.faults.append((name, mm.now)))
        # `Controller::advance_clock`: one call per control period, ticked or passed (device time advances by one
        # period); a standalone function in the release ELF
        self.periods = []  # simulated times of each call
        for _name, addr, _size in elf.find(r"Controller::advance_clock$"):
            m.add_breakpoint(addr, lambda mm: self.periods.append(mm.now))
        self.stalled = None  # (task, resets then): its polls return at once until the next reset
        self.settings_reads = 0
        self.settings_not_erased = 0
        m.uc.hook_add(UC_HOOK_MEM_READ, self._settings_read, None, SETTINGS[0], SETTINGS[1] - 1)
        self.csr_reads = []  # (time, value) of RCC_CSR reads
        rcc_read = m.rcc.read

        def read(offset, size, rcc_read=rcc_read):
            value = rcc_read(offset, size)
            if offset == 0x74:
                self.csr_reads.append((m.now, value))
            return value

        m.rcc.read = read

    def _poll(self, m):
        r0 = m.reg(A.UC_ARM_REG_R0)
        for task, (addr, size) in self.pools.items():
            if addr <= r0 < addr + size:
                self.polled.setdefault(task, set()).add(m.reg(A.UC_ARM_REG_IPSR) & 0x1FF)
                if self.stalled == (task, len(m.resets)):
                    m.uc.reg_write(A.UC_ARM_REG_PC, m.reg(A.UC_ARM_REG_LR) | 1)  # the poll returns at once

    def drop_task_probes(self):
        """The tasks' polls and the start's breakpoints no longer watched (`tasks-reached` and `stall` are done):
        every code hook slows every instruction."""
        for h in self.task_hooks:
            self.m.uc.hook_del(h)
        self.task_hooks = []

    def stall(self, task):
        """Stops polling `task` (the others run on) until the chip resets."""
        self.stalled = (task, len(self.m.resets))

    def periods_between(self, t0, t1):
        return sum(1 for t in self.periods if t0 <= t < t1)

    def _settings_read(self, uc, access, addr, size, value, ud):
        self.settings_reads += 1
        if bytes(uc.mem_read(addr, size)) != b"\xff" * size:
            self.settings_not_erased += 1


class Snapshot:
    def __init__(self, m):
        m.advance()  # the models up to now: the last chunk may have ended past their last update
        st = m.dma["dma2"].streams[5]
        self.t = m.now
        self.updates = m.tim["tim1"].updates
        self.items = st.items
        self.bsrr = m.gpio["b"].dma_words
        self.dma_irqs = m.entries.get(16 + 68, 0)
        self.feeds = len(m.iwdg.reloads)


def source_constant(name):
    """An integer `const` of the core (`shared/src`), wherever it is defined."""
    for root, _dirs, files in os.walk(os.path.join(REPO, "shared/src")):
        for f in sorted(files):
            if f.endswith(".rs"):
                found = re.search(rf"const {name}: \w+ = ([\d_]+);", open(os.path.join(root, f)).read())
                if found:
                    return int(found.group(1).replace("_", ""))
    raise KeyError(f"const {name} not found under shared/src")


def serial_checks(m, p, log, plant, ringpod, hold_ups=False, usb=None, usb_full=False, rom=None,
                  elf=None, client=None, scratch=None):
    c = CHECKS
    u = m.usart1
    bridge = PtyBridge(u)
    m.observers.append(bridge.poll)
    cli = Cli(m, ringpod, bridge)
    port = ["--port", bridge.path]

    r = cli.run("device", "status", *port)
    try:
        status = json.loads(r.stdout)
    except ValueError:
        status = {}
    # RM0383 19.3.4: with OVER8 0, baud = f_PCLK / (16 x USARTDIV), USARTDIV in 1/16ths (BRR): rounding it is at
    # most half a sixteenth off, 1 / (32 USARTDIV) of the rate (0.48 % at 921,600 from 96 MHz); the receiver
    # takes up to 3.41 % (19.3.5, a fractional divider)
    baud = SYSCLK / max(1, u.brr)
    error = baud / CLI_BAUD - 1
    rounding = 16 / (32 * u.brr) if u.brr else 0
    c.check("serial-status", r.code == 0 and "state" in status and u.overruns == 0 and abs(error) <= rounding,
            f"{r} | USART1 BRR {u.brr} ({baud:.0f} baud, {100 * error:+.2f} % from the CLI's {CLI_BAUD}; BRR "
            f"rounding allows {100 * rounding:.2f} %), CR1 {u.cr1:#06x}; {bridge.to_board} bytes in, "
            f"{bridge.to_host} out, {u.overruns} overruns; {r.sim_s:.2f} simulated s")

    def steps():
        r = cli.run("device", "status", *port)
        try:
            return json.loads(r.stdout)["steps"]
        except (ValueError, KeyError):
            return None

    # a jog: the STEP edges on GPIOB (the plant) against the steps the device counts; the watchdog reset above
    # latched a fault, which the host clears first
    clear = cli.run("device", "clear", *port)
    before = steps()
    plant.reset_counts()
    plant.clear_timing()
    enabled_at = m.now
    en = cli.run("device", "enable", *port)
    m.run(m.now + int(0.6 * SYSCLK))  # logic, then power, each with its settling time
    jog = cli.run("device", "jog", "1", "0.5", *port)
    after = steps()
    dev = [b - a for a, b in zip(before, after)] if before and after else None
    timed, timing_said = timing(plant, SLOT_US, both_ways=False)
    c.check("serial-jog", en.code == 0 and jog.code == 0 and dev is not None and dev[0] != 0
            and dev == plant.net and timed,
            f"{clear}; {en}; {jog}; device steps moved {dev}, STEP edges on PB0-PB5 (signed by DIR) {plant.net}; "
            f"{timing_said}")
    disabled_at = m.now
    cli.run("device", "disable", *port)
    m.run(m.now + int(0.6 * SYSCLK))  # drivers, power, logic off
    supply_order_check(CHECKS, plant, enabled_at, disabled_at)
    settings_check(m, p, log, cli, port)
    if usb is not None:
        usb_link_checks(CHECKS, m, usb, port)
        spare_check(CHECKS, m, cli, port, usb, plant, SLOT_US)
    homing_check(m, plant, cli, port)
    stream_check(m, plant, cli, port, ringpod)
    if usb is not None:
        usb_stream_checks(CHECKS, m, usb, plant, stream_check)
    if rom is not None:
        bootloader_refused_check(CHECKS, m, cli, port, plant, rom)
    # the host gone mid-stream: back within the time on USART1, the cable pulled and plugged again on USB
    silent_check(CHECKS, m, cli, port, plant, bridge, "usart-silent", power_down=False)
    if usb is not None:
        cable_check(CHECKS, m, usb, plant)
    pins_check(CHECKS, plant, Counter(plant.ignored), plant.dir_undriven)
    estop_check(CHECKS, m, cli, port, plant)
    if usb is not None and usb_full:
        usb_full_checks(CHECKS, m, usb, plant, homing_check)
    else:
        homing_check(m, plant, cli, port, name="serial-home-again")
    # the host gone for good (on USB with the cable in, when the host is plugged): the power-down, then the e-stop
    # in the states that need no homing and the end switches
    if usb is not None:
        silent_check(CHECKS, m, usb.cli, ["--port", usb.bridge.path], plant, usb.bridge, "usb-silent",
                     power_down=True)
    else:
        silent_check(CHECKS, m, cli, port, plant, bridge, "usart-silent-gone", power_down=True)
    estop_states_check(CHECKS, m, cli, port, plant)
    limit_check(CHECKS, m, cli, port, plant)
    jog_buzz_check(CHECKS, m, cli, port, plant)
    if hold_ups:
        homing_check(m, plant, cli, port, name="serial-home-hold-ups")
        hold_up_checks(CHECKS, m, cli, port)
    if rom is not None:
        bootloader_entry_checks(CHECKS, m, cli, port, rom, log, usb)
        if usb is not None:
            clients = [("dfu-client", client)] if client is not None else []
            board = board_client_check(CHECKS, m, cli, port, rom, usb.host, elf_image(elf), scratch, client)
            clients.append(("dfu-client-board", board))
            flash_check(CHECKS, m, cli, port, rom, log, DfuBridge(m, usb.host), elf, clients)


SLOT_US = source_constant("STEP_SLOT_NS") / 1000


def stream_check(m, plant, cli, port, ringpod, name="serial-stream", backwards=False):
    """`ringpod stream` of a one-second CSV (heave 4 mm and yaw 3 degrees, at rest at both ends) over the link:
    the device's step counts, the STEP edges on GPIOB (signed by DIR) and the simulated controller
    (`stream --sim --fast`, the same core on the host) end at the same steps. The host paces the rows by its own
    clock and the emulated board runs many times slower than real time, so the rows arrive within about 0.2
    simulated s: the same path, faster (still inside the device's limits), ending at the same pose."""
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        f.write("t,x,y,z,alpha,beta,gamma\n")
        for i in range(51):
            t = i / 50
            s = t * t * (3 - 2 * t)  # smoothstep: at rest at both ends
            s = 1 - s if backwards else s
            f.write(f"{t:.2f},0,0,{0.227 + 0.004 * s:.6f},0,0,{3.0 * s:.4f}\n")  # from the home pose (z 227 mm)
    args = ["--input", f.name, "--degrees", "--report-json", "--quiet"]
    sim = subprocess.run([ringpod, "stream", "--sim", "--fast", *args], capture_output=True, text=True, timeout=120)
    before = json.loads(cli.run("device", "status", *port).stdout or "{}").get("steps")
    plant.reset_counts()
    plant.clear_timing()
    r = cli.run("stream", *port, *args, sim_limit_s=30)
    m.run(m.now + SYSCLK // 20)  # the steps still in the ring
    after = json.loads(cli.run("device", "status", *port).stdout or "{}").get("steps")
    os.unlink(f.name)
    try:
        report, want = json.loads(r.stdout), json.loads(sim.stdout)["final_steps"]
    except (ValueError, KeyError):
        report, want = {}, None
    moved = [b - a for a, b in zip(before, after)] if before and after else None
    timed, timing_said = timing(plant, SLOT_US, both_ways=True)
    CHECKS.check(name, r.code == 0 and report.get("outcome") == "followed"
                 and report.get("setpoints_applied") == report.get("setpoints_sent")
                 and moved == plant.net and after == report.get("final_steps") == want and timed,
                 f"`ringpod stream` exit {r.code} after {r.sim_s:.2f} simulated s: {report.get('outcome')}, "
                 f"{report.get('setpoints_sent')} setpoints sent, {report.get('setpoints_applied')} applied, limited "
                 f"{report.get('limited', {}).get('device')} by the device; device "
                 f"steps {before} -> {after} (moved {moved}), STEP edges on PB0-PB5 (signed by DIR) {plant.net}, the "
                 f"report's final steps {report.get('final_steps')}, `stream --sim --fast` {want}; {timing_said}"
                 + ("" if r.code == 0 else f"; {r}"))


def homing_check(m, plant, cli, port, name="serial-home"):
    """`device home` through the plant's switches: each axis approaches its switch, backs off, approaches slowly
    and is given its home position where the debounced switch trips, then the platform moves to the home pose.
    Where the device's count and the STEP edges put each axis then gives the plant position the device latched:
    on the switch, past its first edge by the contact's bounce (1.6 ms), the debounce (3 ms) and the 1 ms sampling
    and tick, less the periods the device has planned but the pins not yet played (the step ring's one period and
    the queued one): 4-5 ms, two or three steps at the slow approach's rate; up to 10 ms more when the edge comes
    between two of the inputs task's waits and its 10 ms sweep finds it (firmware/src/app/inputs.rs)."""
    edges0, exti0, bounces0 = list(plant.switch_edges), m.exti.edges, plant.bounces
    plant.clear_timing()
    en = cli.run("device", "enable", *port)
    m.run(m.now + int(0.6 * SYSCLK))
    home = cli.run("device", "home", *port)
    m.run(m.now + SYSCLK // 20)  # the steps still in the ring
    st = cli.run("device", "status", *port)
    try:
        status = json.loads(st.stdout)
    except ValueError:
        status = {}
    dev = status.get("steps", [0] * 6)
    latched = [p - d + h for p, d, h in zip(plant.position, dev, HOME_POSITION)]  # the plant where it latched
    past_ms = [round(1000 * (x - 0) * t / r, 1) for x, t, r in zip(latched, TOWARD, SLOW_RATE)]
    on_switch = all(0 <= x < FLAG_WIDTH if a < 4 else x <= 0 for a, x in enumerate(latched))
    edges = [b - a for a, b in zip(edges0, plant.switch_edges)]
    timed, timing_said = timing(plant, SLOT_US, both_ways=True)
    CHECKS.check(name, home.code == 0 and status.get("state") == "Ready" and status.get("homed") and timed
                 and on_switch and all(0 < t <= 22 for t in past_ms) and all(e >= 4 for e in edges)
                 and m.exti.edges - exti0 >= sum(edges) and plant.bounces - bounces0 >= 4 * 6,
                 f"{en}; `device home` exit {home.code} after {home.sim_s:.2f} simulated s: state "
                 f"{status.get('state')}, homed {status.get('homed')}; home switches PA1-PA6 changed {edges} times "
                 f"(fast approach, back-off, slow approach, clear; {plant.bounces - bounces0} contact changes each "
                 f"bounced 4 times over 1.6 ms), {m.exti.edges - exti0} EXTI edges; plant at "
                 f"{plant.position}, device counts {dev}: latched at {latched} (on the switch: {on_switch}), "
                 f"{past_ms} ms past the switch edge at the slow approach's speed (more than 0, at most 22 ms: the debounce, "
                 f"at most one 10 ms sweep); {timing_said}" + ("" if home.code == 0 else f"; {home}"))


def settings_check(m, p, log, cli, port):
    """A setting stored over the link into sectors 6-7 and restored after `device restart`. Sector 6 is first
    filled as ~200 saves leave it (written through the debug port, as a probe would), so this save closes it,
    writes into sector 7 and erases sector 6: 2 s with the CPU stalled, under the widened watchdog."""
    iw, fl = m.iwdg, m.flash
    sector6 = SETTINGS[0]
    m.uc.mem_write(sector6, used_up_page(0x20000))
    programs, erases, resets, lines = len(fl.programs), len(fl.erases), len(m.resets), len(log.lines)
    start = m.now
    st = cli.run("device", "config", "set", "stream.timeout_ms", "250", *port)
    widened = []  # the reload value while the settings task stores
    asked = None  # a request whose bytes reach USART1 while the erase stalls the CPU, and the overruns before it
    while m.now - start < 4 * SYSCLK and not any("the configuration" in t for _, _, t in log.lines[lines:]):
        if asked is None and fl.busy_until > m.now + SYSCLK:
            overruns, received, stalled_at = m.usart1.overruns, m.usart1.received, m.now
            r = cli.run("device", "status", *port, hold=True)
            asked = (r, m.usart1.overruns - overruns, m.usart1.received - received, ms(fl.busy_until - stalled_at))
        m.run(m.now + SYSCLK // 100)
        widened.append(iw.rlr_act)
        log.poll()
    m.run(m.now + SYSCLK // 2)  # the periods the erase cost, caught up
    # device time (one control period per `Controller::advance_clock`) against simulated time across the save
    periods, sim_ms = p.periods_between(start, m.now), ms(m.now - start)
    stored = [t for _, _, t in log.lines[lines:] if "the configuration" in t]
    caught = [t for _, _, t in log.lines[lines:] if "lost to device time" in t]
    feeds = [t for t in iw.reloads if t >= start]
    gap = max((b - a for a, b in zip(feeds, feeds[1:])), default=0)
    busy = fl.busy_until - fl.busy_from if fl.erases[erases:] else 0
    rs = cli.run("device", "restart", *port)
    got = cli.run("device", "config", "get", "stream.timeout_ms", *port)
    try:
        value = json.loads(got.stdout)["value"]
    except (ValueError, KeyError):
        value = None
    new = fl.programs[programs:]
    outside = [hex(a) for a, _ in new if not SETTINGS[0] <= a < SETTINGS[1]]
    restarted = [cause for _, cause in m.resets[resets:]]
    timeout = max(widened, default=0) * iw.tick(iw.pr_act)
    CHECKS.check("serial-settings", st.code == 0 and stored and "stored" in stored[0] and value == 250
                 and fl.erases[erases:] == [6] and new and not outside and not fl.rejected
                 and restarted == ["SYSRESETREQ"] and gap < timeout and abs(periods - sim_ms) <= 2 and caught
                 and asked is not None and asked[0].code == 0 and asked[1] == 0,
                 f"{st}; the settings task: {stored[0] if stored else 'nothing stored'!r}, {len(new)} words programmed, "
                 f"sector erases {fl.erases[erases:]} (BSY and the CPU stalled for {ms(busy):.0f} ms), outside sectors 6-7: {outside or 'none'}, {len(fl.rejected)} rejected stores; "
                 f"the watchdog widened to RLR {max(widened, default=0)} ({ms(timeout):.0f} ms), longest gap between "
                 f"feeds {ms(gap):.0f} ms; device time {periods} ms in {sim_ms:.1f} simulated ms across the save "
                 f"(at most 2 ms apart; the firmware: {caught}); "
                 + (f"`device status` sent {asked[3]:.0f} ms before the erase's end: exit {asked[0].code}; while the CPU "
                    f"stood USART1 received {asked[2]} bytes, {asked[1]} overruns (want 0: DMA takes them); " if asked else
                    "no request sent during the erase; ")
                 + f"{rs}: resets {restarted}; {got}")


# Lines above info the run causes on purpose: the watchdog-reset check's reset.
EXPECTED_LOG = [r"the last reset was the watchdog's"]


def log_check(m, log):
    """Every defmt line of the run: the boot's, and nothing above info but the lines its checks cause."""
    log.poll()
    up = [text for _, level, text in log.lines if "firmware up" in text]
    noisy = [f"{ms(t):.0f} ms {level}: {text}" for t, level, text in log.lines
             if level not in ("info", "debug", "trace") and not any(re.search(e, text) for e in EXPECTED_LOG)]
    expected = sorted({text for _, level, text in log.lines if level not in ("info", "debug", "trace")} - set(noisy))
    CHECKS.check("log", up and any("settings:" in text for _, _, text in log.lines) and not noisy,
                 f"{len(log.lines)} defmt lines read over RTT in the whole run; {len(up)} starts "
                 f"({up[0] if up else 'never up'}); above info only the expected {expected}"
                 + (f"; unexpected: {noisy[:4]}" if noisy else ""))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--elf", default=os.path.join(REPO, "target/thumbv7em-none-eabihf/firmware/ringpod-firmware"))
    ap.add_argument("--memory-x", default=os.path.join(REPO, "memory.x"))
    ap.add_argument("--seconds", type=float, default=1.0, help="simulated seconds of normal running")
    ap.add_argument("--ringpod", help="the host CLI binary: runs the serial-link checks over a pty")
    ap.add_argument("--hold-ups", action="store_true",
                    help="also the hold-up checks mid-stream (hold_up.py; not yet reliable at the emulator's speed)")
    ap.add_argument("--no-usb", action="store_true", help="no USB host: every link check over USART1")
    ap.add_argument("--usb-full", action="store_true",
                    help="also homing over USB, and the cable pulled mid-stream and plugged again (usb_checks.py)")
    ap.add_argument("--until", help="stop after this check (the mutants' runs)")
    # The whole run takes about 81 simulated s on idle cores and 90 to 91 beside other work: the firmware keeps running
    # while the host's commands wait on a busy machine, so the limit keeps room for that.
    ap.add_argument("--max-sim-s", type=float, default=150.0, help="stop the run past this many simulated seconds")
    ap.add_argument("--max-wall-s", type=float, default=2400.0, help="stop the run past this many wall seconds")
    ap.add_argument("--count-instructions", action="store_true", help="count instructions (slow): for the book's Emulation chapter")
    args = ap.parse_args()

    c = CHECKS
    c.until = args.until
    ram = memory_x(args.memory_x)["RAM"]
    wall0 = time.time()
    # the image `flash-usb` writes, first written by the published DfuSe client into the ROM model alone
    scratch = tempfile.mkdtemp(prefix="rehost-dfu-")
    atexit.register(shutil.rmtree, scratch, True)
    try:
        renamed = renamed_elf(args.elf, os.path.join(scratch, "renamed.elf"))
        client = client_check(c, elf_image(renamed), scratch)
    except (ValueError, OSError, subprocess.SubprocessError) as e:  # `flash-usb` then writes the ELF as it is: fails
        renamed, client = args.elf, None
        c.check("dfu-client", False, f"{type(e).__name__}: {e}")
    m = Machine(args.elf, ram)
    m.limit(int(args.max_sim_s * SYSCLK), wall0 + args.max_wall_s)
    p = Probes(m)
    log = DefmtLog(m)
    m.observers.append(log.poll)
    plant = Plant(m)
    usb = None if args.ringpod is None or args.no_usb else UsbLink(m, args.ringpod)  # plugged in from power-on
    rom = SystemMemory(m, usb.host if usb else None)
    if args.count_instructions:
        m.count_instructions()

    # -- boot, then normal running: no host, no switch changes --
    boot_end = int(0.1 * SYSCLK)
    m.run(boot_end)
    before = Snapshot(m)
    m.run(boot_end + int(args.seconds * SYSCLK))
    after = Snapshot(m)
    wall_run = time.time() - wall0

    rcc, acr = m.rcc.instance, m.flash.acr
    pll = rcc.PLLCFGR
    pll_m, pll_n, pll_p, pll_q = pll & 0x3F, (pll >> 6) & 0x1FF, 2 * (((pll >> 16) & 3) + 1), (pll >> 24) & 0xF
    vco = 25_000_000 // pll_m * pll_n
    cfgr = rcc.CFGR
    ppre1, ppre2 = (cfgr >> 10) & 7, (cfgr >> 13) & 7
    clocks = {
        "HSE on+ready, oscillator (not bypass)": rcc.CR & (1 << 16) and rcc.CR & (1 << 17) and not rcc.CR & (1 << 18),
        "PLL on+ready from HSE": rcc.CR & (1 << 24) and rcc.CR & (1 << 25) and pll & (1 << 22),
        "M/N/P/Q = 25/384/4/8": (pll_m, pll_n, pll_p, pll_q) == (25, 384, 4, 8),
        "SYSCLK = PLL (SWS)": (cfgr >> 2) & 3 == 2,
        "AHB /1, APB1 /2, APB2 /1": (cfgr >> 4) & 0xF == 0 and ppre1 == 4 and ppre2 < 4,
        "flash latency 3 WS": acr & 0xF == 3,
    }
    bad = [k for k, ok in clocks.items() if not ok]
    c.check("boot-clocks", not bad and m.rcc.sysclk_hz() == 96_000_000 and vco // pll_q == 48_000_000,
            f"SYSCLK {m.rcc.sysclk_hz() / 1e6:g} MHz (VCO {vco / 1e6:g} MHz / P {pll_p}), USB {vco / pll_q / 1e6:g} MHz, "
            f"APB1 {96 / (2 ** (ppre1 - 3) if ppre1 >= 4 else 1):g} MHz, FLASH_ACR {acr:#06x} "
            f"(LATENCY {acr & 0xF}, RM0383 3.4: 3 WS for 90-100 MHz at 2.7-3.6 V)" + (f"; wrong: {', '.join(bad)}" if bad else ""))

    fault = m.fault or (p.faults and f"{p.faults[0][0]} entered at {ms(p.faults[0][1]):.2f} ms") or (
        m.resets and f"{len(m.resets)} resets: {', '.join(f'{cause} at {ms(t):.1f} ms' for t, cause in m.resets[:3])}")
    c.check("boot-no-fault", not fault and not m.resets,
            fault or f"no HardFault, DefaultHandler, panic or emulator fault; no reset; "
            + ", ".join(f"{label} " + (f"at {ms(p.reached[label]):.2f} ms" if label in p.reached else
                                      "inlined into its caller" if label in p.inlined else "not reached")
                        for label in ("board::start", "Executor::run")))

    stack_top, stack_floor = ram[0] + ram[1], m.elf.address("_stack_end")
    deepest = min(m.stack_depth_lowest(), m.stack_low)
    c.check("boot-stack", stack_floor <= deepest < stack_top and m.stack_low >= stack_floor,
            f"deepest stack write {deepest:#010x}: {stack_top - deepest} of {stack_top - stack_floor} bytes between "
            f"_stack_end {stack_floor:#010x} and the top of RAM (memory.x {ram[0]:#010x}+{ram[1] // 1024}K); "
            f"lowest SP seen {m.stack_low:#010x}")

    tasks = ["control_task", "inputs_task", "usb_task", "link_task", "uart_link_task", "settings_task", "steps_task"]
    missing = [t for t in tasks if t not in p.polled]
    steps_ipsr = sorted(p.polled.get("steps_task", ()))
    # The board's start spawns every task: when LTO inlined it (no symbol to break on), its tasks polled say it ran.
    started = "board::start" in p.reached or "board::start" in p.inlined
    c.check("tasks-reached", not missing and steps_ipsr == [16 + 71] and started,
            f"polled: {', '.join(f'{t} (IPSR {sorted(v)})' for t, v in sorted(p.polled.items()))}; "
            f"steps_task runs in USART6's interrupt (IPSR 87)" + (f"; never polled: {missing}" if missing else ""))

    # -- the step generator: TIM1 update -> DMA2 stream 5 channel 6 -> GPIOB.BSRR --
    tim1, st = m.tim["tim1"], m.dma["dma2"].streams[5]
    slot_ns = source_constant("STEP_SLOT_NS")
    # Two periods of the 1 kHz control tick: the half-transfer and transfer-complete interrupts are the boundaries.
    ring = 2 * (1_000_000 // slot_ns)
    # The ring is a static of the board module (wherever its set-up function lives).
    ring_buf = m.elf.one(r"board::(\w+::)*(\{\{closure\}\}::)?RING_BUF$")[1]
    arr = SYSCLK * slot_ns // 1_000_000_000 - 1
    config = {
        f"TIM1 PSC 0 ARR {arr}": tim1.psc == 0 and tim1.arr == arr,
        "TIM1 CEN, DIER.UDE": tim1.cr1 & T.CEN and tim1.dier & T.UDE,
        "S5 CHSEL 6": st.channel == 6,
        "memory-to-peripheral, circular, MINC, 32-bit": (st.cr >> 6) & 3 == 1 and st.cr & D.CIRC
        and st.cr & D.MINC and not st.cr & D.PINC and (st.cr >> 11) & 3 == 2 and (st.cr >> 13) & 3 == 2,
        "HTIE+TCIE": st.cr & D.HTIE and st.cr & D.TCIE,
        "PAR = GPIOB.BSRR": st.par == GPIOB_BSRR,
        f"M0AR = RING_BUF, NDTR {ring}": st.m0ar == ring_buf and st.reload == ring,
    }
    bad = [k for k, ok in config.items() if not ok]
    c.check("steps-config", not bad and st.cr & D.EN,
            f"TIM1 PSC {tim1.psc} ARR {tim1.arr} ({(tim1.arr + 1) * 1e9 / SYSCLK:g} ns) DIER {tim1.dier:#06x}; "
            f"DMA2_S5CR {st.cr:#010x} (CHSEL {st.channel}) PAR {st.par:#010x} M0AR {st.m0ar:#010x} NDTR {st.reload}"
            + (f"; wrong: {', '.join(bad)}" if bad else ""))

    dt = after.t - before.t
    updates, items, bsrr = after.updates - before.updates, after.items - before.items, after.bsrr - before.bsrr
    expected = dt // (arr + 1)
    irqs = after.dma_irqs - before.dma_irqs
    c.check("steps-paced", abs(updates - expected) <= 1 and items == updates and bsrr == items
            and abs(irqs - 2 * items / ring) <= 2,
            f"over {ms(dt):.0f} ms: {updates} TIM1 updates (expected {expected}), {items} DMA words, "
            f"{bsrr} GPIOB.BSRR writes by the DMA, {irqs} DMA2_STREAM5 interrupts (HT+TC every {ring // 2} words: "
            f"{2 * items / ring:.1f})")

    gpiob = m.gpio["b"]
    step_edges = sum(gpiob.edges(pin, gpiob.rises) for pin in STEP_PINS)
    odr = gpiob.instance.ODR
    c.check("steps-idle", step_edges == 0 and odr >> ENABLE_N & 1 and not odr >> LOGIC_RELAY & 1
            and not odr >> POWER_RELAY & 1,
            f"no host command: {step_edges} STEP edges on PB0-PB5; ENABLE (PB13, active low) {odr >> ENABLE_N & 1}, "
            f"relays PB14/PB15 {odr >> LOGIC_RELAY & 1}/{odr >> POWER_RELAY & 1}; GPIOB.ODR {odr:#06x}")

    # -- the watchdog --
    iw = m.iwdg
    feeds = [t for t in iw.reloads if before.t <= t < after.t]
    config_feeds = [t for t in iw.config_reloads if before.t <= t < after.t]
    periods = p.periods_between(before.t, after.t)
    gaps = [b - a for a, b in zip(feeds, feeds[1:])]
    timeout = iw.rlr_act * iw.tick(iw.pr_act)
    # each control period (ticked or passed: `Controller::advance_clock`) ends with one feed, so periods and feeds
    # alternate (a period's clock comes before its feed at the same time); a feed of a timer of its own drifts
    # against the control loop's schedule and breaks the alternation where the two cross. The window's edges may
    # split one period from its feed.
    marks = sorted([(t, 0) for t in p.periods if before.t <= t < after.t] + [(t, 1) for t in feeds])
    doubled = [round(ms(a[0]), 3) for a, b in zip(marks, marks[1:]) if a[1] == b[1]]
    c.check("watchdog-fed", iw.started and gaps and max(gaps) < timeout and not m.resets and periods > 0
            and abs(len(feeds) - periods) <= 1 and not config_feeds and not doubled,
            f"IWDG PR {iw.pr_act} (/{4 << iw.pr_act}) RLR {iw.rlr_act}: timeout {ms(timeout):.0f} ms at LSI 32 kHz; "
            f"fed {len(feeds)} times in {ms(dt):.0f} ms ({len(config_feeds)} by a change of its configuration), "
            f"{periods} control periods ticked or passed, each followed by its feed before the next"
            + (f" but at {doubled[:4]} ms ({len(doubled)} times: two periods or two feeds in a row)" if doubled else "")
            + f"; longest gap {ms(max(gaps or [0])):.2f} ms")
    priority_check(c, m)
    inputs_check(c, m, plant)

    # -- settings flash --
    erased = all(b == 0xFF for b in m.uc.mem_read(SETTINGS[0], SETTINGS[1] - SETTINGS[0]))
    c.check("flash-erased", erased and p.settings_reads > 0 and p.settings_not_erased == 0,
            f"sectors 6-7 read 0xFF; settings restore read them {p.settings_reads} times, all erased: nothing "
            f"stored, the compiled-in configuration runs")
    outside = [(a, s) for a, s in m.flash.programs if not SETTINGS[0] <= a < SETTINGS[1]]
    bad_erase = [n for n in m.flash.erases if n not in (6, 7)]
    c.check("flash-writes", not outside and not bad_erase and not m.flash.rejected,
            f"{len(m.flash.programs)} programmed words, {len(m.flash.erases)} sector erases, "
            f"{len(m.flash.rejected)} rejected stores; outside sectors 6-7: "
            f"{[hex(a) for a, _ in outside] + [f'sector {n}' for n in bad_erase] or 'none'}"
            + (f"; rejected at {[(hex(a), sector_of(a), why) for a, _, why in m.flash.rejected[:3]]}"
               if m.flash.rejected else ""))

    # -- the watchdog resets a stalled control loop: the control task alone stops, every timer runs on --
    held_at = m.now
    feeds_before = iw.reloads  # the reset starts a new list
    p.stall("control_task")
    m.run(held_at + int(0.2 * SYSCLK))
    last_feed = feeds_before[-1] if feeds_before else 0
    reset = m.resets[0] if m.resets else None
    after_reset = m.now
    m.run(after_reset + int(0.3 * SYSCLK))
    csr_after = [v for t, v in p.csr_reads if reset and t >= reset[0]]
    log.poll()
    said = [text for t, level, text in log.lines if reset and t >= reset[0] and level == "error"]
    refeeds = [t for t in m.iwdg.reloads if reset and t > reset[0]]
    since_reset = m.now - reset[0] if reset else 0
    c.check("watchdog-reset", reset is not None and reset[1] == "IWDG" and csr_after
            and reset[0] - held_at <= timeout + SYSCLK // 1000
            and csr_after[0] & IWDGRSTF and m.rcc.instance.CSR & IWDGRSTF == 0 and len(refeeds) > ms(since_reset) * 0.9
            and any("the last reset was the watchdog's" in text for text in said)
            and m.fault is None,
            (f"the control task stalled from {ms(held_at):.1f} ms (TIM5 and the other tasks running): IWDG reset at "
             f"{ms(reset[0]):.1f} ms ({ms(reset[0] - last_feed):.1f} ms after the last feed, "
             f"{ms(reset[0] - held_at):.1f} after the stall; at most {ms(timeout):.0f} + 1); after the reset the firmware read "
             f"RCC_CSR {csr_after[0] if csr_after else 0:#010x} (IWDGRSTF {bool(csr_after and csr_after[0] & IWDGRSTF)}) "
             f"and cleared it (RMVF), logged {said[0].split(' ms ', 1)[-1] if said else 'no error'!r}, fed the watchdog {len(refeeds)} times in the "
             f"{ms(since_reset):.0f} ms after the reset"
             if reset else f"no reset within 200 ms of stalling the control task (fault: {m.fault})"))

    p.drop_task_probes()

    # -- the host link on USART1: the real CLI over a pty --
    if args.ringpod:
        serial_checks(m, p, log, plant, args.ringpod, args.hold_ups, usb, args.usb_full, rom,
                      renamed, client, scratch)
    if not args.ringpod:
        pins_check(c, plant, plant.ignored, plant.dir_undriven)
    log_check(m, log)
    if args.ringpod:
        c.check("cli-exits", not Cli.unexpected,
                "every `ringpod` run ended with the exit status its check expects"
                + "".join(f"; {r}" for r in Cli.unexpected[:4]))
    c.check("run-limits", not m.over_limit,
            f"{m.now / SYSCLK:.1f} simulated s (at most {args.max_sim_s}), {time.time() - wall0:.0f} wall s (at "
            f"most {args.max_wall_s})" + (f"; stopped: {m.over_limit}" if m.over_limit else ""))

    wall = time.time() - wall0
    sim = m.now / SYSCLK
    print(f"rehost: {sim:.2f} simulated s in {wall:.1f} s wall ({wall / sim:.2f} s per simulated s; "
          f"normal running {wall_run:.1f} s); the host link over USART1 and a pty")
    if args.count_instructions:
        print(f"rehost: {m.instructions} instructions in {sim:.2f} simulated s ({m.instructions / sim / 1e6:.2f} M/s "
              f"simulated, {100 * m.instructions / m.now:.1f}% of the cycles), {m.instructions / wall / 1e6:.2f} M/s wall")
    print(f"{c.passed} passed, {c.failed} failed")
    return 0 if c.failed == 0 else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Enough:
        print(f"{CHECKS.passed} passed, {CHECKS.failed} failed")
        sys.exit(0 if CHECKS.failed == 0 else 1)
    except Exception as e:  # a harness error is a failed check, said as one, not a traceback alone
        import traceback

        traceback.print_exc()
        print(f"FAIL harness: {type(e).__name__}: {e}")
        print(f"{CHECKS.passed} passed, {CHECKS.failed + 1} failed")
        sys.exit(1)
