"""Screenshots of the virtual screen without extra packages: `xwd -root` (x11-apps) parsed here
into RGB rows, written as PNG with zlib, and searched for colours.

    img = grab(display)                 # Image(width, height, rows of bytes RGBRGB...)
    img.save_png("shot.png"); img.count(rect, rgb, tol)
"""

import struct
import subprocess
import zlib


class Image:
    def __init__(self, width, height, rows):
        self.width, self.height, self.rows = width, height, rows  # rows[y]: bytes, 3 per pixel, top row first

    def pixel(self, x, y):
        r = self.rows[y]
        return r[3 * x], r[3 * x + 1], r[3 * x + 2]

    def crop(self, x0, y0, x1, y1):
        x0, y0 = max(0, x0), max(0, y0)
        x1, y1 = min(self.width, x1), min(self.height, y1)
        return Image(x1 - x0, y1 - y0, [self.rows[y][3 * x0:3 * x1] for y in range(y0, y1)])

    def save_png(self, path):
        raw = b"".join(b"\x00" + bytes(r) for r in self.rows)

        def chunk(kind, data):
            c = struct.pack(">I", len(data)) + kind + data
            return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", self.width, self.height, 8, 2, 0, 0, 0))
               + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
        tmp = path + ".tmp"
        with open(tmp, "wb") as f:
            f.write(png)
        import os
        os.replace(tmp, path)

    def matches(self, x, y, rgb, tol):
        p = self.pixel(x, y)
        return all(abs(p[k] - rgb[k]) <= tol for k in range(3))

    def count(self, rect, predicate):
        """Pixels in rect (x0, y0, x1, y1; top-left origin) for which predicate((r, g, b)) holds."""
        x0, y0, x1, y1 = rect
        n = 0
        for y in range(max(0, y0), min(self.height, y1)):
            row = self.rows[y]
            for x in range(max(0, x0), min(self.width, x1)):
                if predicate((row[3 * x], row[3 * x + 1], row[3 * x + 2])):
                    n += 1
        return n

    def bands(self, rect, rgb, tol=4, min_width_fraction=0.5):
        """Horizontal bands of colour rgb in rect: [(y0, y1, x0, x1)] top to bottom, made of rows in
        which at least min_width_fraction of the rect's width has the colour (text inside a field
        breaks the runs but not the count); x0, x1 span the colour's pixels."""
        x0, y0, x1, y1 = rect
        need = (x1 - x0) * min_width_fraction
        out, cur = [], None
        for y in range(max(0, y0), min(self.height, y1)):
            xs = [x for x in range(max(0, x0), min(self.width, x1)) if self.matches(x, y, rgb, tol)]
            if len(xs) >= need:
                if cur is None:
                    cur = [y, y + 1, xs[0], xs[-1] + 1]
                else:
                    cur[1] = y + 1
                    cur[2], cur[3] = min(cur[2], xs[0]), max(cur[3], xs[-1] + 1)
            elif cur is not None:
                out.append(tuple(cur))
                cur = None
        if cur is not None:
            out.append(tuple(cur))
        return out

    def column_runs(self, x, y0, y1, tol=6, min_gap=2):
        """Runs [(top, bottom)] of the column x between y0 and y1 whose pixels differ from the colour
        at (x, y1 - 1) (the background below the last run), merged across gaps under min_gap."""
        bg = self.pixel(x, y1 - 1)
        runs, cur, gap = [], None, 0
        for y in range(y0, y1):
            differs = not self.matches(x, y, bg, tol)
            if differs:
                if cur is None:
                    cur = [y, y + 1]
                else:
                    cur[1] = y + 1
                gap = 0
            elif cur is not None:
                gap += 1
                if gap >= min_gap:
                    runs.append(tuple(cur))
                    cur, gap = None, 0
        if cur is not None:
            runs.append(tuple(cur))
        return runs


def parse_xwd(data):
    """An XWD dump (ZPixmap, 24/32 bits per pixel, as Xvfb's default visual gives) as an Image."""
    header = struct.unpack(">25I", data[:100])
    header_size, version, fmt, depth, width, height = header[:6]
    byte_order, bits_per_pixel, bytes_per_line = header[7], header[11], header[12]
    red_mask, green_mask, blue_mask = header[14:17]
    ncolors = header[19]
    if version != 7 or fmt != 2 or bits_per_pixel not in (24, 32):
        raise ValueError("unsupported XWD (version %d, format %d, %d bpp)" % (version, fmt, bits_per_pixel))
    offset = header_size + 12 * ncolors
    bpp = bits_per_pixel // 8
    end = "<" if byte_order == 0 else ">"
    shifts = [(m, (m & -m).bit_length() - 1) for m in (red_mask, green_mask, blue_mask)]
    rows = []
    word = struct.Struct(end + "I")
    for y in range(height):
        line = data[offset + y * bytes_per_line: offset + y * bytes_per_line + width * bpp]
        out = bytearray(3 * width)
        if bpp == 4 and byte_order == 0 and (red_mask, green_mask, blue_mask) == (0xFF0000, 0xFF00, 0xFF):
            out[0::3], out[1::3], out[2::3] = line[2::4], line[1::4], line[0::4]  # B G R X in memory
        elif bpp == 4:
            for x, (v,) in enumerate(word.iter_unpack(line)):
                out[3 * x] = (v & shifts[0][0]) >> shifts[0][1]
                out[3 * x + 1] = (v & shifts[1][0]) >> shifts[1][1]
                out[3 * x + 2] = (v & shifts[2][0]) >> shifts[2][1]
        else:
            for x in range(width):
                v = int.from_bytes(line[3 * x:3 * x + 3], "little" if byte_order == 0 else "big")
                for k in range(3):
                    out[3 * x + k] = (v & shifts[k][0]) >> shifts[k][1]
        rows.append(bytes(out))
    return Image(width, height, rows)


def grab(display, env=None):
    data = subprocess.run(["xwd", "-root", "-silent", "-display", display], check=True, capture_output=True,
                          timeout=30, env=env).stdout
    return parse_xwd(data)
