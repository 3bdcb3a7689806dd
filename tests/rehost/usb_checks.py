"""The USB link: the flashed firmware enumerated by `usb_host.UsbHost` on the OTG FS model, and the real `ringpod` CLI
driving it through a pty bridged to the bulk endpoints, as a PC's /dev/ttyACM0.

- `usb-enumerated`: the descriptors as a host reads them (VID:PID 1209:0001, the interface association, the CDC
  communication interface with its header, ACM and union functional descriptors and its interrupt endpoint, the
  data interface with a bulk OUT and a bulk IN endpoint of 64 bytes, the strings), the CDC-ACM line requests
  accepted, nothing stalled, the OTG FS interrupt enabled on the NVIC.
- `usb-status` and `usb-stream` (run.py's stream check): the same commands as over USART1, over USB; `links-both`:
  `device status` over both links at once, each answered on its own.
- `usb-home` (`--usb-full`): run.py's homing check over USB. Not in the default run: the CLI allows `device home`
  12,000 status polls 10 wall ms apart, and over USB a status (722 bytes, twelve packets) comes back in a fraction
  of the 7.8 ms it takes on USART1 at 921,600 baud, so the CLI polls several times as often per simulated second;
  with the machine loaded (about 30 wall s per simulated s) the polls ran out 4 of the 7.7 simulated s into homing.
- `usb-cable`: the cable pulled mid-stream (VBUS low, no SOF: the core suspends, the host's port
  is gone): the motion stops within the stream timeout and its braking, the supplies stay as the supervisor keeps
  them after a stop (a lost stream is no fault); plugged again, the host enumerates the device again and streams.
"""

import json
import struct
import subprocess
import tempfile

from machine import SYSCLK
from models.otg import IRQ
from serial_link import Cli, PtyBridge, cli_env
from usb_host import UsbHost

VID_PID = (0x1209, 0x0001)
# The serial number is the chip's unique ID (RM0383 39.1) as the machine models it: `Machine.uid_hex`.
STRINGS = {"manufacturer": "ringpod", "product": "ringpod motion controller"}
ENABLE_N, LOGIC_RELAY, POWER_RELAY = 13, 14, 15  # board::resources::PORT_MAP, pin table


class UsbLink:
    """The host on the bus, the pty its CDC-ACM port appears as, and a CLI runner on that port."""

    def __init__(self, m, ringpod):
        self.m = m
        self.host = UsbHost(m.otg, m.clock)
        m.timed.append(self.host)
        self.host.plug()
        self.ringpod = ringpod
        self.bridge = self.cli = None

    def open_port(self):
        self.bridge = PtyBridge(self.host)
        self.m.observers.append(self.bridge.poll)
        self.cli = Cli(self.m, self.ringpod, self.bridge)
        return ["--port", self.bridge.path]


def _interfaces(host):
    """The configuration's descriptors grouped: IADs, and per interface its descriptor, class ones and endpoints."""
    iads, ifaces, cur = [], [], None
    for kind, d in host.descriptors():
        if kind == 11:
            iads.append(d)
        elif kind == 4:
            cur = {"desc": d, "class": [], "endpoints": []}
            ifaces.append(cur)
        elif kind == 0x24 and cur:
            cur["class"].append(d[2])
        elif kind == 5 and cur:
            cur["endpoints"].append((d[2], d[3] & 3, struct.unpack_from("<H", d, 4)[0]))
    return iads, ifaces


