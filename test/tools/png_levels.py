"""Decode the PNG embedded in a femcod pressure figure, independently of femcod:
Python's standard library only (base64, zlib, struct). Checks the PNG signature, every
chunk's CRC-32, IHDR (8-bit palette, no interlace) and each scanline's filter byte (None
or Up, the two femcod writes), and
prints the image's size and then its palette indices, one row per line.

    python3 test/tools/png_levels.py FIGURE.svg > levels.txt
"""
import base64
import re
import struct
import sys
import zlib


def main(path):
    text = open(path, encoding="utf-8").read()
    match = re.search(r'xlink:href="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    if not match:
        sys.exit("no embedded PNG")
    png = base64.b64decode(match.group(1), validate=True)
    if png[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("bad signature")
    pos, idat, header, palette = 8, b"", None, None
    while pos < len(png):
        length, kind = struct.unpack(">I4s", png[pos:pos + 8])
        data = png[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", png[pos + 8 + length:pos + 12 + length])
        if zlib.crc32(kind + data) != crc:
            sys.exit("bad CRC in " + kind.decode())
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", data)
        elif kind == b"PLTE":
            palette = data
        elif kind == b"IDAT":
            idat += data
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if (depth, colour, interlace) != (8, 3, 0):
        sys.exit("expected an 8-bit palette image without interlace")
    raw = zlib.decompress(idat)
    if len(raw) != height * (width + 1):
        sys.exit("wrong amount of image data")
    print(width, height, len(palette) // 3, palette[0], palette[1], palette[2])
    prior = bytes(width)
    for row in range(height):
        line = raw[row * (width + 1):(row + 1) * (width + 1)]
        if line[0] == 0:  # None
            values = bytes(line[1:])
        elif line[0] == 2:  # Up: each byte plus the one above it, modulo 256
            values = bytes((a + b) % 256 for a, b in zip(line[1:], prior))
        else:
            sys.exit("unexpected filter type %d" % line[0])
        prior = values
        print(" ".join(str(v) for v in values))


if __name__ == "__main__":
    main(sys.argv[1])
