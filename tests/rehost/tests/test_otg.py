import struct
import unittest

from models import otg as O
from models.otg import OtgFs
from tests.helpers import Lines


def device(lines=None, clocked=True, sensing=False, vbus_on_pa9=False):
    """A core configured as embassy's driver leaves it after a bus reset: FIFOs sized, EP0 and a bulk pair."""
    o = OtgFs(lines or Lines(), clocked=lambda: clocked, vbus_on_pa9=vbus_on_pa9)
    o.vbus = True
    o.write(O.GCCFG, 4, O.PWRDWN | (O.VBUSBSEN if sensing else O.NOVBUSSENS))
    o.write(O.GRXFSIZ, 4, 0x3E)
    o.write(O.DIEPTXF0, 4, 16 << 16 | 0x3E)
    o.write(0x104, 4, 16 << 16 | 0x4E)  # DIEPTXF1
    o.write(O.GAHBCFG, 4, 1)
    o.write(O.GINTMSK, 4, O.RXFLVL | O.USBRST | O.ENUMDNE | O.IEPINT | O.OEPINT)
    o.write(O.DIEPMSK, 4, O.XFRC)
    o.write(O.DOEPMSK, 4, O.STUP)
    o.write(O.DAINTMSK, 4, 0x0003_0003)
    o.write(O.DIEPCTL + 0x20, 4, O.USBAEP | 2 << 18 | 1 << 22 | 64)  # EP1 IN bulk, TX FIFO 1
    o.write(O.DOEPCTL + 0x20, 4, O.USBAEP | 2 << 18 | 64)  # EP1 OUT bulk
    o.write(O.DOEPTSIZ + 0x20, 4, 1 << 19 | 64)
    return o


class OtgRegisterTest(unittest.TestCase):
    def test_core_reset_completes_and_ahb_is_idle(self):
        o = OtgFs()
        o.write(O.GRSTCTL, 4, O.CSRST)
        self.assertEqual(o.read(O.GRSTCTL, 4), O.AHBIDL)

    def test_gintsts_is_rc_w1_and_device_mode(self):
        o = device()
        o.bus_reset()
        self.assertEqual(o.read(O.GINTSTS, 4) & (O.USBRST | 1), O.USBRST)
        o.write(O.GINTSTS, 4, O.USBRST)
        self.assertEqual(o.read(O.GINTSTS, 4) & O.USBRST, 0)

    def test_unclocked_core_reads_zero_and_never_attaches(self):
        o = device(clocked=False)
        self.assertEqual(o.read(O.GRSTCTL, 4), 0)
        self.assertFalse(o.attached())

    def test_attach_needs_the_transceiver_and_a_valid_session(self):
        o = device()
        self.assertTrue(o.attached())
        o.write(O.DCTL, 4, 2)  # SDIS
        self.assertFalse(o.attached())
        o.write(O.DCTL, 4, 0)
        o.write(O.GCCFG, 4, O.NOVBUSSENS)  # transceiver powered down
        self.assertFalse(o.attached())
        # VBUS sensing on a board without VBUS on PA9: the session never becomes valid
        self.assertFalse(device(sensing=True).attached())
        self.assertTrue(device(sensing=True, vbus_on_pa9=True).attached())

    def test_interrupt_follows_status_and_mask(self):
        lines = Lines()
        o = device(lines)
        o.write(O.GINTMSK, 4, 0)
        o.bus_reset()
        self.assertEqual(lines.pended, [])
        o.write(O.GINTMSK, 4, O.USBRST)
        self.assertEqual(lines.pended, [O.IRQ])


