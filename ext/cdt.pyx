# cython: language_level=3
"""Constrained Delaunay triangulation kernel (private; use ``rigger.cdt``).

Incremental Delaunay insertion in Hilbert-curve order with Lawson flips, on a half-edge triangle structure closed by
"ghost" triangles that share one vertex at infinity (so the convex hull grows without a super-triangle and without its
precision problems). Each point is located by a walk from the last inserted vertex or, when closer, from an inserted
vertex a few segments away (outlines). Constraint segments are then inserted one by one: the triangles the segment
crosses are retriangulated by flipping the crossed edges (Sloan 1993) and Delaunay-ness is restored by Lawson flips
that never cross a constraint. Crossing constraints are split at a new Steiner vertex; vertices lying on a segment split it.
Every decision is made by the exact predicates of ``cdt_predicates.h``.

Half-edge ``h`` is corner ``h % 3`` of triangle ``h // 3`` and runs from ``V[h]`` to ``V[nxt(h)]``; ``N[h]`` is its twin
and ``C[h]`` how many input segments cover it (0: unconstrained).
"""
from libc.stdlib cimport malloc, realloc, free
from libc.string cimport memcpy, memset
from libc.math cimport fabs, sqrt, frexp, ldexp

ctypedef unsigned char npy_bool

import numpy as np

cdef extern from "cdt_predicates.h" nogil:
    int rg_orient2d(double ax, double ay, double bx, double by, double cx, double cy)
    int rg_incircle(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy)

# Crossing constraints closer than this fraction of the bounding box to an endpoint are routed through it.
cdef double SNAP_FRACTION = 2.0 ** -40
RENUMBER_MIN = 16384
# How far along its chain of segment neighbours a point looks for an inserted one to start locating from.
cdef int LINK_HOPS = 8

cdef enum:
    GHOST = -1
    ERR_NOMEM = -1
    ERR_INTERNAL = -2
    LOC_FACE = 0
    LOC_EDGE = 1
    LOC_VERTEX = 2


cdef struct Mesh:
    double *xy          # 2 doubles per vertex
    int nv
    int cap_v
    int *V              # origin vertex of each half-edge (3 per triangle)
    int *N              # twin half-edge
    int *C              # constraint multiplicity
    int nt
    int cap_t
    int *VT             # per vertex: one half-edge leaving it, -1 before insertion
    int *stack          # half-edges waiting for a Lawson check
    int sn
    int scap
    unsigned int rng
    long long budget    # guard against any non-terminating loop: every step spends one unit
    double snap         # SNAP_FRACTION of the bounding box: closer than this to a segment counts as on it


cdef inline int nxt(int h) noexcept nogil:
    return h - 2 if h % 3 == 2 else h + 1


cdef inline int prv(int h) noexcept nogil:
    return h + 2 if h % 3 == 0 else h - 1


cdef inline int orient_v(Mesh *m, int a, int b, int c) noexcept nogil:
    return rg_orient2d(m.xy[2 * a], m.xy[2 * a + 1], m.xy[2 * b], m.xy[2 * b + 1], m.xy[2 * c], m.xy[2 * c + 1])


cdef inline int orient_p(Mesh *m, int a, int b, double px, double py) noexcept nogil:
    return rg_orient2d(m.xy[2 * a], m.xy[2 * a + 1], m.xy[2 * b], m.xy[2 * b + 1], px, py)


cdef inline int incircle_v(Mesh *m, int a, int b, int c, int d) noexcept nogil:
    return rg_incircle(m.xy[2 * a], m.xy[2 * a + 1], m.xy[2 * b], m.xy[2 * b + 1],
                       m.xy[2 * c], m.xy[2 * c + 1], m.xy[2 * d], m.xy[2 * d + 1])


cdef inline int spend(Mesh *m) noexcept nogil:
    m.budget -= 1
    return m.budget < 0


# ---------------------------------------------------------------------------------------------------- storage

cdef int grow_ints(int **arr, int cap) noexcept nogil:
    cdef int *p = <int *> realloc(arr[0], <size_t> cap * sizeof(int))
    if p == NULL:
        return ERR_NOMEM
    arr[0] = p
    return 0


cdef int new_triangles(Mesh *m, int count) noexcept nogil:
    """Index of the first of ``count`` fresh triangles, growing the arrays when full."""
    cdef int cap
    if m.nt + count > m.cap_t:
        cap = m.cap_t + m.cap_t // 2 + count + 16
        if grow_ints(&m.V, 3 * cap) or grow_ints(&m.N, 3 * cap) or grow_ints(&m.C, 3 * cap):
            return ERR_NOMEM
        m.cap_t = cap
    m.nt += count
    return m.nt - count


cdef int new_vertex(Mesh *m, double x, double y) noexcept nogil:
    cdef int cap
    cdef double *p
    if m.nv == m.cap_v:
        cap = m.cap_v + m.cap_v // 2 + 16
        p = <double *> realloc(m.xy, <size_t> cap * 2 * sizeof(double))
        if p == NULL:
            return ERR_NOMEM
        m.xy = p
        if grow_ints(&m.VT, cap):
            return ERR_NOMEM
        m.cap_v = cap
    m.xy[2 * m.nv] = x
    m.xy[2 * m.nv + 1] = y
    m.VT[m.nv] = -1
    m.nv += 1
    return m.nv - 1


cdef int push(Mesh *m, int h) noexcept nogil:
    if m.sn == m.scap:
        m.scap = 2 * m.scap + 16
        if grow_ints(&m.stack, m.scap):
            return ERR_NOMEM
    m.stack[m.sn] = h
    m.sn += 1
    return 0


cdef inline void link(Mesh *m, int h, int g, int c) noexcept nogil:
    m.N[h] = g
    m.N[g] = h
    m.C[h] = c
    m.C[g] = c


cdef inline void set_tri(Mesh *m, int t, int a, int b, int c) noexcept nogil:
    m.V[3 * t] = a
    m.V[3 * t + 1] = b
    m.V[3 * t + 2] = c
    if a != GHOST:
        m.VT[a] = 3 * t
    if b != GHOST:
        m.VT[b] = 3 * t + 1
    if c != GHOST:
        m.VT[c] = 3 * t + 2


# ---------------------------------------------------------------------------------------------------- topology

