"""The data checksum of the HDF5 files contactrom writes (rom/hdf5_io.cpp): every
dataset carries the attribute checksum_lookup3 = lookup3(its data bytes). A program
that edits a dataset stores the new value:

    f[name].attrs.create("checksum_lookup3", lookup3(f[name][()].tobytes()), dtype="<u4")
"""


def lookup3(data):
    """Bob Jenkins' lookup3 (hashlittle, initial value 0) of bytes, as
    rom/hdf5_io.cpp computes the checksum of a dataset's data."""
    m = 0xFFFFFFFF

    def rot(x, r):
        return ((x << r) | (x >> (32 - r))) & m

    def word(p, n):
        return int.from_bytes(data[p:p + min(n, 4)], "little") if n > 0 else 0

    length, k = len(data), 0
    a = b = c = (0xDEADBEEF + length) & m
    while length > 12:
        a, b, c = (a + word(k, 4)) & m, (b + word(k + 4, 4)) & m, (c + word(k + 8, 4)) & m
        a = (a - c) & m; a ^= rot(c, 4); c = (c + b) & m
        b = (b - a) & m; b ^= rot(a, 6); a = (a + c) & m
        c = (c - b) & m; c ^= rot(b, 8); b = (b + a) & m
        a = (a - c) & m; a ^= rot(c, 16); c = (c + b) & m
        b = (b - a) & m; b ^= rot(a, 19); a = (a + c) & m
        c = (c - b) & m; c ^= rot(b, 4); b = (b + a) & m
        length -= 12
        k += 12
    if length == 0:
        return c
    a = (a + word(k, length)) & m
    b = (b + (word(k + 4, length - 4) if length > 4 else 0)) & m
    c = (c + (word(k + 8, length - 8) if length > 8 else 0)) & m
    c ^= b; c = (c - rot(b, 14)) & m
    a ^= c; a = (a - rot(c, 11)) & m
    b ^= a; b = (b - rot(a, 25)) & m
    c ^= b; c = (c - rot(b, 16)) & m
    a ^= c; a = (a - rot(c, 4)) & m
    b ^= a; b = (b - rot(a, 14)) & m
    c ^= b; c = (c - rot(b, 24)) & m
    return c