class OtgTransferTest(unittest.TestCase):
    def test_setup_lands_in_rx_fifo_and_pop_raises_stup(self):
        o = device()
        self.assertEqual(o.setup(0, bytes(range(8))), "ACK")
        self.assertTrue(o.read(O.GINTSTS, 4) & O.RXFLVL)
        status = o.read(O.GRXSTSP, 4)
        self.assertEqual(((status >> 17) & 0xF, (status >> 4) & 0x7FF, status & 0xF), (O.SETUP_DATA, 8, 0))
        words = [o.read(O.FIFO, 4), o.read(O.FIFO, 4)]
        self.assertEqual(struct.pack("<II", *words), bytes(range(8)))
        self.assertEqual((o.read(O.GRXSTSP, 4) >> 17) & 0xF, O.SETUP_DONE)
        self.assertEqual(o.read(O.DOEPINT, 4), O.STUP)
        self.assertTrue(o.read(O.GINTSTS, 4) & O.OEPINT)
        self.assertIsNone(o.setup(3, bytes(8)))  # not this device's address

    def test_out_is_nakked_until_the_application_clears_nak(self):
        o = device()
        self.assertEqual(o.out(0, 1, b"abc"), "ACK")
        self.assertEqual(o.out(0, 1, b"def"), "NAK")  # NAK set after the packet
        o.read(O.GRXSTSP, 4)
        self.assertEqual(o.read(O.FIFO, 4), int.from_bytes(b"abc\0", "little"))
        self.assertEqual((o.read(O.GRXSTSP, 4) >> 17) & 0xF, O.OUT_DONE)  # a short packet ends the transfer
        o.write(O.DOEPCTL + 0x20, 4, o.read(O.DOEPCTL + 0x20, 4) | O.CNAK)
        self.assertEqual(o.out(0, 1, b"def"), "ACK")
        o.write(O.DOEPCTL + 0x20, 4, O.USBAEP | O.STALL)
        self.assertEqual(o.out(0, 1, b"x"), "STALL")

    def test_in_waits_for_the_whole_packet_then_completes(self):
        o = device()
        self.assertEqual(o.in_(0, 1), "NAK")
        o.write(O.DIEPTSIZ + 0x20, 4, 1 << 29 | 1 << 19 | 6)
        o.write(O.DIEPCTL + 0x20, 4, o.read(O.DIEPCTL + 0x20, 4) | O.EPENA | O.CNAK)
        o.write(O.FIFO * 2, 4, int.from_bytes(b"ring", "little"))
        self.assertEqual(o.in_(0, 1), "NAK")  # 4 of 6 bytes in the FIFO
        o.write(O.FIFO * 2, 4, int.from_bytes(b"po\0\0", "little"))
        self.assertEqual(o.in_(0, 1), b"ringpo")
        self.assertFalse(o.read(O.DIEPCTL + 0x20, 4) & O.EPENA)
        self.assertEqual(o.read(O.DIEPINT + 0x20, 4) & O.XFRC, O.XFRC)
        self.assertEqual(o.read(O.DTXFSTS + 0x20, 4), 16)

    def test_zero_length_in_packet(self):
        o = device()
        o.write(O.DIEPTSIZ + 0x20, 4, 1 << 19)
        o.write(O.DIEPCTL + 0x20, 4, o.read(O.DIEPCTL + 0x20, 4) | O.EPENA | O.CNAK)
        self.assertEqual(o.in_(0, 1), b"")

    def test_bus_reset_deactivates_endpoints_and_address_takes_after_status(self):
        o = device()
        o.write(O.DCFG, 4, 5 << 4)
        self.assertEqual(o.setup(0, bytes(8)), "ACK")  # the status stage still at address 0
        o.write(O.DIEPTSIZ, 4, 1 << 19)
        o.write(O.DIEPCTL, 4, O.EPENA | O.CNAK)
        self.assertEqual(o.in_(0, 0), b"")
        self.assertIsNone(o.in_(0, 0))
        self.assertEqual(o.in_(5, 0), "NAK")
        o.bus_reset()
        self.assertIsNone(o.out(0, 1, b"x"))  # EP1 no longer active
        self.assertFalse(o.read(O.DIEPCTL + 0x20, 4) & O.USBAEP)


if __name__ == "__main__":
    unittest.main()