cdef int find_edge(Mesh *m, int u, int w) noexcept nogil:
    """The half-edge u -> w, or -1. Turns around u through its fan (closed, thanks to the ghosts)."""
    cdef int h = m.VT[u], start = h
    if h < 0:
        return -1
    while True:
        if m.V[nxt(h)] == w:
            return h
        h = m.N[prv(h)]
        if h == start:
            return -1


cdef void flip(Mesh *m, int h) noexcept nogil:
    """Replace edge a-b shared by (a, b, c) and (b, a, d) with c-d: triangles become (c, a, d) and (d, b, c)."""
    cdef int o = m.N[h]
    cdef int h1 = nxt(h), h2 = prv(h), o1 = nxt(o), o2 = prv(o)
    cdef int a = m.V[h], b = m.V[h1], c = m.V[h2], d = m.V[o2]
    cdef int x1 = m.N[h1], x2 = m.N[h2], y1 = m.N[o1], y2 = m.N[o2]
    cdef int cx1 = m.C[h1], cx2 = m.C[h2], cy1 = m.C[o1], cy2 = m.C[o2]
    m.V[h] = c
    m.V[h1] = a
    m.V[h2] = d
    m.V[o] = d
    m.V[o1] = b
    m.V[o2] = c
    link(m, h, x2, cx2)
    link(m, h1, y1, cy1)
    link(m, o, y2, cy2)
    link(m, o1, x1, cx1)
    link(m, h2, o2, 0)
    if a != GHOST:
        m.VT[a] = h1
    if b != GHOST:
        m.VT[b] = o1
    if c != GHOST:
        m.VT[c] = h
    if d != GHOST:
        m.VT[d] = o


cdef int split_triangle(Mesh *m, int t, int p) noexcept nogil:
    """Insert vertex p inside triangle t (possibly a ghost); queue the three edges opposite p."""
    cdef int t1 = new_triangles(m, 2)
    if t1 < 0:
        return t1
    cdef int t2 = t1 + 1, base = 3 * t
    cdef int a = m.V[base], b = m.V[base + 1], c = m.V[base + 2]
    cdef int n1 = m.N[base + 1], n2 = m.N[base + 2], c1 = m.C[base + 1], c2 = m.C[base + 2]
    set_tri(m, t, a, b, p)
    set_tri(m, t1, b, c, p)
    set_tri(m, t2, c, a, p)
    link(m, 3 * t1, n1, c1)
    link(m, 3 * t2, n2, c2)
    link(m, base + 1, 3 * t1 + 2, 0)
    link(m, 3 * t1 + 1, 3 * t2 + 2, 0)
    link(m, 3 * t2 + 1, base + 2, 0)
    if push(m, base) or push(m, 3 * t1) or push(m, 3 * t2):
        return ERR_NOMEM
    return 0


cdef int split_edge(Mesh *m, int h, int p) noexcept nogil:
    """Insert vertex p on the open edge h = a -> b of (a, b, c) / (b, a, d); the four halves keep its constraint."""
    cdef int t3 = new_triangles(m, 2)
    if t3 < 0:
        return t3
    cdef int t4 = t3 + 1, o = m.N[h]
    cdef int t1 = h // 3, t2 = o // 3
    cdef int h1 = nxt(h), h2 = prv(h), o1 = nxt(o), o2 = prv(o)
    cdef int a = m.V[h], b = m.V[h1], c = m.V[h2], d = m.V[o2]
    cdef int x1 = m.N[h1], x2 = m.N[h2], y1 = m.N[o1], y2 = m.N[o2]
    cdef int cx1 = m.C[h1], cx2 = m.C[h2], cy1 = m.C[o1], cy2 = m.C[o2], cc = m.C[h]
    cdef int b1 = 3 * t1, b2 = 3 * t2, b3 = 3 * t3, b4 = 3 * t4
    set_tri(m, t1, a, p, c)
    set_tri(m, t3, p, b, c)
    set_tri(m, t2, b, p, d)
    set_tri(m, t4, p, a, d)
    link(m, b1, b4, cc)
    link(m, b3, b2, cc)
    link(m, b1 + 1, b3 + 2, 0)
    link(m, b2 + 1, b4 + 2, 0)
    link(m, b1 + 2, x2, cx2)
    link(m, b3 + 1, x1, cx1)
    link(m, b2 + 2, y2, cy2)
    link(m, b4 + 1, y1, cy1)
    if push(m, b1 + 2) or push(m, b3 + 1) or push(m, b2 + 2) or push(m, b4 + 1):
        return ERR_NOMEM
    return 0


# ---------------------------------------------------------------------------------------------------- geometry

cdef inline int ghost_corner(Mesh *m, int t) noexcept nogil:
    if m.V[3 * t] == GHOST:
        return 0
    if m.V[3 * t + 1] == GHOST:
        return 1
    if m.V[3 * t + 2] == GHOST:
        return 2
    return -1


cdef int collinear_position(Mesh *m, int u, int w, double px, double py) noexcept nogil:
    """For p on the line u-w: -2 before u, -1 at u, 0 strictly between, 1 at w, 2 beyond w (exact comparisons)."""
    cdef double ux = m.xy[2 * u], uy = m.xy[2 * u + 1], wx = m.xy[2 * w], wy = m.xy[2 * w + 1]
    cdef double dx = wx - ux, dy = wy - uy, pu, pw, s
    if (dx if dx > 0 else -dx) >= (dy if dy > 0 else -dy):
        pu = px - ux
        pw = px - wx
        s = dx
    else:
        pu = py - uy
        pw = py - wy
        s = dy
    if s < 0:
        pu = -pu
        pw = -pw
    if pu < 0:
        return -2
    if pu == 0:
        return -1
    if pw < 0:
        return 0
    if pw == 0:
        return 1
    return 2


cdef int in_conflict(Mesh *m, int o, int p) noexcept nogil:
    """Does vertex p lie strictly inside the circumcircle of the triangle of half-edge o (a half-plane for ghosts)?"""
    cdef int q0 = m.V[o], q1 = m.V[nxt(o)], q2 = m.V[prv(o)]
    if q2 == GHOST:
        return orient_v(m, q0, q1, p) > 0
    if q0 == GHOST:
        return orient_v(m, q1, q2, p) > 0
    if q1 == GHOST:
        return orient_v(m, q2, q0, p) > 0
    return incircle_v(m, q0, q1, q2, p) > 0


