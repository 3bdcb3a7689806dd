"""Checks of the board as wired: the interrupt priorities read from the NVIC, the inputs read through their pulls,
the STEP edges the drivers could see, the step signals' timing, and the e-stop chain opened mid-stream.

- `irq-priorities`: the NVIC's IPR bytes (PM0214 4.2.7: 0xE000_E400 + IRQn, the upper 4 bits implemented) of every
  enabled interrupt: the step generator's executor (USART6, IRQ 71) strictly above (a lower number than) USB, TIM5
  USART1 and the EXTI lines, so that none of their handlers delays the next period's rendering; only the DMA
  interrupts (the one that wakes it, DMA2 stream 5, IRQ 68, and USART1's rings' streams 2 and 7, whose handlers note
  progress and wake) may be at or above it. USART1's bytes go through DMA, so its handler (an idle line, an error)
  may wait.
- `inputs-wired` (after boot): every input the plant is wired to reads through the pull its wiring needs (the switches to ground
  the internal pull-up, the supply senses the pull-down, the e-stop chain its external pull-up and no internal
  one), and no read so far found one floating.
- `pins-electrical`: every STEP rise of the run reached a driver (STEP driven as an output, the drivers enabled,
  the motor supply on) and every step had its DIR driven, until the e-stop check opens the chain (a stop by design
  cuts the drivers' enable under the period that is playing); no edge on a pin of the step port that nothing is
  wired to (PB11: a STEP bit there is a step no driver sees).
- `estop`: the e-stop chain opened once the platform moves in `stream --motion demo`: the last STEP edge within
  the debounce (3 ms), the inputs task's sampling and the step ring's two periods; the supervisor latches
  `Fault(EStop)` and keeps only what that fault keeps (drivers disabled, motor power off, logic on); the CLI ends
  on the device's stop (exit 5); closed again, `device clear` leaves the fault.
"""

import json

from plant import ENABLE_N, LOGIC_EN, POWER_EN, PULLS

NVIC_IPR = 0xE000_E400
IRQ_NAMES = {6: "EXTI0", 7: "EXTI1", 8: "EXTI2", 9: "EXTI3", 10: "EXTI4", 23: "EXTI9_5", 37: "USART1",
             40: "EXTI15_10", 50: "TIM5", 67: "OTG_FS", 68: "DMA2_STREAM5", 71: "USART6"}
EXECUTOR, STEP_DMA = 71, 68
DMA_IRQS = {11, 12, 13, 14, 15, 16, 17, 47, 56, 57, 58, 59, 60, 68, 69, 70}  # RM0383 10.2: DMA1/DMA2 streams 0-7
MUST_BE_BELOW = ("OTG_FS", "TIM5", "USART1", "EXTI")
# the e-stop to the last STEP edge: 3 ms debounce, 1 ms sampling and tick, the ring's two 1 ms periods, and a
# period of margin for where in its period the chain opens
ESTOP_STOP_MS = 7.0


def ipr(m, irq):
    return m.read(NVIC_IPR + (irq & ~3), 4) >> (8 * (irq & 3)) & 0xFF


def priority_check(checks, m):
    enabled = sorted(m.nvic.enabled)
    prio = {irq: ipr(m, irq) >> 4 for irq in enabled}
    mine = prio.get(EXECUTOR)
    named = {IRQ_NAMES.get(irq, f"IRQ{irq}"): p for irq, p in prio.items() if irq not in DMA_IRQS or irq == STEP_DMA}
    # embassy enables every DMA stream's interrupt at init (`dma_interrupt_priority`); of them DMA2 stream 5 wakes
    # the executor, and streams 2 and 7 (USART1's rings) wake the link task
    dma = [irq for irq in enabled if irq in DMA_IRQS]
    wrong = [IRQ_NAMES.get(irq, f"IRQ{irq}") for irq in enabled
             if irq not in (EXECUTOR, *dma) and mine is not None and prio[irq] <= mine]
    covered = all(any(n.startswith(w) for n in named) for w in MUST_BE_BELOW)
    checks.check("irq-priorities", mine is not None and not wrong and covered
                 and prio.get(STEP_DMA, 16) <= mine,
                 f"NVIC IPR (PM0214 4.2.7, 4 bits; lower pre-empts) of the enabled interrupts: {named}; the step "
                 f"executor (USART6) at {mine}, above {', '.join(MUST_BE_BELOW)} (USART1 through DMA: no byte waits "
                 f"for its handler); the other {len(dma) - 1} DMA streams' interrupts (enabled by embassy; short "
                 f"handlers that wake a task) not counted" + (f"; not below it: {wrong}" if wrong else "")
                 + ("" if covered else "; not all of USB, USART1, TIM5 and EXTI enabled"))


