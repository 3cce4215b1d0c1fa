#!/usr/bin/env python3
"""Writes the seeds of the structure-aware and round-trip targets into corpus/TARGET/.

Their inputs are decoded by the `arbitrary` crate (1.x), so each seed is the encoding of an input: integers
and floats little-endian, a bool or an Option's tag one byte, an enum's variant a u32 (variant
`(v · count) >> 32`), a Vec each element after a byte 1 and ended by a byte 0. Files that the round-trip
targets read are taken from the plain targets' seeds. The point cloud targets' seeds are small files of each
format (PLY ASCII and binary, PCD ASCII, binary and binary_compressed, XYZ, CSV, LAS 1.2 with point format 0).

    fuzz/make_seeds.py        # from anywhere; rewrites the seeds it owns
"""
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def u8(v):
    return bytes([v & 0xFF])


def u16(v):
    return struct.pack("<H", v)


def u32(v):
    return struct.pack("<I", v)


def i32(v):
    return struct.pack("<i", v)


def u64(v):
    return struct.pack("<Q", v)


def i64(v):
    return struct.pack("<q", v)


def f64(v):
    return struct.pack("<d", v)


def some(encoded):
    return b"\x01" + encoded


NONE = b"\x00"


def vec(items):
    return b"".join(b"\x01" + item for item in items) + b"\x00"


def bytes_vec(data):
    return vec([bytes([b]) for b in data])


