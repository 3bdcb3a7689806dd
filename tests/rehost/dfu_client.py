"""pydfuutil (a published Python port of dfu-util, pinned in requirements.txt) run as its own command line, its USB
reached through the harness's USB/IP server (`usbip.UsbipBackend`) instead of libusb:

    python dfu_client.py USBIP_PORT [pydfuutil's arguments...]

pydfuutil takes its PyUSB backend from `pydfuutil.DEFAULT_BACKEND`, which its modules read when they are imported:
it is set before they are.

One fault of pydfuutil 0.11.3 is worked around, in its device search only: for each interface PyUSB yields (one per
alternate setting) it lists every alternate setting of that interface again, so a device with four alternate
settings, as the STM32 ROM bootloader has, is found four times over and every download or upload stops with "More
than one DFU capable USB device found!" (dfu-util walks `interface[i].altsetting[j]` once). The repeats are dropped
after its search; its DfuSe code (the layout string's sectors, erase, address, download, status polls, upload,
leave) runs unchanged."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import pydfuutil  # noqa: E402

from usbip import UsbipBackend  # noqa: E402


def _once(probe):
    def probe_devices(ctx):
        probe(ctx)
        seen, last, at = set(), None, dfu_util.DfuUtil.dfu_root
        while at is not None:
            key = (at.bus, at.devnum, at.configuration, at.interface, at.altsetting)
            if key in seen:
                last.next = at.next
            else:
                seen.add(key)
                last = at
            at = at.next

    return probe_devices


if __name__ == "__main__":
    pydfuutil.DEFAULT_BACKEND = UsbipBackend(port=int(sys.argv[1]))
    from pydfuutil import dfu_util

    dfu_util.probe_devices = _once(dfu_util.probe_devices)
    from pydfuutil.__main__ import main

    sys.argv = ["pydfuutil", *sys.argv[2:]]
    sys.exit(main())
