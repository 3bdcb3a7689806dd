"""A settings sector as ~200 saves leave it, in the layout `sequential-storage` 6 writes (the crate behind the
core's `ringpod_core::store`; its `src/lib.rs` page markers and `src/item.rs` item header), so that the next save
has to close that page, move on and erase it: the sector erase the firmware must survive.

A page starts with a marker word (0x00: partial open) and holds items: an 8-byte header (data CRC32, where 0 means
erased; length, u16; CRC16 of the length) and the data, word aligned. Here the used-up page holds superseded items,
marked erased, filling all but `free` bytes, which is less than the record needs.
"""

import struct

WORD = 4  # embassy-stm32's WRITE_SIZE on the F4: the crate's word


def crc16(data):
    """sequential-storage's `item::crc16` (CRC-16F/4.2 reflected, 0x1a2e)."""
    crc = 0xFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0x1A2E if crc & 1 else crc >> 1
    crc ^= 0xFFFF
    return 0xFFFE if crc == 0xFFFF else crc


def used_up_page(page_size, free=200):
    """The bytes of a partial-open page whose erased items leave `free` bytes (at most) before the end marker."""
    page = bytearray(b"\xff" * page_size)
    page[:WORD] = bytes(WORD)  # start marker: partial open
    at, end = WORD, page_size - WORD
    while end - at - 8 > free:
        n = min(0xFFFC, end - at - 8 - free) & ~(WORD - 1)
        length = struct.pack("<H", n)
        page[at : at + 8] = bytes(4) + length + struct.pack("<H", crc16(length))  # data CRC 0: an erased item
        page[at + 8 : at + 8 + n] = bytes(n)
        at += 8 + n
    return bytes(page)
