"""USB/IP for the harness's devices: a server that exports one device model, and a PyUSB backend that imports it,
so that a published USB client (PyUSB, and a DFU tool over it) reaches the model in userspace, without the kernel's
USB stack, which these machines lack.

The protocol is the Linux kernel's USB/IP (Documentation/usb/usbip_protocol.rst): on a TCP connection, OP_REQ_DEVLIST
/ OP_REP_DEVLIST lists the exported devices (then the connection closes); OP_REQ_IMPORT / OP_REP_IMPORT attaches one
by its bus id, after which the connection carries USBIP_CMD_SUBMIT / USBIP_RET_SUBMIT (one URB each, 48-byte
headers, the setup packet in CMD_SUBMIT, the data after the header: OUT data in the command, IN data in the reply)
and USBIP_CMD_UNLINK / USBIP_RET_UNLINK. All fields are big-endian (network byte order).

Only control transfers on endpoint 0 are served (the ROM bootloader's DFU interface has no other endpoint): a
request the device stalls is answered with status -EPIPE, as the kernel's stub reports a stall. The backend does
what the client machine's USB core does with an imported device before a program sees it (the device and
configuration descriptors read, configuration 1 set) and reports a stall as libusb does (LIBUSB_ERROR_PIPE).
"""

import socket
import struct
import threading

import usb.backend
import usb.core

VERSION = 0x0111
OP_REQ_DEVLIST, OP_REP_DEVLIST, OP_REQ_IMPORT, OP_REP_IMPORT = 0x8005, 0x0005, 0x8003, 0x0003
CMD_SUBMIT, CMD_UNLINK, RET_SUBMIT, RET_UNLINK = 1, 2, 3, 4
DIR_OUT, DIR_IN = 0, 1
EPIPE = 32
SPEED_FULL = 2  # enum usb_device_speed
BUSID = "1-1"
BUSNUM, DEVNUM = 1, 2