def descriptor_check(checks, m, link):
    h = link.host
    dev = h.device or bytes(18)
    vid_pid = struct.unpack_from("<HH", dev, 8)
    want_strings = {**STRINGS, "serial": m.uid_hex()}
    strings = {name: h.strings.get(dev[14 + i]) for i, name in enumerate(want_strings)}
    iads, ifaces = _interfaces(h)
    want = {
        "VID:PID 1209:0001": vid_pid == VID_PID,
        "device class 0xEF/2/1 (interface association)": tuple(dev[4:7]) == (0xEF, 2, 1),
        "EP0 64 bytes": dev[7] == 64,
        "one IAD over interfaces 0-1, CDC ACM": [tuple(d[2:7]) for d in iads] == [(0, 2, 2, 2, 0)],
        "interface 0 CDC/ACM/none, header+ACM+union": len(ifaces) == 2 and tuple(ifaces[0]["desc"][5:8]) == (2, 2, 0)
        and ifaces[0]["class"] == [0, 2, 6],
        "interface 0: interrupt IN, 8 bytes": len(ifaces) == 2 and [(a >> 7, t, s) for a, t, s in ifaces[0]["endpoints"]]
        == [(1, 3, 8)],
        "interface 1 CDC data": len(ifaces) == 2 and ifaces[1]["desc"][5] == 0x0A,
        "interface 1: bulk OUT and IN, 64 bytes": len(ifaces) == 2
        and sorted((a >> 7, t, s) for a, t, s in ifaces[1]["endpoints"]) == [(0, 2, 64), (1, 2, 64)],
        "strings, the serial number the modelled unique ID": strings == want_strings,
        "configured, nothing stalled": h.configured and not h.stalls,
        "OTG_FS interrupt enabled": IRQ in m.nvic.enabled,
    }
    bad = [k for k, ok in want.items() if not ok]
    enumerated = [t for t, what in h.log if what == "configured"]
    checks.check("usb-enumerated", not bad,
                 f"{h.enumerations} enumerations (first configured at {enumerated[0] * 1000 / SYSCLK if enumerated else 0:.1f} "
                 f"ms); device descriptor {dev.hex()}, VID:PID {vid_pid[0]:04x}:{vid_pid[1]:04x}, {len(iads)} IAD, "
                 f"interfaces {[(tuple(i['desc'][5:8]), i['endpoints']) for i in ifaces]}, strings {strings}; "
                 f"{'SET_LINE_CODING 921600 8N1 and SET_CONTROL_LINE_STATE DTR|RTS accepted' if h.configured else 'not configured'}"
                 f"; bus log {[(round(t * 1000 / SYSCLK, 1), what) for t, what in h.log[-4:]]}; OTG_FS IRQ {IRQ} priority "
                 f"{m.nvic.priority(16 + IRQ) >> 4}" + (f"; wrong: {', '.join(bad)}" if bad else "")
                 + (f"; stalls {h.stalls}" if h.stalls else ""))


def status_check(checks, link, port):
    r = link.cli.run("device", "status", *port)
    try:
        status = json.loads(r.stdout)
    except ValueError:
        status = {}
    h = link.host
    checks.check("usb-status", r.code == 0 and "state" in status,
                 f"{r} | over USB: {link.bridge.to_board} bytes in ({h.out_packets} bulk OUT packets), "
                 f"{link.bridge.to_host} out (bulk IN packets by size {dict(sorted(h.in_sizes.items()))}); "
                 f"{r.sim_s:.2f} simulated s")