cdef int legalize(Mesh *m, int p) noexcept nogil:
    """Lawson flips around the freshly inserted vertex p until every queued edge is (constrained) Delaunay."""
    cdef int h, o
    while m.sn > 0:
        if spend(m):
            return ERR_INTERNAL
        m.sn -= 1
        h = m.stack[m.sn]
        o = m.N[h]
        if m.C[h] or not in_conflict(m, o, p):
            continue
        flip(m, h)
        # p is corner prv(h) of (p, a, d) and corner nxt(o) of (d, b, p): queue the edges facing it
        if push(m, nxt(h)) or push(m, o):
            return ERR_NOMEM
    return 0


cdef int locate(Mesh *m, double px, double py, int t, int *out) noexcept nogil:
    """Walk from triangle t to the point; returns LOC_FACE (out: a half-edge of the triangle or ghost holding it),
    LOC_EDGE (out: the half-edge whose open segment holds it) or LOC_VERTEX (out: a half-edge leaving that vertex)."""
    cdef int g, h, k, o, pos, r, zeros, z0, z1, came = -1
    while True:
        if spend(m):
            return ERR_INTERNAL
        g = ghost_corner(m, t)
        if g >= 0:
            h = 3 * t + (g + 1) % 3
            o = orient_p(m, m.V[h], m.V[nxt(h)], px, py)
            if o > 0:
                out[0] = h
                return LOC_FACE
            if o < 0:
                came = m.N[h]
                t = came // 3
                continue
            came = -1
            pos = collinear_position(m, m.V[h], m.V[nxt(h)], px, py)
            if pos == 0:
                out[0] = h
                return LOC_EDGE
            if pos == -1:
                out[0] = h
                return LOC_VERTEX
            if pos == 1:
                out[0] = nxt(h)
                return LOC_VERTEX
            t = m.N[nxt(h)] // 3 if pos == 2 else m.N[prv(h)] // 3
            continue
        m.rng = m.rng * 1103515245u + 12345u
        r = (m.rng >> 16) % 3
        zeros = 0
        z0 = z1 = -1
        for k in range(3):
            h = 3 * t + (r + k) % 3
            if h == came:
                continue  # the edge just crossed: the point is strictly on its inner side
            o = orient_p(m, m.V[h], m.V[nxt(h)], px, py)
            if o < 0:
                break
            if o == 0:
                if zeros == 0:
                    z0 = h
                else:
                    z1 = h
                zeros += 1
        else:
            if zeros == 0:
                out[0] = 3 * t
                return LOC_FACE
            if zeros == 1:
                out[0] = z0
                return LOC_EDGE
            # two collinear edges meet at the vertex the point coincides with
            out[0] = z1 if nxt(z0) == z1 else z0
            return LOC_VERTEX
        came = m.N[h]
        t = came // 3


