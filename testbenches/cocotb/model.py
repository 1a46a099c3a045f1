"""The testbench's own model of what the core is documented to do (README, "The
search"): the left-balanced kd-tree image it loads and a brute-force kNN with the
core's integer metric and radius rule. Written from the documentation, not from the
project's Rust code.
"""

import numpy as np


def left_subtree_size(n):
    """Nodes in the left subtree of a left-balanced (complete) binary tree of n."""
    if n <= 1:
        return 0
    h = (n + 1).bit_length() - 1  # 2^h - 1 <= n < 2^(h+1) - 1
    full = 1 << h
    last = n - (full - 1)
    return (full // 2 - 1) + min(last, full // 2)


def build_tree(points):
    """Heap-ordered tree of integer grid points (1-based: index 0 unused).

    Split on the axis of largest extent (ties: the lowest axis), the node is the
    point at the left-balanced median position, ties on the split coordinate broken
    by point index. Returns (coords[N+1, 3], axis[N+1]).
    """
    pts = np.asarray(points, dtype=np.int64)
    n = len(pts)
    coords = np.zeros((n + 1, 3), dtype=np.int64)
    axis = np.zeros(n + 1, dtype=np.int64)
    stack = [(np.arange(n), 1)]
    while stack:
        idx, addr = stack.pop()
        if len(idx) == 0:
            continue
        sub = pts[idx]
        ext = sub.max(axis=0) - sub.min(axis=0)
        ax = int(np.argmax(ext))  # first maximum: the lowest axis on ties
        order = idx[np.lexsort((idx, pts[idx, ax]))]
        left = left_subtree_size(len(idx))
        m = order[left]
        coords[addr] = pts[m]
        axis[addr] = ax
        stack.append((order[:left], 2 * addr))
        stack.append((order[left + 1 :], 2 * addr + 1))
    return coords, axis


def check_tree(coords, axis):
    """The kd-tree property the search relies on: left <= node <= right on the
    node's split axis, for every subtree."""
    n = len(coords) - 1

    def subtree(a):
        out, todo = [], [a]
        while todo:
            b = todo.pop()
            if b <= n:
                out.append(b)
                todo += [2 * b, 2 * b + 1]
        return out

    for a in range(1, n + 1):
        ax = axis[a]
        for b in subtree(2 * a):
            assert coords[b, ax] <= coords[a, ax]
        for b in subtree(2 * a + 1):
            assert coords[b, ax] >= coords[a, ax]


def distances(coords, q, metric):
    """The core's integer distance from query q to every heap address (index 0: none)."""
    d = np.abs(coords[1:] - np.asarray(q, dtype=np.int64))
    if metric == "l1":
        return d.sum(axis=1)
    if metric == "l2":
        return (d * d).sum(axis=1)
    raise ValueError(f"unknown metric {metric}")


def check_result(coords, q, k, radius, metric, found):
    """Compare one result with brute force. `found` is [(address, distance), ...].

    The k nearest photons within the inclusive radius: the count is min(k, photons
    within), the returned distances are the k smallest, each returned photon is at
    the distance reported and no photon is returned twice. Which of several photons
    tied at the k-th distance is returned is not checked (the multiset is).
    """
    n = len(coords) - 1
    d = distances(coords, q, metric)
    within = np.sort(d[d <= radius])
    want = within[:k]
    errors = []
    if len(found) != len(want):
        errors.append(f"count {len(found)}, brute force {len(want)}")
    addrs = [a for a, _ in found]
    if len(set(addrs)) != len(addrs):
        errors.append(f"a photon returned twice: {addrs}")
    for a, dist in found:
        if not 1 <= a <= n:
            errors.append(f"address {a} outside 1..{n}")
        elif d[a - 1] != dist:
            errors.append(f"photon {a} reported at {dist}, is at {d[a - 1]}")
    got = sorted(dist for _, dist in found)
    if got != [int(x) for x in want]:
        errors.append(f"distances {got}, brute force {[int(x) for x in want]}")
    return errors