def usb_link_checks(checks, m, link, serial_port):
    """After the serial checks' settings check: the descriptors, status, and both links at once."""
    port = link.open_port()
    start = m.now  # `device restart` just reset the board: the host enumerates it again
    while not link.host.configured and m.now - start < 2 * SYSCLK:
        m.run(m.now + SYSCLK // 100)
    descriptor_check(checks, m, link)
    status_check(checks, link, port)
    both_links_check(checks, m, link, port, serial_port)


def usb_stream_checks(checks, m, link, plant, stream_check):
    """Homed (over USART1): a stream over USB."""
    port = ["--port", link.bridge.path]
    # from where the serial stream ended back to the home pose: the same rows, backwards
    stream_check(m, plant, link.cli, port, link.ringpod, name="usb-stream", backwards=True)


def usb_full_checks(checks, m, link, plant, homing_check):
    """`--usb-full`: homing over USB (the cable pulled and plugged again is in the default run)."""
    port = ["--port", link.bridge.path]
    homing_check(m, plant, link.cli, port, name="usb-home")


def both_links_check(checks, m, link, port, serial_port):
    """`device status` over USART1 and over USB at the same time: each link gets its own answer."""
    with tempfile.TemporaryFile() as out:
        proc = subprocess.Popen([link.ringpod, "device", "status", *serial_port], stdout=out,
                                stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, env=cli_env())
        r = link.cli.run("device", "status", *port)
        start = m.now
        while proc.poll() is None and m.now - start < 20 * SYSCLK:
            m.run(m.now + SYSCLK // 200)
        if proc.poll() is None:
            proc.kill()
        code = proc.wait()
        out.seek(0)
        serial_out = out.read().decode(errors="replace")
    answers = []
    for text in (r.stdout, serial_out):
        try:
            answers.append(json.loads(text).get("state"))
        except ValueError:
            answers.append(None)
    checks.check("links-both", r.code == 0 and code == 0 and None not in answers,
                 f"`device status` over USB exit {r.code} (state {answers[0]}) while the same over USART1 ran: "
                 f"exit {code} (state {answers[1]})")


def _odr(m):
    return m.gpio["b"].instance.ODR


def cable_check(checks, m, link, plant):
    """The cable pulled mid-stream, then plugged again (after the stream and homing checks: homed and Ready)."""
    port = ["--port", link.bridge.path]
    got = link.cli.run("device", "config", "get", "stream.timeout_ms", *port)
    try:
        timeout_ms = json.loads(got.stdout)["value"]
    except (ValueError, KeyError):
        timeout_ms = None
    moves = []  # simulated times at which the plant's position changed
    last = [list(plant.position)]

    def watch():
        if plant.position != last[0]:
            last[0] = list(plant.position)
            moves.append(m.now)

    m.observers.append(watch)
    pulled = []
    since = link.bridge.to_board

    def during(sim_s):
        if not pulled and link.bridge.to_board - since > 2_000 and moves:
            pulled.append(m.now)
            link.host.unplug()
            link.bridge.hang_up()

    r = link.cli.run("stream", *port, "--motion", "demo", "--duration", "4", "--rate", "50", "--quiet",
                     "--report-json", sim_limit_s=30, during=during, expect=(6,))
    if pulled:
        m.run(max(m.now, pulled[0] + SYSCLK // 2))
    m.observers.remove(watch)
    odr = _odr(m)
    supplies = (odr >> ENABLE_N & 1, odr >> LOGIC_RELAY & 1, odr >> POWER_RELAY & 1)
    stopped_ms = (max(moves) - pulled[0]) * 1000 / SYSCLK if pulled and moves else None
    # plugged again: the host enumerates the device again; a new port, as /dev/ttyACM0 comes back
    enumerations = link.host.enumerations
    link.host.plug()
    start = m.now
    while link.host.enumerations == enumerations and m.now - start < 2 * SYSCLK:
        m.run(m.now + SYSCLK // 100)
    again_ms = (m.now - start) * 1000 / SYSCLK
    m.observers.remove(link.bridge.poll)
    port = link.open_port()  # the port the enumeration made
    st = link.cli.run("device", "status", *port)
    try:
        status = json.loads(st.stdout)
    except ValueError:
        status = {}
    again = link.cli.run("stream", *port, "--motion", "demo", "--duration", "1", "--rate", "50", "--quiet",
                         "--report-json", sim_limit_s=30)
    try:
        report = json.loads(again.stdout)
    except ValueError:
        report = {}
    brake_ms = 150  # braking to rest at the acceleration limit from the demo motion's speed
    checks.check("usb-cable",
                 pulled and timeout_ms and stopped_ms is not None and stopped_ms <= timeout_ms + brake_ms
                 and r.code == 6 and supplies == (0, 1, 1) and link.host.enumerations == enumerations + 1
                 and status.get("state") == "Ready" and status.get("homed") and again.code == 0
                 and report.get("outcome") == "followed",
                 f"cable pulled {pulled[0] * 1000 / SYSCLK if pulled else '-'} ms into the run, mid-stream: the "
                 f"last STEP edge {stopped_ms if stopped_ms is None else round(stopped_ms, 1)} ms after it (stream "
                 f"timeout {timeout_ms} ms + braking, at most {brake_ms} ms); `ringpod stream` exit {r.code} (6: "
                 f"transport_lost, no answer within its patience); ENABLE, LOGIC, POWER {supplies} (0 = drivers "
                 f"enabled; 1 = relay on); plugged again: enumerated in "
                 f"{again_ms:.0f} ms, state {status.get('state')}, homed {status.get('homed')}; a new stream exit "
                 f"{again.code}: {report.get('outcome')}, {report.get('setpoints_applied')} of "
                 f"{report.get('setpoints_sent')} applied" + ("" if again.code == 0 else f"; {again}"))
