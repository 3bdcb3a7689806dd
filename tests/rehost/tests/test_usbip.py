import socket
import struct
import unittest

import usb.core
import usb.util

from dfu_client_check import ModelOnWire
from models import dfuse_rom as D
from usbip import LIBUSB_ERROR_PIPE, OP_REP_DEVLIST, OP_REQ_DEVLIST, VERSION, UsbipBackend, UsbipServer


class UsbipTest(unittest.TestCase):
    def setUp(self):
        self.model = ModelOnWire()
        self.server = UsbipServer(self.model.descriptors, self.model.control)
        self.backend = UsbipBackend(port=self.server.port)

    def tearDown(self):
        self.server.close()

    def test_the_device_list_on_the_wire(self):
        # usbip_protocol.rst: OP_REP_DEVLIST, one device of 312 bytes, then 4 bytes per interface
        with socket.create_connection(("127.0.0.1", self.server.port)) as s:
            s.sendall(struct.pack(">HHI", VERSION, OP_REQ_DEVLIST, 0))
            reply = b""
            while chunk := s.recv(4096):
                reply += chunk
        self.assertEqual(struct.unpack_from(">HHII", reply), (0x0111, OP_REP_DEVLIST, 0, 1))
        record = reply[12:12 + 312]
        self.assertEqual(record[256:288].rstrip(b"\0"), b"1-1")
        self.assertEqual(struct.unpack_from(">IIIHHH", record, 288), (1, 2, 2, 0x0483, 0xDF11, 0x2200))
        self.assertEqual(record[-1], 1, "one interface")
        self.assertEqual(reply[12 + 312:], bytes([0xFE, 1, 2, 0]), "DFU mode: class FE, subclass 1, protocol 2")

    def test_pyusb_finds_reads_and_sees_a_stall(self):
        dev = usb.core.find(idVendor=0x0483, idProduct=0xDF11, backend=self.backend)
        self.assertIsNotNone(dev)
        self.assertEqual(usb.util.get_string(dev, dev.iProduct), "STM32  BOOTLOADER")
        cfg = dev.get_active_configuration()
        alts = [(i.bInterfaceNumber, i.bAlternateSetting) for i in cfg]
        self.assertEqual(alts, [(0, 0), (0, 1), (0, 2), (0, 3)])
        self.assertEqual(usb.util.get_string(dev, cfg[(0, 0)].iInterface), D.LAYOUTS[0])
        # the DfuSe functional descriptor follows the last alternate setting (libusb's `extra`)
        self.assertEqual(bytes(cfg[(0, 3)].extra_descriptors)[:2], b"\x09\x21")
        status = dev.ctrl_transfer(0xA1, 3, 0, 0, 6)
        self.assertEqual(list(status), [0, 0, 0, 0, D.DFU_IDLE, 0])
        # UPLOAD of block 0 out of state: a stall, as libusb reports one, then dfuERROR
        with self.assertRaises(usb.core.USBError) as stalled:
            dev.ctrl_transfer(0xA1, 2, 0, 0, 64)
        self.assertEqual(stalled.exception.backend_error_code, LIBUSB_ERROR_PIPE)
        self.assertEqual(dev.ctrl_transfer(0xA1, 5, 0, 0, 1)[0], D.ERROR)
        self.assertEqual(self.server.stalls, 1)

    def test_an_out_transfer_carries_its_data(self):
        dev = usb.core.find(idVendor=0x0483, idProduct=0xDF11, backend=self.backend)
        self.assertEqual(dev.ctrl_transfer(0x21, 1, 0, 0, b"\x21\x00\x40\x00\x08"), 5)  # Set Address Pointer
        while dev.ctrl_transfer(0xA1, 3, 0, 0, 6)[4] != D.DNLOAD_IDLE:
            pass
        self.assertEqual(self.model.rom.pointer, 0x0800_4000)


if __name__ == "__main__":
    unittest.main()