def inputs_check(checks, m, plant):
    bad, seen = [], []
    for (port, pin), want in PULLS.items():
        g = m.gpio[port]
        name = f"P{port.upper()}{pin}"
        pull, mode = g.pull(pin), g.mode(pin)
        seen.append(f"{name} {['input', 'output', 'AF', 'analog'][mode]} pull {({1: 'up', 0: 'down'}).get(pull, 'none')}")
        if mode != 0 or pull != want:
            bad.append(name)
    floating = {f"P{port.upper()}{pin}": n for port in "ac" for pin, n in m.gpio[port].floating_reads.items() if n}
    checks.check("inputs-wired", not bad and not floating,
                 f"{'; '.join(seen)}; floating reads {floating or 'none'}"
                 + (f"; wrong mode or pull: {bad} (want {', '.join(f'{k[0]}{k[1]} {v}' for k, v in PULLS.items() if f'P{k[0].upper()}{k[1]}' in bad)})" if bad else ""))


def pins_check(checks, plant, ignored, undriven):
    from machine import SYSCLK

    def enable_before(t):
        last = [(round(c * 1000 / SYSCLK, 3), level) for c, level in plant.enable_changes if c <= t][-1:]
        nxt = [(round(c * 1000 / SYSCLK, 3), level) for c, level in plant.enable_changes if c > t][:1]
        return f"ENABLE changes around it {last + nxt}"

    at = [(round(t * 1000 / SYSCLK, 3), f"axis {a + 1}", why, enable_before(t)) for t, a, why in plant.ignored_at]
    stray = {f"PB{pin}": n for pin, n in sorted(plant.stray_edges.items())}
    checks.check("pins-electrical", not ignored and not undriven and not stray,
                 f"STEP rises that reached no driver: {dict(ignored) or 'none'}{f' (ms, axis, why: {at})' if at else ''}; "
                 f"steps with DIR undriven: {undriven} (until the e-stop check); edges on the step port's unwired "
                 f"pins (none of STEP, DIR, ENABLE, the relays): {stray or 'none'}")


def timing(plant, slot_us, both_ways):
    """(ok, detail) of the step signals since `plant.clear_timing()`: STEP high >= 2.5 us, DIR set-up and hold
    >= 5 us (FIRMWARE.md), and, when `both_ways`, at least one reversal seen."""
    width, setup, hold, reversals = plant.timing(slot_us)
    ok = (width is not None and width >= 2.5 and (setup is None or setup >= 5.0) and (hold is None or hold >= 5.0)
          and (not both_ways or (reversals and setup is not None and hold is not None)))
    return ok, (f"shortest STEP high {width} us (>= 2.5), DIR set-up {setup} us and hold {hold} us (>= 5) over "
                f"{reversals} reversals")


def _status(cli, port):
    try:
        return json.loads(cli.run("device", "status", *port).stdout)
    except ValueError:
        return {}


def estop_check(checks, m, cli, port, plant):
    """Homed and Ready: a stream, the e-stop chain opened once the platform moves, then closed and cleared."""
    from machine import SYSCLK

    moves, last, opened = [], [list(plant.position)], []

    def watch():
        if plant.position != last[0]:
            last[0] = list(plant.position)
            moves.append(m.now)

    m.observers.append(watch)

    def during(_sim_s):
        if not opened and len(moves) > 20:
            opened.append(m.now)
            plant.open_estop(True)

    r = cli.run("stream", *port, "--motion", "demo", "--duration", "4", "--rate", "50", "--quiet",
                "--report-json", sim_limit_s=30, during=during, expect=(5,))
    if opened:
        m.run(max(m.now, opened[0] + SYSCLK // 5))
    m.observers.remove(watch)
    odr = m.gpio["b"].instance.ODR
    supplies = (odr >> ENABLE_N & 1, odr >> LOGIC_EN & 1, odr >> POWER_EN & 1)
    status = _status(cli, port)
    after = [t for t in moves if opened and t > opened[0]]
    stop_ms = (max(after) - opened[0]) * 1000 / SYSCLK if after else 0.0
    plant.open_estop(False)
    m.run(m.now + SYSCLK // 50)
    clear = cli.run("device", "clear", *port)
    cleared = _status(cli, port)
    checks.check("estop", opened and r.code == 5 and stop_ms <= ESTOP_STOP_MS and supplies == (1, 1, 0)
                 and "EStop" in str(status.get("state")) and clear.code == 0
                 and "Fault" not in str(cleared.get("state")),
                 f"e-stop (PA0) opened {opened[0] * 1000 / SYSCLK if opened else '-'} ms into the run, mid-stream: "
                 f"the last STEP edge {stop_ms:.1f} ms after (at most {ESTOP_STOP_MS}); `stream` exit {r.code} "
                 f"(5: the device stopped); ENABLE, LOGIC, POWER {supplies} (want 1, 1, 0: drivers disabled, logic "
                 f"kept, motor power off); state {status.get('state')}; closed again, `device clear` exit "
                 f"{clear.code}: state {cleared.get('state')}" + ("" if r.code == 5 else f"; {r}; the device's bad frames {status.get('bad_frames')}, "
                                              f"refusals {status.get('rejected')}"))
