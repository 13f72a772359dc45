"""The numba kernels of ``gsr.plan.relax_jit`` (imported only when numba is installed).

Top-level functions, so that numba's on-disk cache (``cache=True``, in ``__pycache__``) is reused by
later processes instead of compiling again (~10 s CPU the first time).
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sift_push(keys, cst, facts, size, c, k, f):
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if cst[p] < c or (cst[p] == c and keys[p] < k):
            break
        keys[i] = keys[p]
        cst[i] = cst[p]
        facts[i] = facts[p]
        i = p
    keys[i] = k
    cst[i] = c
    facts[i] = f


@njit(cache=True, nogil=True)
def pop(keys, cst, facts, size):
    # removes the root (size = size after removal); caller read the root first
    k, c, f = keys[size], cst[size], facts[size]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= size:
            break
        m = left
        right = left + 1
        if right < size and (
            cst[right] < cst[left] or (cst[right] == cst[left] and keys[right] < keys[left])
        ):
            m = right
        if cst[m] > c or (cst[m] == c and keys[m] > k):
            break
        keys[i] = keys[m]
        cst[i] = cst[m]
        facts[i] = facts[m]
        i = m
    keys[i] = k
    cst[i] = c
    facts[i] = f


@njit(cache=True, nogil=True)
def hadd(
    state_bytes,
    n_atoms,
    true_fact,
    comp_atom,
    comp_fact,
    pre_of_ptr,
    pre_of_idx,
    add_ptr,
    add_idx,
    npre,
    ucost,
    goal,
    stop,
    cost,
    sup,
    acc,
    unsat,
    first,
    hk,
    hc,
    hf,
):
    inf = np.int64(1) << np.int64(62)
    cost[:] = inf
    sup[:] = -1
    acc[:] = ucost
    unsat[:] = npre
    nfirst = 0
    for byte in range(state_bytes.shape[0]):
        b = state_bytes[byte]
        if b == 0:
            continue
        for bit in range(8):
            if (b >> bit) & 1:
                a = byte * 8 + bit
                if a < n_atoms:
                    first[nfirst] = a
                    nfirst += 1
    first[nfirst] = true_fact
    nfirst += 1
    for j in range(comp_atom.shape[0]):
        a = comp_atom[j]
        if not (state_bytes[a >> 3] >> (a & 7)) & 1:
            first[nfirst] = comp_fact[j]
            nfirst += 1
    for j in range(nfirst):
        cost[first[j]] = 0
    size = 0
    seq = 0
    for j in range(nfirst):
        f = first[j]
        for e in range(pre_of_ptr[f], pre_of_ptr[f + 1]):
            u = pre_of_idx[e]
            unsat[u] -= 1
            if unsat[u] == 0:
                v = acc[u]
                for q in range(add_ptr[u], add_ptr[u + 1]):
                    g = add_idx[q]
                    if v < cost[g]:
                        cost[g] = v
                        sup[g] = u
                        if g == stop:
                            return
                        sift_push(hk, hc, hf, size, v, seq, g)
                        size += 1
                        seq += 1
    while size > 0:
        c = hc[0]
        f = hf[0]
        size -= 1
        if size > 0:
            pop(hk, hc, hf, size)
        if cost[f] != c:
            continue
        if f == goal:
            return
        for e in range(pre_of_ptr[f], pre_of_ptr[f + 1]):
            u = pre_of_idx[e]
            acc[u] += c
            unsat[u] -= 1
            if unsat[u] == 0:
                v = acc[u]
                for q in range(add_ptr[u], add_ptr[u + 1]):
                    g = add_idx[q]
                    if v < cost[g]:
                        cost[g] = v
                        sup[g] = u
                        if g == stop:
                            return
                        sift_push(hk, hc, hf, size, v, seq, g)
                        size += 1
                        seq += 1


@njit(cache=True, nogil=True)
def relaxed_plan(goal, sup, pre_ptr, pre_idx, owner, seen, mark, stamp, stack, out):
    """Operators of the relaxed plan (each once, in discovery order); returns their number."""
    n_out = 0
    top = 0
    seen[goal] = stamp
    stack[0] = goal
    top = 1
    while top > 0:
        top -= 1
        u = sup[stack[top]]
        if u < 0:
            continue
        o = owner[u]
        if o >= 0 and mark[o] != stamp:
            mark[o] = stamp
            out[n_out] = o
            n_out += 1
        for e in range(pre_ptr[u], pre_ptr[u + 1]):
            g = pre_idx[e]
            if seen[g] != stamp:
                seen[g] = stamp
                stack[top] = g
                top += 1
    return n_out


@njit(cache=True, nogil=True)
def reach_without(first, blocked, pre_of_ptr, pre_of_idx, add_ptr, add_idx, npre, no_pre, unsat, seen, queue):
    """Relaxed exploration from the facts ``first`` that never adds the facts ``blocked``
    (landmarks' first achievers); ``seen`` ends with the reached facts (``blocked`` excluded)."""
    unsat[:] = npre
    seen[:] = 0
    for b in blocked:
        seen[b] = 1
    n = 0
    for f in first:
        if not seen[f]:
            seen[f] = 1
            queue[n] = f
            n += 1
    for u in no_pre:
        for q in range(add_ptr[u], add_ptr[u + 1]):
            g = add_idx[q]
            if not seen[g]:
                seen[g] = 1
                queue[n] = g
                n += 1
    k = 0
    while k < n:
        f = queue[k]
        k += 1
        for e in range(pre_of_ptr[f], pre_of_ptr[f + 1]):
            u = pre_of_idx[e]
            unsat[u] -= 1
            if unsat[u] == 0:
                for q in range(add_ptr[u], add_ptr[u + 1]):
                    g = add_idx[q]
                    if not seen[g]:
                        seen[g] = 1
                        queue[n] = g
                        n += 1
    for b in blocked:
        seen[b] = 0