def variant(index, count):
    return u32(-(-(index << 32) // count))


def shape(seed, nodes, divided=0.45):
    """A tree description: 0 empty, 1 full, 2 divided (mod 3), from a fixed pseudo-random sequence."""
    rng = random.Random(seed)
    out = [2]
    for _ in range(nodes - 1):
        r = rng.random()
        out.append(2 if r < divided else 1 if r < divided + 0.3 else 0)
    return bytes_vec(bytes(out))


def plain_seed(target, name):
    with open(os.path.join(HERE, "corpus", target, name), "rb") as f:
        return f.read()


# Enum variants of the targets' inputs, in declaration order.
HEADER_EDITS = 6  # Replace, Insert, Text, Drop, Duplicate, Swap
BODY_EDITS = 6  # Xor, Set, Drop, Duplicate, Truncate, Append
NUMBERS = 4  # Int, Big, Float, Text
V2_EDITS = 12  # Xor, Word, DropWord, InsertWord, Entry, Header, DropLevel, DuplicateLevel, SwapLevels,
#                StaleChecksum, Length, Depth
VDB_EDITS = 2  # Field, Body


def replace_line(at, keyword, numbers):
    return variant(0, HEADER_EDITS) + u8(at) + u8(keyword) + vec(numbers)


def int_number(v):
    return variant(0, NUMBERS) + i64(v)


def float_number(v):
    return variant(2, NUMBERS) + f64(v)


def body(index, *fields):
    return variant(index, BODY_EDITS) + b"".join(fields)


SEEDS = {
    "ktree_v2_behind_crc": {
        # k, level, shape, edits, cut, tail
        "k3_plain": u8(2) + u8(4) + shape(1, 60) + vec([]) + u8(0) + vec([]),
        "k2_flip": u8(1) + u8(3) + shape(2, 40) + vec([variant(0, V2_EDITS) + u8(1) + u16(0) + u8(0x04)])
        + u8(0) + vec([]),
        "k1_counts": u8(0) + u8(10) + shape(3, 30, 0.6)
        + vec([variant(4, V2_EDITS) + u8(2) + u8(1) + u64(3)]) + u8(0) + vec([]),
        "k4_repeat": u8(3) + u8(2) + shape(4, 40) + vec([variant(7, V2_EDITS) + u8(1)]) + u8(0) + vec([]),
    },
    "ktree_v2_roundtrip": {
        # k, level, shape, file
        "k3_file": u8(2) + u8(5) + shape(5, 80) + bytes_vec(plain_seed("ktree_v2", "ball3.ktree")),
        "k1_deep": u8(0) + u8(31) + shape(6, 64, 0.55) + vec([]),
        "k4_v1_file": u8(3) + u8(3) + shape(7, 50) + bytes_vec(plain_seed("ktree_v1", "k4")),
    },
    "binvox_structured": {
        # level, shape, voxel size, origin, header edits, body edits, offset, read level
        "l3_plain": u8(3) + shape(8, 60) + f64(0.5) + f64(1) + f64(-2) + f64(3.25) + vec([]) + vec([])
        + NONE + NONE,
        "l2_dim3": u8(2) + shape(9, 30) + f64(1) + f64(0) + f64(0) + f64(0)
        + vec([replace_line(1, 1, [int_number(3)] * 3)]) + vec([body(4, u16(2))]) + NONE + NONE,
        "l4_moved": u8(4) + shape(10, 80) + f64(0.1) + f64(0) + f64(0) + f64(0) + vec([])
        + vec([body(3, u16(5), u8(2))]) + some(i64(1) + i64(0) + i64(2)) + some(u8(5)),
    },
    "binvox_roundtrip": {
        # level, shape, voxel size, origin, shift, file
        "l3_file": u8(3) + shape(11, 60) + f64(0.25) + f64(0) + f64(1) + f64(2) + bytes([1, 2, 3])
        + bytes_vec(plain_seed("binvox", "ball3.binvox")),
        "l5": u8(5) + shape(12, 120) + f64(1e-3) + f64(-1e6) + f64(0) + f64(7) + bytes([0, 0, 0]) + vec([]),
    },
    "octomap_bt_structured": {
        # level, shape, corner, res, header edits, body edits, offset, read level, unknown full
        "l4_plain": u8(4) + shape(13, 60) + u16(32768) * 3 + f64(0.05) + vec([]) + vec([]) + NONE + NONE
        + u8(0),
        "l16_size": u8(16) + shape(14, 60) + u16(0) * 3 + f64(1) + vec([replace_line(3, 3, [int_number(17)])])
        + vec([]) + NONE + NONE + u8(0),
        "l6_unknown": u8(6) + shape(15, 50) + u16(1000) + u16(40000) + u16(64) + f64(0.2) + vec([])
        + vec([body(0, u16(3), u8(0x30))]) + NONE + some(u8(8)) + u8(1),
    },
    "octomap_bt_roundtrip": {
        # level, shape, corner, res, file
        "l4_file": u8(4) + shape(16, 60) + u16(32768) * 3 + f64(0.05)
        + bytes_vec(plain_seed("octomap_bt", "ball3.bt")),
        "l16": u8(16) + shape(17, 80) + u16(0) * 3 + f64(0.5) + vec([]),
        "l9_corner": u8(9) + shape(18, 60) + u16(512) + u16(65024) + u16(33000) + f64(2.5) + vec([]),
    },
    "vdb_structured": {
        # level, shape, offset, voxel size, origin, edits, read offset, read level
        "l5_plain": u8(5) + shape(19, 80) + i32(-3) + i32(7) + i32(0) + f64(0.5) + f64(1) + f64(2) + f64(3)
        + vec([]) + NONE + NONE,
        "l10_field": u8(10) + shape(20, 60) + i32(128) + i32(-256) + i32(0) + f64(1) + f64(0) + f64(0)
        + f64(0) + vec([variant(0, VDB_EDITS) + u16(40) + u64(2)]) + NONE + NONE,
        "l12_drop": u8(12) + shape(21, 60) + i32(0) * 3 + f64(1) + f64(0) + f64(0) + f64(0)
        + vec([variant(1, VDB_EDITS) + body(2, u16(30), u8(1))]) + NONE + some(u8(13)),
    },
    "vdb_roundtrip": {
        # level, shape, offset, voxel size, origin, file
        "l4_odd": u8(4) + shape(22, 60) + i32(-5) + i32(3) + i32(1) + f64(0.3) + f64(0.1) + f64(0.2)
        + f64(0.3) + vec([]),
        "l12": u8(12) + shape(23, 80) + i32(4096) + i32(-128) + i32(0) + f64(2) + f64(0) + f64(0) + f64(0)
        + vec([]),
    },
}

CLOUD = [(0.0, 0.0, 0.0), (1.5, -2.25, 3.0), (0.5, 0.5, 0.5), (-4.0, 8.0, 2.0)]


def ply_cloud(binary):
    head = "ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n" \
        "property uchar red\nend_header\n" % ("binary_little_endian" if binary else "ascii", len(CLOUD))
    if binary:
        return head.encode() + b"".join(struct.pack("<fffB", *p, 200) for p in CLOUD)
    return (head + "".join("%g %g %g 200\n" % p for p in CLOUD)).encode()


def pcd_cloud(binary):
    head = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\n" \
        "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA %s\n" \
        % (len(CLOUD), len(CLOUD), "binary" if binary else "ascii")
    if binary:
        return head.encode() + b"".join(struct.pack("<fffH", *p, 7) for p in CLOUD)
    return (head + "".join("%g %g %g 7\n" % p for p in CLOUD)).encode()


def lzf_literals(data, repeat_at=None):
    """LZF (liblzf's format) of `data`: literal runs of at most 32 bytes; where `repeat_at` is given, the
    bytes from there on (a repeat of the 2 bytes just before) as one back reference instead."""
    out = b""
    head = data if repeat_at is None else data[:repeat_at]
    for i in range(0, len(head), 32):
        run = head[i:i + 32]
        out += u8(len(run) - 1) + run
    if repeat_at is not None:
        n = len(data) - repeat_at  # a reference of n bytes, 2 back
        assert 3 <= n <= 8 and data[repeat_at:] == (data[repeat_at - 2:repeat_at] * 4)[:n]
        out += u8((n - 2) << 5) + u8(1)
    return out


def pcd_compressed_cloud():
    """PCD `DATA binary_compressed`: the sizes, then LZF of the fields column by column (x, y, z, intensity),
    the last bytes a back reference."""
    head = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\n" \
        "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary_compressed\n" % (len(CLOUD), len(CLOUD))
    columns = b"".join(struct.pack("<f", p[a]) for a in range(3) for p in CLOUD) + u16(7) * len(CLOUD)
    data = lzf_literals(columns, len(columns) - 6)
    return head.encode() + u32(len(data)) + u32(len(columns)) + data


def las_cloud():
    """LAS 1.2, point format 0 (20-byte records), scale 0.01, no VLR."""
    scale = 0.01
    xs = [[p[a] for p in CLOUD] for a in range(3)]
    header = b"LASF" + struct.pack("<HH", 0, 0) + bytes(16) + bytes([1, 2]) + b"ktree".ljust(32, b"\0") \
        + b"make_seeds.py".ljust(32, b"\0") + struct.pack("<HHHIIBHI", 1, 2026, 227, 227, 0, 0, 20, len(CLOUD)) \
        + struct.pack("<5I", len(CLOUD), 0, 0, 0, 0) + struct.pack("<3d", scale, scale, scale) \
        + struct.pack("<3d", 0, 0, 0) \
        + struct.pack("<6d", max(xs[0]), min(xs[0]), max(xs[1]), min(xs[1]), max(xs[2]), min(xs[2]))
    assert len(header) == 227
    points = b"".join(struct.pack("<iiiHBBbBH", *(round(c / scale) for c in p), 0, 0x09, 2, 0, 0, 0)
                      for p in CLOUD)
    return header + points


SEEDS.update({
    "cloud_ply": {"ascii.ply": ply_cloud(False), "binary.ply": ply_cloud(True)},
    "cloud_pcd": {"ascii.pcd": pcd_cloud(False), "binary.pcd": pcd_cloud(True),
                  "compressed.pcd": pcd_compressed_cloud()},
    "cloud_xyz": {
        "points.xyz": ("# x y z\n" + "".join("%g %g %g 1\n" % p for p in CLOUD)).encode(),
        "points.csv": ("x,y,z\n" + "".join("%g,%g,%g\n" % p for p in CLOUD)).encode(),
    },
    "cloud_las": {"format0.las": las_cloud()},
})

for target, seeds in SEEDS.items():
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
