"""The external-memory core's image, as the export's header documents it: the top
T levels of the heap-ordered tree stay on chip; the levels below are cut into
blocks of s levels (bands aligned to the bottom of the tree, the short band just
under the on-chip levels), block b's 2^s words at word b * 2^s, each block's nodes
in its subtree's own heap order from word 0. Written from the documentation, not
from the Rust code, so that the bench checks the core's placement independently.
"""


def bands(h, t, s):
    """Per level below T: (its band's root level, the band's first block); and the blocks."""
    below = h - t
    height = below % s or s
    out, root, base = [], t, 0
    while root < h:
        out += [(root, base)] * height
        base += 1 << root
        root += height
        height = s
    return out, base


def word_of(a, h, t, s, table=None):
    """The image word of heap address a (>= 2^T)."""
    table = table or bands(h, t, s)[0]
    level = a.bit_length() - 1
    root_level, base = table[level - t]
    depth = level - root_level
    block = base + ((a >> depth) - (1 << root_level))
    offset = (1 << depth) + (a & ((1 << depth) - 1)) - 1
    return (block << s) + offset


def image(words, h, t, s, word_bytes, swap_blocks=None):
    """The memory's bytes for `words` (index = heap address, bytes each; index 0
    unused). With swap_blocks=(i, j) two blocks trade places: a broken layout."""
    table, blocks = bands(h, t, s)
    out = bytearray(blocks * (word_bytes << s))
    for a in range(1 << t, len(words)):
        w = word_of(a, h, t, s, table)
        out[w * word_bytes : (w + 1) * word_bytes] = words[a][:word_bytes]
    if swap_blocks:
        n = word_bytes << s
        i, j = (b * n for b in swap_blocks)
        out[i : i + n], out[j : j + n] = out[j : j + n], out[i : i + n]
    return bytes(out)