cdef int insert_at(Mesh *m, int p, int loc, int h) noexcept nogil:
    cdef int err = split_triangle(m, h // 3, p) if loc == LOC_FACE else split_edge(m, h, p)
    if err:
        return err
    return legalize(m, p)


# ---------------------------------------------------------------------------------------------------- Delaunay

cdef int scale_exponent(const double *xy, int n) noexcept nogil:
    """The binary exponent e of the largest coordinate magnitude (0 when all are zero): scaled by 2^-e, |x| < 1."""
    cdef double peak = 0.0
    cdef int i, e
    for i in range(2 * n):
        if fabs(xy[i]) > peak:
            peak = fabs(xy[i])
    frexp(peak, &e)
    return e


cdef void power_factors(int exponent, double *up, double *up_rest) noexcept nogil:
    """2^-exponent as the product of two doubles, multiplied in turn: one when scaling down (a single rounding, as in
    ldexp), two exact factors when scaling up by more than 2^1023."""
    if exponent > 0:
        up[0] = ldexp(1.0, -exponent)
        up_rest[0] = 1.0
    else:
        up[0] = ldexp(1.0, min(-exponent, 1023))
        up_rest[0] = ldexp(1.0, -exponent - min(-exponent, 1023))


cdef double hilbert_order(const double *xy, int n, int *order, unsigned int *keys, unsigned int *tmp_keys,
                          int *tmp_order) noexcept nogil:
    """Biased randomised insertion order (BRIO): random rounds of doubling size, each sorted along a Hilbert curve.
    Returns the size of the points' bounding box (its longer side), which the curve is fitted to.

    Pure Hilbert order makes points on a smooth outline see long hull chains and flip quadratically often; random
    rounds keep the expected work O(n log n) while the curve keeps the walks short. The round of a point comes from a
    hash of its coordinates, so exact duplicates share a round and (the sorts being stable) keep index order, while
    distinct points in one cell of the curve (dense outlines) still get independent rounds.
    """
    cdef double x0 = xy[0], x1 = xy[0], y0 = xy[1], y1 = xy[1], sx, sy
    cdef int i, shift, levels = 1
    cdef unsigned int qx, qy, d, state, rx, ry, sw, fl, top
    cdef int counts[2049]
    cdef unsigned char step[16]
    # one level of the curve as a table: (state, x bit, y bit) -> digit | next state << 2, where the state records
    # whether the cell's frame is swapped (bit 0) and mirrored (bit 1) relative to the square
    for state in range(16):
        sw = (state >> 2) & 1
        fl = state >> 3
        rx = ((state & 1) if sw else (state >> 1) & 1) ^ fl
        ry = (((state >> 1) & 1) if sw else (state & 1)) ^ fl
        if ry == 0:
            fl ^= rx
            sw ^= 1
        step[state] = ((3 * rx) ^ ry) | ((sw | (fl << 1)) << 2)
    for i in range(n):
        if xy[2 * i] < x0:
            x0 = xy[2 * i]
        if xy[2 * i] > x1:
            x1 = xy[2 * i]
        if xy[2 * i + 1] < y0:
            y0 = xy[2 * i + 1]
        if xy[2 * i + 1] > y1:
            y1 = xy[2 * i + 1]
    # a grid of about 16 cells per point (at most 2^16 a side): finer only costs levels, coarser loses locality
    while levels < 16 and (1 << (2 * levels)) < 16 * <long long> n:
        levels += 1
    top = (1u << levels) - 1
    sx = top / (x1 - x0) if x1 > x0 else 0.0
    sy = top / (y1 - y0) if y1 > y0 else 0.0
    for i in range(n):
        qx = <unsigned int> ((xy[2 * i] - x0) * sx)
        qy = <unsigned int> ((xy[2 * i + 1] - y0) * sy)
        if qx > top:
            qx = top
        if qy > top:
            qy = top
        d = 0
        state = 0
        for shift in range(levels - 1, -1, -1):
            state = step[(state << 2) | (((qx >> shift) & 1) << 1) | ((qy >> shift) & 1)]
            d = (d << 2) | (state & 3)
            state >>= 2
        keys[i] = d
        order[i] = i
    for shift in range(0, 2 * levels, 11):
        memset(counts, 0, sizeof(counts))
        for i in range(n):
            counts[((keys[i] >> shift) & 0x7FF) + 1] += 1
        for i in range(2048):
            counts[i + 1] += counts[i]
        for i in range(n):
            d = (keys[i] >> shift) & 0x7FF
            tmp_keys[counts[d]] = keys[i]
            tmp_order[counts[d]] = order[i]
            counts[d] += 1
        for i in range(n):
            keys[i] = tmp_keys[i]
            order[i] = tmp_order[i]
    # stable counting sort by round, the rarest (smallest) round first
    memset(counts, 0, sizeof(counts))
    for i in range(n):
        keys[i] = 31 - brio_round(xy[2 * order[i]], xy[2 * order[i] + 1])
        counts[keys[i] + 1] += 1
    for i in range(32):
        counts[i + 1] += counts[i]
    for i in range(n):
        tmp_order[counts[keys[i]]] = order[i]
        counts[keys[i]] += 1
    for i in range(n):
        order[i] = tmp_order[i]
    return max(x1 - x0, y1 - y0)


cdef inline unsigned int brio_round(double px, double py) noexcept nogil:
    """Round 31 - k with probability 2^-(k+1): the trailing zeros of a well-mixed hash of the point's coordinates."""
    cdef unsigned long long bx, by, mixed
    px += 0.0  # -0.0 and 0.0 are the same coordinate
    py += 0.0
    memcpy(&bx, &px, sizeof(double))
    memcpy(&by, &py, sizeof(double))
    mixed = (bx ^ (bx >> 29)) * 0x9E3779B97F4A7C15ull + (by ^ (by >> 31)) * 0xC2B2AE3D27D4EB4Full
    cdef unsigned int x = <unsigned int> (mixed ^ (mixed >> 32))
    x ^= x >> 16
    x *= 0x85EBCA6Bu
    x ^= x >> 13
    x *= 0xC2B2AE35u
    x ^= x >> 16
    x |= 0x80000000u
    cdef unsigned int k = 0
    while not (x & 1u):
        x >>= 1
        k += 1
    return k


cdef int seed_triangle(Mesh *m, int a, int b, int c) noexcept nogil:
    """The first real triangle (a, b, c), counter-clockwise, closed by three ghosts."""
    cdef int t = new_triangles(m, 4)
    if t < 0:
        return t
    set_tri(m, t, a, b, c)
    set_tri(m, t + 1, b, a, GHOST)
    set_tri(m, t + 2, c, b, GHOST)
    set_tri(m, t + 3, a, c, GHOST)
    link(m, 3 * t, 3 * (t + 1), 0)
    link(m, 3 * t + 1, 3 * (t + 2), 0)
    link(m, 3 * t + 2, 3 * (t + 3), 0)
    link(m, 3 * (t + 1) + 1, 3 * (t + 3) + 2, 0)
    link(m, 3 * (t + 1) + 2, 3 * (t + 2) + 1, 0)
    link(m, 3 * (t + 2) + 2, 3 * (t + 3) + 1, 0)
    return 0


cdef inline double distance2(Mesh *m, int u, int w) noexcept nogil:
    cdef double dx = m.xy[2 * u] - m.xy[2 * w], dy = m.xy[2 * u + 1] - m.xy[2 * w + 1]
    return dx * dx + dy * dy


cdef void link_segment_ends(const int *seg_v, int nseg, int n, int *linked) noexcept nogil:
    """``linked[v]``: one vertex sharing a segment with v, or -1 (chained, these lead along an outline)."""
    cdef int i, a, b
    for i in range(n):
        linked[i] = -1
    for i in range(nseg):
        a = seg_v[2 * i]
        b = seg_v[2 * i + 1]
        if a != b:
            if linked[a] < 0:
                linked[a] = b
            if linked[b] < 0:
                linked[b] = a


cdef int walk_start(Mesh *m, int p, int last, const int *linked) noexcept nogil:
    """The triangle to start locating p from: at the last inserted vertex, or at the first inserted vertex along p's
    chain of segment neighbours when that one is closer. Hilbert order jumps between cells; along an outline such a
    jump crosses a fan of thin triangles, while a segment neighbour sits a few vertices away."""
    cdef int q, hops = LINK_HOPS
    if linked != NULL:
        q = linked[p]
        while q >= 0 and m.VT[q] < 0 and hops > 0:
            q = linked[q]
            hops -= 1
        if q >= 0 and m.VT[q] >= 0 and distance2(m, q, p) < distance2(m, last, p):
            return m.VT[q] // 3
    return m.VT[last] // 3


cdef int delaunay(Mesh *m, int n, const int *order, int *vmap, const int *linked) noexcept nogil:
    """Insert points 0..n-1 in the given order. Returns 1 when they are all collinear (no triangle), 0 when done.
    ``linked`` (or NULL) gives each point one segment neighbour, or -1, to start the point location from."""
    cdef int k, p, a, b = -1, c = -1, loc, h, err, last
    a = order[0]
    for k in range(1, n):
        p = order[k]
        if m.xy[2 * p] != m.xy[2 * a] or m.xy[2 * p + 1] != m.xy[2 * a + 1]:
            b = p
            break
    if b < 0:
        return 1
    for k in range(1, n):
        p = order[k]
        if p != b and orient_v(m, a, b, p) != 0:
            c = p
            break
    if c < 0:
        return 1
    err = seed_triangle(m, a, b, c) if orient_v(m, a, b, c) > 0 else seed_triangle(m, a, c, b)
    if err:
        return err
    last = a
    for k in range(n):
        p = order[k]
        if p == a or p == b or p == c:
            continue
        loc = locate(m, m.xy[2 * p], m.xy[2 * p + 1], walk_start(m, p, last, linked), &h)
        if loc < 0:
            return loc
        if loc == LOC_VERTEX:
            vmap[p] = m.V[h]
            continue
        err = insert_at(m, p, loc, h)
        if err:
            return err
        last = p
    return 0


# ---------------------------------------------------------------------------------------------------- constraints

cdef struct Buffer:
    int *data
    int n
    int cap


cdef int buf_push2(Buffer *b, int x, int y) noexcept nogil:
    if b.n + 2 > b.cap:
        b.cap = 2 * b.cap + 64
        if grow_ints(&b.data, b.cap):
            return ERR_NOMEM
    b.data[b.n] = x
    b.data[b.n + 1] = y
    b.n += 2
    return 0


cdef int restore_delaunay(Mesh *m, Buffer *pairs) noexcept nogil:
    """Lawson flips over the listed edges (vertex pairs) and the edges they expose, never across a constraint."""
    cdef int u, w, h, o, x, y
    while pairs.n > 0:
        if spend(m):
            return ERR_INTERNAL
        pairs.n -= 2
        u = pairs.data[pairs.n]
        w = pairs.data[pairs.n + 1]
        h = find_edge(m, u, w)
        if h < 0 or m.C[h]:
            continue
        o = m.N[h]
        x = m.V[prv(h)]
        y = m.V[prv(o)]
        if x == GHOST or y == GHOST or incircle_v(m, u, w, x, y) <= 0:
            continue
        flip(m, h)
        if buf_push2(pairs, x, u) or buf_push2(pairs, u, y) or buf_push2(pairs, y, w) or buf_push2(pairs, w, x):
            return ERR_NOMEM
    return 0


cdef struct Work:
    int *data      # triples (a, b, count) of segments still to insert
    int n
    int cap


cdef int work_push(Work *w, int a, int b, int count) noexcept nogil:
    if w.n + 3 > w.cap:
        w.cap = 2 * w.cap + 48
        if grow_ints(&w.data, w.cap):
            return ERR_NOMEM
    w.data[w.n] = a
    w.data[w.n + 1] = b
    w.data[w.n + 2] = count
    w.n += 3
    return 0


cdef inline int split_at(Work *w, int a, int r, int b, int count) noexcept nogil:
    """Queue segment a-b as its two pieces a-r and r-b (``r`` a vertex on it), the far piece first."""
    return work_push(w, r, b, count) or work_push(w, a, r, count)


cdef inline int same_direction(Mesh *m, int a, int b, int p) noexcept nogil:
    """For p on the line a-b: does it lie on the ray from a through b (exact coordinate comparisons)?"""
    cdef double dx = m.xy[2 * b] - m.xy[2 * a], dy = m.xy[2 * b + 1] - m.xy[2 * a + 1]
    cdef double ex = m.xy[2 * p] - m.xy[2 * a], ey = m.xy[2 * p + 1] - m.xy[2 * a + 1]
    if (dx if dx > 0 else -dx) >= (dy if dy > 0 else -dy):
        return (dx > 0) == (ex > 0) and ex != 0
    return (dy > 0) == (ey > 0) and ey != 0


cdef int on_segment(Mesh *m, int a, int b, int p) noexcept nogil:
    """Does p lie on the open segment a-b, exactly or within SNAP of it (the rounding of a Steiner vertex)?"""
    cdef double ax = m.xy[2 * a], ay = m.xy[2 * a + 1]
    cdef double dx = m.xy[2 * b] - ax, dy = m.xy[2 * b + 1] - ay
    cdef double ex = m.xy[2 * p] - ax, ey = m.xy[2 * p + 1] - ay
    cdef double length2 = dx * dx + dy * dy, along = dx * ex + dy * ey
    if orient_v(m, a, b, p) == 0:
        return same_direction(m, a, b, p)
    if not (0.0 < along < length2):
        return 0
    return fabs(dx * ey - dy * ex) <= m.snap * sqrt(length2)


cdef int mark(Mesh *m, int h, int count) noexcept nogil:
    m.C[h] += count
    m.C[m.N[h]] += count
    return 0


cdef int split_constraint(Mesh *m, Work *w, Buffer *dirty, int h, int a, int b, int count) noexcept nogil:
    """Segment a-b crosses the constrained edge h = p -> q: split both at a new vertex near their intersection.

    A crossing that passes within SNAP of an endpoint is routed through that endpoint instead: a Steiner vertex there
    would sit a rounding error away from it and make the next near-parallel segment cross again and again.
    """
    cdef int p = m.V[h], q = m.V[nxt(h)], k = m.C[h], loc, at, s, err
    cdef double ax = m.xy[2 * a], ay = m.xy[2 * a + 1], bx = m.xy[2 * b], by = m.xy[2 * b + 1]
    cdef double px = m.xy[2 * p], py = m.xy[2 * p + 1], qx = m.xy[2 * q], qy = m.xy[2 * q + 1]
    cdef double da = (qx - px) * (ay - py) - (qy - py) * (ax - px)
    cdef double db = (qx - px) * (by - py) - (qy - py) * (bx - px)
    cdef double dp = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    cdef double dq = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
    cdef double lab = sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay))
    cdef double lpq = sqrt((qx - px) * (qx - px) + (qy - py) * (qy - py))
    dp = fabs(dp) / lab
    dq = fabs(dq) / lab
    da = fabs(da) / lpq
    db = fabs(db) / lpq
    cdef double nearest = min(min(dp, dq), min(da, db))
    if nearest <= m.snap:
        if nearest == dp or nearest == dq:
            s = p if nearest == dp else q
            if work_push(w, a, s, count) or work_push(w, s, b, count):
                return ERR_NOMEM
            return 0
        s = a if nearest == da else b
        return (release(m, dirty, p, q) or work_push(w, a, b, count) or work_push(w, p, s, k) or
                work_push(w, s, q, k))
    cdef double t = da / (da + db)
    cdef double sx = ax + t * (bx - ax), sy = ay + t * (by - ay)
    loc = locate(m, sx, sy, h // 3, &at)
    if loc < 0:
        return loc
    if loc == LOC_VERTEX:
        s = m.V[at]
    else:
        m.C[h] = 0  # the constraint moves to the two pieces through the new vertex: let the insertion flip it
        m.C[m.N[h]] = 0
        s = new_vertex(m, sx, sy)
        if s < 0:
            return s
        err = insert_at(m, s, loc, at)
        if err:
            return err
    return (release(m, dirty, p, q) or work_push(w, p, s, k) or work_push(w, s, q, k) or
            work_push(w, a, s, count) or work_push(w, s, b, count))


cdef int release(Mesh *m, Buffer *dirty, int p, int q) noexcept nogil:
    """Drop the constraint of edge p-q, if that edge still exists, and flip it if it is no longer Delaunay."""
    cdef int h = find_edge(m, p, q)
    if h < 0:
        return 0
    m.C[h] = 0
    m.C[m.N[h]] = 0
    dirty.n = 0
    return buf_push2(dirty, p, q) or restore_delaunay(m, dirty)


cdef int insert_segment(Mesh *m, Work *w, Buffer *crossed, Buffer *fresh, Buffer *bypassed, int a, int b,
                        int count) noexcept nogil:
    """Make a-b an edge (or queue its pieces when a vertex lies on it or a constraint crosses it).

    An existing edge a-b that the segment is routed around (through a sliver apex) goes to ``bypassed``: it may lie
    where a constraint split at a crossing ran, Delaunay only while that hid the apex, and as an ordinary edge it
    is checked, and flipped if need be, once every segment is in."""
    cdef int h, start, p, q, o, r, s, head, u, v, x, y, k
    cdef long long guard
    h = find_edge(m, a, b)
    if h >= 0:
        # a sliver apex within SNAP of the edge (beside a Steiner vertex) lies on the segment: route through it
        r = m.V[prv(h)]
        if r == GHOST or not on_segment(m, a, b, r):
            r = m.V[prv(m.N[h])]
            if r == GHOST or not on_segment(m, a, b, r):
                return mark(m, h, count)
        return buf_push2(bypassed, a, b) or split_at(w, a, r, b, count)
    # the triangle around a that the segment leaves through
    h = m.VT[a]
    start = h
    while True:
        p = m.V[nxt(h)]
        q = m.V[prv(h)]
        if p != GHOST and on_segment(m, a, b, p):
            # through p; the piece a-p is queued rather than marked, so that a sliver apex within SNAP of it (a
            # vertex nearer along the segment) is routed through as well
            return split_at(w, a, p, b, count)
        if p != GHOST and q != GHOST and orient_v(m, a, b, p) < 0 and orient_v(m, a, b, q) > 0:
            h = nxt(h)
            break
        h = m.N[prv(h)]
        if h == start:
            return ERR_INTERNAL
    # walk along the segment collecting crossed edges (origin right of a->b, destination left)
    crossed.n = 0
    while True:
        if spend(m):
            return ERR_INTERNAL
        # a vertex a rounding error off the segment (beside a Steiner vertex): split there, start again
        r = m.V[h] if on_segment(m, a, b, m.V[h]) else (m.V[nxt(h)] if on_segment(m, a, b, m.V[nxt(h)]) else -1)
        if r >= 0:
            return split_at(w, a, r, b, count)
        if m.C[h]:
            return split_constraint(m, w, fresh, h, a, b, count)
        if buf_push2(crossed, m.V[h], m.V[nxt(h)]):
            return ERR_NOMEM
        o = m.N[h]
        r = m.V[prv(o)]
        if r == b:
            break
        if r == GHOST:
            return ERR_INTERNAL
        s = orient_v(m, a, b, r)
        if s == 0:
            if work_push(w, r, b, count):
                return ERR_NOMEM
            b = r
            break
        if on_segment(m, a, b, r):
            # a rounding error off the segment (next to a Steiner vertex): split there and start again
            return split_at(w, a, r, b, count)
        h = nxt(o) if s > 0 else prv(o)
    # Sloan: flip crossed edges (a ring buffer of vertex pairs) until none crosses a-b
    fresh.n = 0
    head = 0
    k = crossed.n // 2
    guard = 10 * <long long> k * k + 1000
    while k > 0:
        guard -= 1
        if guard < 0 or spend(m):
            return ERR_INTERNAL
        u = crossed.data[2 * head]
        v = crossed.data[2 * head + 1]
        head = (head + 1) % (crossed.n // 2)
        k -= 1
        h = find_edge(m, u, v)
        if h < 0:
            return ERR_INTERNAL
        x = m.V[prv(h)]
        y = m.V[prv(m.N[h])]
        if orient_v(m, x, y, u) * orient_v(m, x, y, v) >= 0:
            # not strictly convex yet: retry after the others
            crossed.data[2 * ((head + k) % (crossed.n // 2))] = u
            crossed.data[2 * ((head + k) % (crossed.n // 2)) + 1] = v
            k += 1
            continue
        flip(m, h)
        if (x == a and y == b) or (x == b and y == a):
            continue
        if orient_v(m, a, b, x) * orient_v(m, a, b, y) < 0:
            crossed.data[2 * ((head + k) % (crossed.n // 2))] = x
            crossed.data[2 * ((head + k) % (crossed.n // 2)) + 1] = y
            k += 1
        elif buf_push2(fresh, x, y):
            return ERR_NOMEM
    h = find_edge(m, a, b)
    if h < 0:
        return ERR_INTERNAL
    mark(m, h, count)
    return restore_delaunay(m, fresh)


cdef int insert_constraints(Mesh *m, const int *segs, int nseg, const int *vmap) noexcept nogil:
    cdef Work w
    cdef Buffer crossed, fresh, bypassed
    cdef int i, a, b, count, err = 0
    w.data = NULL
    w.n = w.cap = 0
    crossed.data = fresh.data = bypassed.data = NULL
    crossed.n = crossed.cap = fresh.n = fresh.cap = bypassed.n = bypassed.cap = 0
    for i in range(nseg - 1, -1, -1):
        err = work_push(&w, vmap[segs[2 * i]], vmap[segs[2 * i + 1]], 1)
        if err:
            break
    while err == 0 and w.n > 0:
        if spend(m):
            err = ERR_INTERNAL
            break
        w.n -= 3
        a = w.data[w.n]
        b = w.data[w.n + 1]
        count = w.data[w.n + 2]
        if a != b and count > 0:
            err = insert_segment(m, &w, &crossed, &fresh, &bypassed, a, b, count)
    if err == 0:
        err = restore_delaunay(m, &bypassed)
    free(w.data)
    free(crossed.data)
    free(fresh.data)
    free(bypassed.data)
    return err


# ---------------------------------------------------------------------------------------------------- regions

cdef int flood(Mesh *m, int t, signed char *removed, int *stack) noexcept nogil:
    """Mark every triangle reachable from t without crossing a constraint (hole seeds)."""
    cdef int n = 1, u, k, h, v
    removed[t] = 1
    stack[0] = t
    while n > 0:
        n -= 1
        u = stack[n]
        for k in range(3):
            h = 3 * u + k
            v = m.N[h] // 3
            if not m.C[h] and not removed[v]:
                removed[v] = 1
                stack[n] = v
                n += 1
    return 0


cdef int depths(Mesh *m, int *depth, int *entry_t, int *entry_next, int *stack) noexcept nogil:
    """Even-odd depth of every triangle: the fewest constraint crossings (with multiplicity) from outside the hull.

    Dial's shortest paths: free moves (across unconstrained edges) flood at the current depth; crossing a constraint
    edge costs its multiplicity and parks the triangle in the bucket of that depth (a ring of max-multiplicity + 1
    singly linked lists). ``entry_*`` need room for every ghost and every constrained half-edge.
    """
    cdef int nb = 1, t, u, k, h, v, e, n_entries = 0, pending = 0, sn, d = 0, b
    for h in range(3 * m.nt):
        if m.C[h] + 1 > nb:
            nb = m.C[h] + 1
    cdef int *head = <int *> malloc(<size_t> nb * sizeof(int))
    if head == NULL:
        return ERR_NOMEM
    for b in range(nb):
        head[b] = -1
    for t in range(m.nt):
        depth[t] = -1
        if ghost_corner(m, t) >= 0:
            entry_t[n_entries] = t
            entry_next[n_entries] = head[0]
            head[0] = n_entries
            n_entries += 1
            pending += 1
    while pending > 0:
        b = d % nb
        while head[b] >= 0:
            e = head[b]
            head[b] = entry_next[e]
            pending -= 1
            t = entry_t[e]
            if depth[t] >= 0:
                continue
            depth[t] = d
            stack[0] = t
            sn = 1
            while sn > 0:
                sn -= 1
                u = stack[sn]
                for k in range(3):
                    h = 3 * u + k
                    v = m.N[h] // 3
                    if depth[v] >= 0:
                        continue
                    if m.C[h] == 0:
                        depth[v] = d
                        stack[sn] = v
                        sn += 1
                    else:
                        entry_t[n_entries] = v
                        entry_next[n_entries] = head[(d + m.C[h]) % nb]
                        head[(d + m.C[h]) % nb] = n_entries
                        n_entries += 1
                        pending += 1
        d += 1
    free(head)
    return 0


# ---------------------------------------------------------------------------------------------------- Python API

_ERRORS = {ERR_NOMEM: MemoryError("out of memory while triangulating"),
           ERR_INTERNAL: RuntimeError("internal error in the triangulation (please report the input)")}


def orient2d(double ax, double ay, double bx, double by, double cx, double cy):
    """Exact sign of the orientation of (a, b, c): +1 counter-clockwise, -1 clockwise, 0 collinear."""
    return rg_orient2d(ax, ay, bx, by, cx, cy)


def incircle(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy):
    """Exact sign of d against the circle through counter-clockwise a, b, c: +1 inside, -1 outside, 0 on it."""
    return rg_incircle(ax, ay, bx, by, cx, cy, dx, dy)


def triangulate(points, segments, bint inside, holes):
    """Triangulate validated arrays; see ``rigger.cdt.triangulate`` for the contract."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    cdef int n = points.shape[0], nseg = segments.shape[0]
    vmap_arr = np.arange(n, dtype=np.int32)
    if n < 3:
        return _collinear_result(points, segments)
    cdef const double[:, ::1] xy = points
    cdef int[::1] vmap = vmap_arr
    cdef const int[:, ::1] segs = np.ascontiguousarray(segments, dtype=np.int32)
    cdef int exponent
    cdef double up, up_rest
    # scale by a power of two (exact) so that products in the predicates neither overflow nor underflow
    with nogil:
        exponent = scale_exponent(&xy[0, 0], n)
        power_factors(exponent, &up, &up_rest)
    cdef Mesh m
    memset(&m, 0, sizeof(Mesh))
    m.rng = 12345
    m.budget = 2000 * (<long long> n + nseg) + 10000000
    cdef int *order = <int *> malloc(<size_t> n * sizeof(int))
    cdef int *tmp_order = <int *> malloc(<size_t> n * sizeof(int))
    cdef unsigned int *keys = <unsigned int *> malloc(<size_t> n * sizeof(unsigned int))
    cdef unsigned int *tmp_keys = <unsigned int *> malloc(<size_t> n * sizeof(unsigned int))
    cdef int err = 0, i
    # below this many points everything stays in cache anyway and renumbering only costs
    cdef bint renumber = n >= RENUMBER_MIN
    cdef int *internal = <int *> malloc(<size_t> n * sizeof(int)) if renumber else NULL  # input point -> vertex
    cdef int *seg_v = <int *> malloc(<size_t> (2 * nseg + 1) * sizeof(int))  # segment ends as vertices
    cdef int *linked = <int *> malloc(<size_t> n * sizeof(int)) if nseg else NULL
    try:
        m.cap_v = n + 16
        m.cap_t = 2 * n + 16
        m.xy = <double *> malloc(<size_t> m.cap_v * 2 * sizeof(double))
        m.VT = <int *> malloc(<size_t> m.cap_v * sizeof(int))
        m.V = <int *> malloc(<size_t> m.cap_t * 3 * sizeof(int))
        m.N = <int *> malloc(<size_t> m.cap_t * 3 * sizeof(int))
        m.C = <int *> malloc(<size_t> m.cap_t * 3 * sizeof(int))
        if not (order and tmp_order and keys and tmp_keys and m.xy and m.VT and m.V and m.N and m.C and seg_v and
                (internal or not renumber) and (linked or not nseg)):
            raise MemoryError("out of memory while triangulating")
        with nogil:
            for i in range(n):
                m.xy[2 * i] = xy[i, 0] * up * up_rest
                m.xy[2 * i + 1] = xy[i, 1] * up * up_rest
                m.VT[i] = -1
            m.nv = n
            m.snap = SNAP_FRACTION * hilbert_order(m.xy, n, order, keys, tmp_keys, tmp_order)
            if renumber:
                # number the vertices in insertion order, so that the predicates read memory close together
                for i in range(n):
                    m.xy[2 * i] = xy[order[i], 0] * up * up_rest
                    m.xy[2 * i + 1] = xy[order[i], 1] * up * up_rest
                    tmp_order[i] = i
                    internal[order[i]] = i
            for i in range(2 * nseg):
                seg_v[i] = internal[segs[i // 2, i % 2]] if renumber else segs[i // 2, i % 2]
            if nseg:
                link_segment_ends(seg_v, nseg, n, linked)
            err = delaunay(&m, n, tmp_order if renumber else order, &vmap[0], linked)
        if err == 1:
            return _collinear_result(points, segments)
        if err:
            raise _ERRORS[err]
        # internal vertex -> input point
        original = np.asarray(<int[:n]> order).copy() if renumber else np.arange(n, dtype=np.int32)
        if nseg:
            with nogil:
                err = insert_constraints(&m, seg_v, nseg, &vmap[0])
            if err:
                raise _ERRORS[err]
        vertex_map = np.empty(n, dtype=np.int32)
        vertex_map[original] = original[vmap_arr]
        to_input = np.concatenate([original, np.arange(n, m.nv, dtype=np.int32)])
        return _collect(&m, points, exponent, vertex_map, to_input, inside, np.ascontiguousarray(
            np.ldexp(np.asarray(holes, dtype=np.float64).reshape(-1, 2), -exponent)))
    finally:
        free(order)
        free(tmp_order)
        free(keys)
        free(tmp_keys)
        free(internal)
        free(seg_v)
        free(linked)
        free(m.xy)
        free(m.VT)
        free(m.V)
        free(m.N)
        free(m.C)
        free(m.stack)


cdef object _collect(Mesh *m, object points, int exponent, object vmap_arr, object to_input_arr, bint inside,
                     double[:, ::1] holes):
    """Keep the wanted real triangles and build the output arrays (vertices numbered as the input, ``to_input``)."""
    cdef int[::1] to_input = to_input_arr
    cdef int nt = m.nt, t, k, j, h, loc, at, start, kept = 0, nseg = 0, d
    removed_arr = np.zeros(nt, dtype=np.int8)
    stack_arr = np.empty(nt + 1, dtype=np.int32)
    cdef signed char[::1] removed = removed_arr
    cdef int[::1] stack = stack_arr
    for t in range(nt):
        if ghost_corner(m, t) >= 0:
            removed[t] = 1
    start = m.VT[0] // 3 if m.VT[0] >= 0 else 0
    for k in range(holes.shape[0]):
        loc = locate(m, holes[k, 0], holes[k, 1], start, &at)
        if loc < 0:
            raise _ERRORS[loc]
        if not removed[at // 3]:
            flood(m, at // 3, &removed[0], &stack[0])
    cdef int[::1] depth
    if inside:
        depth = np.empty(nt, dtype=np.int32)
        _depths(m, depth, np.empty(4 * nt + 1, dtype=np.int32), np.empty(4 * nt + 1, dtype=np.int32), stack_arr)
        for t in range(nt):
            if depth[t] % 2 == 0:
                removed[t] = 1
    cdef int[::1] new_index = stack_arr  # reused: the flood stack is no longer needed
    for t in range(nt):
        new_index[t] = -1 if removed[t] else kept
        kept += 0 if removed[t] else 1
    triangles = np.empty((kept, 3), dtype=np.int32)
    neighbors = np.empty((kept, 3), dtype=np.int32)
    constrained = np.empty((kept, 3), dtype=np.bool_)
    cdef int[:, ::1] tri_v = triangles, tri_n = neighbors
    cdef npy_bool[:, ::1] tri_c = constrained
    for t in range(nt):
        k = new_index[t]
        if k < 0:
            continue
        for j in range(3):
            tri_v[k, j] = to_input[m.V[3 * t + j]]
            # the edge opposite corner j runs from corner j+1 to corner j+2: half-edge (j + 1) % 3
            h = 3 * t + (j + 1) % 3
            tri_n[k, j] = new_index[m.N[h] // 3]
            tri_c[k, j] = m.C[h] > 0
    for h in range(3 * nt):
        d = m.V[nxt(h)]
        if m.C[h] and m.V[h] >= 0 and d >= 0 and m.V[h] < d:
            nseg += 1
    segs = np.empty((nseg, 2), dtype=np.int32)
    cdef int[:, ::1] seg_v = segs
    nseg = 0
    for h in range(3 * nt):
        d = m.V[nxt(h)]
        if m.C[h] and m.V[h] >= 0 and d >= 0 and m.V[h] < d:
            seg_v[nseg, 0] = min(to_input[m.V[h]], to_input[d])
            seg_v[nseg, 1] = max(to_input[m.V[h]], to_input[d])
            nseg += 1
    segs = segs[np.lexsort((segs[:, 1], segs[:, 0]))]
    n = len(points)
    vertices = np.empty((m.nv, 2), dtype=np.float64)
    vertices[:n] = points
    if m.nv > n:
        vertices[n:] = np.ldexp(np.asarray(<double[:2 * m.nv]> m.xy).reshape(m.nv, 2)[n:], exponent)
    return dict(vertices=vertices, triangles=triangles, neighbors=neighbors, constrained=constrained,
                vertex_map=vmap_arr, segments=segs)


cdef void _depths(Mesh *m, int[::1] depth, int[::1] entry_t, int[::1] entry_next, int[::1] stack):
    if depths(m, &depth[0], &entry_t[0], &entry_next[0], &stack[0]):
        raise MemoryError("out of memory while triangulating")


def _collinear_result(points, segments):
    """No triangle: merge duplicates and split the segments at the points lying on them (all points collinear)."""
    n = len(points)
    if n:
        _, first, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
        vmap = first[inverse.reshape(-1)].astype(np.int32)
    else:
        vmap = np.zeros(0, np.int32)
    reps = np.unique(vmap)
    pieces = []
    if len(segments) and len(reps) > 1:
        span = points[reps].max(axis=0) - points[reps].min(axis=0)
        axis = int(np.argmax(span))
        line = reps[np.argsort(points[reps, axis], kind="stable")]
        rank = np.empty(n, dtype=np.int64)
        rank[line] = np.arange(len(line))
        for a, b in np.asarray(segments):
            ra, rb = sorted((rank[vmap[a]], rank[vmap[b]]))
            pieces.extend(zip(line[ra:rb], line[ra + 1:rb + 1]))
    segs = np.array(sorted({(min(a, b), max(a, b)) for a, b in pieces}), dtype=np.int32).reshape(-1, 2)
    return dict(vertices=np.array(points, dtype=np.float64).reshape(-1, 2), triangles=np.zeros((0, 3), np.int32),
                neighbors=np.zeros((0, 3), np.int32), constrained=np.zeros((0, 3), bool), vertex_map=vmap,
                segments=segs)
