"""USART1's line bridged to a pseudo-terminal, and the real `ringpod` CLI run against it while the machine runs.

The CLI opens the pty's device side (`--port /dev/pts/N`) as it would a USB-serial adapter wired to PA10/PA15.
Bytes the CLI writes are put on USART1's RX line (back to back at the baud rate the firmware set); bytes the
firmware sends are written to the pty as each frame's stop bit goes out. The bridge is polled between CPU chunks,
once a simulated millisecond.
"""

import os
import subprocess
import tempfile
import time
import tty

from machine import SYSCLK


class PtyBridge:
    def __init__(self, usart):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)  # no echo, no line editing: the framed bytes pass as they are
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)  # the device side stays open here, so clients may come and go
        self.usart = usart
        self.out = bytearray()
        self.to_board = self.to_host = 0
        usart.on_tx = self.out.append

    def hang_up(self):
        """The port gone, as Linux's CDC-ACM driver hangs up /dev/ttyACM* when the device leaves the bus: a client
        that holds it open reads EIO from then on."""
        os.close(self.slave)
        os.close(self.master)
        self.master = None

    def poll(self):
        if self.master is None:
            return
        try:
            data = os.read(self.master, 4096)
        except (BlockingIOError, OSError):  # nothing to read; EIO while no client has the port open
            data = b""
        if data:
            self.to_board += len(data)
            self.usart.feed(data)
        if self.out:
            try:
                n = os.write(self.master, bytes(self.out))
            except (BlockingIOError, OSError):
                n = 0
            self.to_host += n
            del self.out[:n]


# The CLI's waits for the board lengthened (host/src/link: RINGPOD_PATIENCE): the emulated board runs 13-55 times
# slower than real time, so an answer due within the CLI's 2 s comes after up to 110 wall s.
PATIENCE = "60"


def cli_env():
    return {**os.environ, "RINGPOD_PATIENCE": PATIENCE}


class Cli:
    """One `ringpod` command run to its end while the machine runs; its output and the simulated time it took.
    Every run whose exit status is not one its caller expects is kept in `Cli.unexpected` (the `cli-exits` check)."""

    unexpected = []

    def __init__(self, m, ringpod, bridge):
        self.m, self.ringpod, self.bridge = m, ringpod, bridge

    def run(self, *args, sim_limit_s=20.0, during=None, expect=(0,), hold=False):
        """`during(simulated_s)`, when given, is called between the machine's steps (every 5 simulated ms);
        `expect`: the exit statuses this run may end with (None: any); `hold`: the machine waits (device time stands
        still) until the CLI's first bytes are on the line, so that they arrive in the state the machine is in now."""
        cmd = [self.ringpod, *args]
        with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
            proc = subprocess.Popen(cmd, stdout=out, stderr=err, stdin=subprocess.DEVNULL, env=cli_env())
            sent, deadline = self.bridge.to_board, time.time() + 30
            while hold and self.bridge.to_board == sent and proc.poll() is None and time.time() < deadline:
                self.bridge.poll()
                time.sleep(0.002)
            start = self.m.now
            step = SYSCLK // 200
            while proc.poll() is None and self.m.now - start < sim_limit_s * SYSCLK and self.m.fault is None:
                self.m.run(self.m.now + step)
                if during is not None:
                    during((self.m.now - start) / SYSCLK)
            if proc.poll() is None:
                proc.kill()
                proc.wait()
            self.bridge.poll()
            out.seek(0)
            err.seek(0)
            r = Result(cmd, proc.returncode, out.read().decode(errors="replace"),
                       err.read().decode(errors="replace"), (self.m.now - start) / SYSCLK)
            if expect is not None and r.code not in expect:
                Cli.unexpected.append(r)
            return r


class Result:
    def __init__(self, cmd, code, stdout, stderr, sim_s):
        self.cmd, self.code, self.stdout, self.stderr, self.sim_s = cmd, code, stdout, stderr, sim_s

    def __str__(self):
        text = (self.stdout.strip() + " " + self.stderr.strip()).strip().replace("\n", " ")
        return f"`{' '.join(os.path.basename(a) if a.startswith('/') and 'pts' not in a else a for a in self.cmd)}` exit {self.code}: {text[:300]}"