def _exact(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("USB/IP peer closed the connection")
        data += chunk
    return data


def _device_record(device, config):
    """struct usbip_usb_device: path, bus id, bus and device numbers, speed, then the device descriptor's fields."""
    vid, pid, bcd = struct.unpack_from("<HHH", device, 8)
    return (f"/sys/devices/rehost/usb{BUSNUM}/{BUSID}".encode().ljust(256, b"\0") + BUSID.encode().ljust(32, b"\0")
            + struct.pack(">IIIHHHBBBBBB", BUSNUM, DEVNUM, SPEED_FULL, vid, pid, bcd, device[4], device[5],
                          device[6], config[5], device[17], config[4]))


class UsbipServer:
    """Exports one device: `descriptors()` gives its (device, configuration) descriptors (None while there is none),
    `control(setup, data)` carries out a control transfer and returns the IN data (b"" for an OUT transfer) or None when the device stalls it."""

    def __init__(self, descriptors, control):
        self.descriptors, self.control = descriptors, control
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(2)
        self.port = self.server.getsockname()[1]
        self.urbs = 0
        self.stalls = 0
        self.unlinks = 0
        self.errors = []
        self.lock = threading.Lock()  # one transfer at a time on the device's bus
        threading.Thread(target=self._serve, daemon=True).start()

    def close(self):
        self.server.close()

    def _serve(self):
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            threading.Thread(target=self._connection, args=(conn,), daemon=True).start()

    def _connection(self, conn):
        try:
            with conn:
                self._session(conn)
        except ConnectionError:
            pass  # the client closed it
        except OSError as e:
            self.errors.append(str(e))

    def _session(self, conn):
        version, code, _status = struct.unpack(">HHI", _exact(conn, 8))
        device, config = self.descriptors() or (None, None)
        if code == OP_REQ_DEVLIST and device is None:  # nothing on the bus now
            conn.sendall(struct.pack(">HHII", VERSION, OP_REP_DEVLIST, 0, 0))
            return
        if code == OP_REQ_DEVLIST:
            # one device, then its interfaces: class, subclass, protocol, padding (of alternate setting 0)
            intf = _split(config)[1][0][0]
            conn.sendall(struct.pack(">HHII", VERSION, OP_REP_DEVLIST, 0, 1) + _device_record(device, config)
                         + bytes([intf[5], intf[6], intf[7], 0]))
            return
        if code != OP_REQ_IMPORT:
            return
        busid = _exact(conn, 32).rstrip(b"\0").decode()
        if busid != BUSID or device is None:
            conn.sendall(struct.pack(">HHI", VERSION, OP_REP_IMPORT, 1))
            return
        conn.sendall(struct.pack(">HHI", VERSION, OP_REP_IMPORT, 0) + _device_record(device, config))
        while True:
            command, seqnum, _devid, direction, ep = struct.unpack(">IIIII", _exact(conn, 20))
            body = _exact(conn, 28)
            if command == CMD_UNLINK:  # every URB is answered before the next is read: nothing left to unlink
                self.unlinks += 1
                conn.sendall(struct.pack(">IIIIIi", RET_UNLINK, seqnum, 0, 0, 0, 0) + bytes(24))
                continue
            _flags, length, _frame, _packets, _interval = struct.unpack_from(">IIiii", body)
            setup = body[20:28]
            data = _exact(conn, length) if direction == DIR_OUT else b""
            with self.lock:
                self.urbs += 1
                got = self.control(setup, data) if ep == 0 else None
            if got is None:
                self.stalls += 1
                reply, status, actual = b"", -EPIPE, 0
            else:
                reply = got[:length] if direction == DIR_IN else b""
                status, actual = 0, len(reply) if direction == DIR_IN else length
            conn.sendall(struct.pack(">IIIIIiiiii", RET_SUBMIT, seqnum, 0, 0, 0, status, actual, 0, -1, 0)
                         + bytes(8) + reply)


# -- the client side: a PyUSB backend (usb.backend.IBackend) over USB/IP --

LIBUSB_ERROR_PIPE = -9  # libusb.h: what libusb reports for a stall, and what DFU tools test for


class _Descriptor:
    def __init__(self, **fields):
        self.__dict__.update(fields)


class _Imported:
    """An imported device: its connection and the descriptors read through it."""

    def __init__(self, address, busid):
        self.sock = socket.create_connection(address)
        self.sock.sendall(struct.pack(">HHI", VERSION, OP_REQ_IMPORT, 0) + busid.encode().ljust(32, b"\0"))
        _version, _code, status = struct.unpack(">HHI", _exact(self.sock, 8))
        if status != 0:
            raise usb.core.USBError(f"USB/IP: import of {busid} refused (status {status})")
        record = _exact(self.sock, 312)
        self.busnum, self.devnum, self.speed = struct.unpack_from(">III", record, 288)
        self.seqnum = 0
        self.lock = threading.Lock()
        # what the client's USB core does with a new device: its descriptors read, a configuration set
        self.device = self.control(0x80, 6, 0x0100, 0, 18)
        head = self.control(0x80, 6, 0x0200, 0, 9)
        self.config = self.control(0x80, 6, 0x0200, 0, struct.unpack_from("<H", head, 2)[0])
        self.control(0x00, 9, self.config[5], 0, b"")
        self.configuration = self.config[5]

    def __del__(self):
        self.sock.close()

    def control(self, rt, req, value, index, data_or_length):
        """One control URB; the IN data, or the OUT length. A stall raises USBError (errno EPIPE, libusb's code)."""
        with self.lock:
            self.seqnum += 1
            out = rt & 0x80 == 0
            data = bytes(data_or_length) if out else b""
            length = len(data) if out else data_or_length
            setup = struct.pack("<BBHHH", rt, req, value, index, length)
            self.sock.sendall(struct.pack(">IIIIIIIiii", CMD_SUBMIT, self.seqnum, self.busnum << 16 | self.devnum,
                                          DIR_OUT if out else DIR_IN, 0, 0, length, 0, 0, 0) + setup + data)
            head = _exact(self.sock, 48)
            _command, seqnum, _d, _dir, _ep, status, actual = struct.unpack_from(">IIIIIii", head)
            reply = _exact(self.sock, actual) if not out else b""
        if seqnum != self.seqnum:
            raise usb.core.USBError(f"USB/IP: reply to URB {seqnum}, not {self.seqnum}")
        if status == -EPIPE:
            raise usb.core.USBError("Pipe error", LIBUSB_ERROR_PIPE, EPIPE)
        if status != 0:
            raise usb.core.USBError(f"USB/IP: URB status {status}", status, -status)
        return actual if out else reply


def _split(config):
    """The configuration descriptor: its own extra bytes, and each interface descriptor with the descriptors after
    it up to the next interface (its class-specific ones, as libusb gives them in `extra`)."""
    i, extra, intfs = config[0], bytearray(), []
    while i + 1 < len(config) and config[i]:
        d = config[i:i + config[i]]
        if d[1] == 4:
            intfs.append([d, bytearray()])
        elif d[1] != 5:
            (intfs[-1][1] if intfs else extra).extend(d)
        i += config[i]
    return bytes(extra), intfs


class UsbipBackend(usb.backend.IBackend):
    """PyUSB's backend interface (usb/backend/__init__.py) over a USB/IP server's exported devices."""

    def __init__(self, host="127.0.0.1", port=3240):
        self.address = (host, port)

    def enumerate_devices(self):
        sock = socket.create_connection(self.address)
        with sock:
            sock.sendall(struct.pack(">HHI", VERSION, OP_REQ_DEVLIST, 0))
            _version, _code, _status, count = struct.unpack(">HHII", _exact(sock, 12))
            busids = []
            for _ in range(count):
                record = _exact(sock, 312)
                busids.append(record[256:288].rstrip(b"\0").decode())
                _exact(sock, 4 * record[311])
        for busid in busids:
            yield _Imported(self.address, busid)

    def get_device_descriptor(self, dev):
        names = ("bLength bDescriptorType bcdUSB bDeviceClass bDeviceSubClass bDeviceProtocol bMaxPacketSize0 idVendor "
                 "idProduct bcdDevice iManufacturer iProduct iSerialNumber bNumConfigurations").split()
        fields = dict(zip(names, struct.unpack("<BBHBBBBHHHBBBB", dev.device)))
        return _Descriptor(**fields, address=dev.devnum, bus=dev.busnum, port_number=1, port_numbers=(1,),
                           speed=dev.speed)

    def get_configuration_descriptor(self, dev, config):
        if config != 0:
            raise IndexError("one configuration")
        names = ("bLength bDescriptorType wTotalLength bNumInterfaces bConfigurationValue iConfiguration bmAttributes "
                 "bMaxPower")
        extra, _ = _split(dev.config)
        return _Descriptor(**dict(zip(names.split(), struct.unpack_from("<BBHBBBBB", dev.config))),
                           extra_descriptors=list(extra))

    def get_interface_descriptor(self, dev, intf, alt, config):
        _, intfs = _split(dev.config)
        found = [(d, e) for d, e in intfs if d[2] == intf and d[3] == alt]
        if config != 0 or not found:
            raise IndexError(f"no interface {intf} alternate setting {alt}")
        d, extra = found[0]
        names = ("bLength bDescriptorType bInterfaceNumber bAlternateSetting bNumEndpoints bInterfaceClass "
                 "bInterfaceSubClass bInterfaceProtocol iInterface").split()
        return _Descriptor(**dict(zip(names, d)), extra_descriptors=list(extra))

    def get_endpoint_descriptor(self, dev, ep, intf, alt, config):
        raise IndexError("endpoint 0 only")

    def open_device(self, dev):
        return dev

    def close_device(self, dev_handle):
        pass

    def set_configuration(self, dev_handle, config_value):
        dev_handle.control(0x00, 9, config_value, 0, b"")
        dev_handle.configuration = config_value

    def get_configuration(self, dev_handle):
        return dev_handle.configuration

    def set_interface_altsetting(self, dev_handle, intf, altsetting):
        dev_handle.control(0x01, 11, altsetting, intf, b"")

    def claim_interface(self, dev_handle, intf):
        pass  # a program on the client owns the imported device: no kernel driver to take it from

    def release_interface(self, dev_handle, intf):
        pass

    def ctrl_transfer(self, dev_handle, bmRequestType, bRequest, wValue, wIndex, data, timeout):
        if bmRequestType & 0x80 == 0:
            return dev_handle.control(bmRequestType, bRequest, wValue, wIndex, data.tobytes())
        got = dev_handle.control(bmRequestType, bRequest, wValue, wIndex, len(data) * data.itemsize)
        data[:len(got)] = type(data)(data.typecode, got)
        return len(got)

    def clear_halt(self, dev_handle, ep):
        pass

    def reset_device(self, dev_handle):
        pass

    def is_kernel_driver_active(self, dev_handle, intf):
        return False

    def detach_kernel_driver(self, dev_handle, intf):
        pass

    def attach_kernel_driver(self, dev_handle, intf):
        pass
