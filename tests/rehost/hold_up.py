"""Hold-ups mid-stream over USART1: the test machine's, and the board's own.

- The test machine holds the board up (the harness stops running the machine for 0.05, 0.5 and 2 wall seconds while
  `ringpod stream` runs, as a busy machine deschedules an emulator): device time stands still, the host's bytes wait
  in the pty, and the stream goes on with every setpoint applied and no restart.
- The board holds itself up (the CPU held for 30 simulated ms, within the watchdog's 48 ms, while its clocks,
  timers, DMA and USART run on, as a sector erase holds it: RM0383 3.5) while the platform moves: the step ring
  (two periods of STEP/DIR words played by a circular DMA into GPIOB's BSRR) is lapped, and the DMA plays the last
  periods' pulses again, steps the device never counted. The firmware finds the ring lapped and latches
  `MotionFault` (firmware/src/app/steps.rs): the counted steps no longer say where the axes are, so the platform
  stops and must be homed again, and the host's run ends on it (`device_stopped`, exit 5; `transport_lost`, exit 6,
  when the emulated board answers later than the host's patience). A board's hold-up
  while it moves is therefore a fault by design; a hold-up of device time that the ring outlives is the core's and
  the simulator's check (`Controller::pass`, host/tests/suite/link.rs), where the stream goes on. A ring that cannot be
  lapped (the DMA in normal mode, re-armed each period) would let the board ride through: not built.
"""

import json
import time

from machine import SYSCLK

STALLS_S = (0.05, 0.5, 2.0)
BOARD_STALL_S = 0.03
# The hold-ups come once the stream's setpoints flow (about 40 frames sent), not during the requests before it,
# whose answers the host waits 2 s for.
STREAMING_BYTES = 2_000


def _status(cli, port):
    try:
        return json.loads(cli.run("device", "status", *port).stdout)
    except ValueError:
        return {}


def _report(r):
    try:
        return json.loads(r.stdout)
    except ValueError:
        return {}


def _stream(cli, port, during, expect=(0,)):
    # 50 setpoints a second of the host's clock: the emulated board runs about 13 times slower than real time, and
    # the link (921,600 baud) carries that stream with room to spare, as a board's carries 1,000 a second.
    return cli.run("stream", *port, "--motion", "demo", "--duration", "4", "--rate", "50", "--quiet",
                   "--report-json", sim_limit_s=60, during=during, expect=expect)


def hold_up_checks(checks, m, cli, port):
    """After `stream_check`: the platform is homed and Ready, drivers enabled. The board's own hold-up last: it
    leaves the board in its latched fault."""
    _machine_hold_ups(checks, cli, port)
    _board_hold_up(checks, m, cli, port)


def _streaming(cli, since):
    """Whether the host's setpoints flow: it has sent more than a request's worth since `since` (bytes)."""
    return cli.bridge.to_board - since > STREAMING_BYTES


def _machine_hold_ups(checks, cli, port):
    for stall in STALLS_S:
        held = []
        since = cli.bridge.to_board

        def during(sim_s, stall=stall, held=held, since=since):
            if not held and _streaming(cli, since):
                held.append(sim_s)
                time.sleep(stall)  # the machine does not run: device time stands still, the pty fills

        r = _stream(cli, port, during)
        report = _report(r)
        checks.check(f"serial-hold-up-{int(stall * 1000)}ms",
                     held and r.code == 0 and report.get("outcome") == "followed" and report.get("restarts") == 0
                     and report.get("setpoints_applied") == report.get("setpoints_sent") and report.get("counts_agree"),
                     f"the board stopped for {stall} wall s at {held[0] if held else '-'} simulated s into "
                     f"`ringpod stream --motion demo --duration 4 --rate 50`: exit {r.code}, {report.get('outcome')}, "
                     f"{report.get('setpoints_applied')} of {report.get('setpoints_sent')} applied, "
                     f"{report.get('restarts')} restarts, counts agree {report.get('counts_agree')}"
                     + ("" if r.code == 0 else f"; {r}"))


def _board_hold_up(checks, m, cli, port):
    overruns0 = m.usart1.overruns
    held = []
    since = cli.bridge.to_board

    def during(sim_s):
        if not held and _streaming(cli, since):
            held.append(sim_s)
            m.cpu_held_until = m.now + int(BOARD_STALL_S * SYSCLK)

    r = _stream(cli, port, during, expect=(5, 6))
    report = _report(r)
    after = _status(cli, port)
    state = str(after.get("state", ""))
    # The host ends on the device's fault (exit 5, device_stopped); or, when the emulated board, 20 times slower
    # than real time, answers later than the host's patience of 5 wall seconds, on an unanswered link (exit 6).
    # Either way the run ends non-zero and the board is in its latched fault.
    ended = (r.code, report.get("outcome")) in ((5, "device_stopped"), (6, "transport_lost"))
    checks.check("serial-hold-up-board",
                 held and ended and "MotionFault" in state,
                 f"the CPU held for {BOARD_STALL_S * 1000:.0f} simulated ms at {held[0] if held else '-'} s into "
                 f"`ringpod stream --motion demo --duration 4 --rate 50`: exit {r.code}, {report.get('outcome')} "
                 f"({report.get('reason')}); the device's state {state}; USART1 overran "
                 f"{m.usart1.overruns - overruns0} times during the hold-up"
                 + ("" if ended else f"; {r}"))
