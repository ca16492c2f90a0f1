/* Exact adaptive orientation and in-circle predicates for the CDT (ext/cdt.pyx).
 *
 * Each predicate first evaluates the determinant in plain double arithmetic with a forward error bound
 * (Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997); only when
 * the result is too close to zero to trust its sign does it recompute the determinant exactly with floating-point
 * expansions. The exact path expands the determinants from the raw coordinates (no rounded differences), which is
 * slower than Shewchuk's staged adaptive version but short and easy to check; it runs on a tiny fraction of calls.
 *
 * Requires IEEE double arithmetic with round-to-nearest and no fused multiply-add contraction (setup.py passes
 * -ffp-contract=off). Exactness holds while no product overflows or underflows; cdt.pyx scales the input by a power of
 * two (an exact operation) so coordinates are of order one.
 */
#ifndef RIGGER_CDT_PREDICATES_H
#define RIGGER_CDT_PREDICATES_H

#include <math.h>

#define RIGGER_EPS 1.1102230246251565e-16 /* 2^-53 */
#define RIGGER_SPLITTER 134217729.0       /* 2^27 + 1 */
static const double rigger_ccw_bound = (3.0 + 16.0 * RIGGER_EPS) * RIGGER_EPS;
static const double rigger_icc_bound = (10.0 + 96.0 * RIGGER_EPS) * RIGGER_EPS;

/* a + b = x + y exactly, |y| <= ulp(x)/2 */
static inline void rg_two_sum(double a, double b, double *x, double *y) {
    double s = a + b;
    double bv = s - a;
    double av = s - bv;
    *x = s;
    *y = (a - av) + (b - bv);
}

static inline void rg_split(double a, double *hi, double *lo) {
    double c = RIGGER_SPLITTER * a;
    double big = c - a;
    *hi = c - big;
    *lo = a - *hi;
}

/* a * b = x + y exactly (Dekker) */
static inline void rg_two_product(double a, double b, double *x, double *y) {
    double p = a * b, ahi, alo, bhi, blo;
    rg_split(a, &ahi, &alo);
    rg_split(b, &bhi, &blo);
    double err = p - ahi * bhi - alo * bhi - ahi * blo;
    *x = p;
    *y = alo * blo - err;
}

/* h = e + b for a nonoverlapping expansion e (increasing magnitude); zero components dropped. Returns length. */
static int rg_grow(int elen, const double *e, double b, double *h) {
    double q = b, hh;
    int n = 0;
    for (int i = 0; i < elen; i++) {
        rg_two_sum(q, e[i], &q, &hh);
        if (hh != 0.0) h[n++] = hh;
    }
    if (q != 0.0 || n == 0) h[n++] = q;
    return n;
}

/* h = e + f. h must hold elen + flen doubles and may not alias e or f. Returns length. */
static int rg_sum(int elen, const double *e, int flen, const double *f, double *h, double *scratch) {
    int n = elen;
    for (int i = 0; i < elen; i++) h[i] = e[i];
    for (int j = 0; j < flen; j++) {
        n = rg_grow(n, h, f[j], scratch);
        for (int i = 0; i < n; i++) h[i] = scratch[i];
    }
    return n;
}

/* h = e * b. h must hold 2 * elen doubles. Returns length. */
static int rg_scale(int elen, const double *e, double b, double *h) {
    double q, hh, p1, p0, sum;
    int n = 0;
    rg_two_product(e[0], b, &q, &hh);
    if (hh != 0.0) h[n++] = hh;
    for (int i = 1; i < elen; i++) {
        rg_two_product(e[i], b, &p1, &p0);
        rg_two_sum(q, p0, &sum, &hh);
        if (hh != 0.0) h[n++] = hh;
        rg_two_sum(p1, sum, &q, &hh);
        if (hh != 0.0) h[n++] = hh;
    }
    if (q != 0.0 || n == 0) h[n++] = q;
    return n;
}

/* h = e * f. h must hold 2 * elen * flen doubles; scratch likewise (twice). Returns length. */
static int rg_mul(int elen, const double *e, int flen, const double *f, double *h, double *scratch) {
    double part[2 * 16];
    double *acc = scratch, *tmp = scratch + 2 * elen * flen;
    int n = 0;
    for (int j = 0; j < flen; j++) {
        int pn = rg_scale(elen, e, f[j], part);
        n = rg_sum(n, acc, pn, part, h, tmp);
        for (int i = 0; i < n; i++) acc[i] = h[i];
    }
    for (int i = 0; i < n; i++) h[i] = acc[i];
    return n;
}

static inline int rg_sign_of(int n, const double *e) {
    double top = e[n - 1];
    return (top > 0.0) - (top < 0.0);
}

/* Exact expansion of det |px py 1; qx qy 1; rx ry 1| (12 doubles). */
static int rg_orient_exact_expansion(double px, double py, double qx, double qy, double rx, double ry, double *out) {
    double terms[6][2];
    rg_two_product(px, qy, &terms[0][1], &terms[0][0]);
    rg_two_product(-py, qx, &terms[1][1], &terms[1][0]);
    rg_two_product(qx, ry, &terms[2][1], &terms[2][0]);
    rg_two_product(-qy, rx, &terms[3][1], &terms[3][0]);
    rg_two_product(rx, py, &terms[4][1], &terms[4][0]);
    rg_two_product(-ry, px, &terms[5][1], &terms[5][0]);
    double scratch[12];
    int n = 0;
    for (int k = 0; k < 6; k++) {
        for (int c = 0; c < 2; c++) {
            n = rg_grow(n, out, terms[k][c], scratch);
            for (int i = 0; i < n; i++) out[i] = scratch[i];
        }
    }
    return n;
}

/* Sign of orient(a, b, c): +1 when counter-clockwise, -1 clockwise, 0 collinear. */
static inline int rg_orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
    double left = (ax - cx) * (by - cy);
    double right = (ay - cy) * (bx - cx);
    double det = left - right;
    double bound = rigger_ccw_bound * (fabs(left) + fabs(right));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    double e[12];
    int n = rg_orient_exact_expansion(ax, ay, bx, by, cx, cy, e);
    return rg_sign_of(n, e);
}

/* Exact x^2 + y^2 (4 doubles). */
static int rg_lift(double x, double y, double *out) {
    double xx[2], yy[2], scratch[4];
    rg_two_product(x, x, &xx[1], &xx[0]);
    rg_two_product(y, y, &yy[1], &yy[0]);
    return rg_sum(2, xx, 2, yy, out, scratch);
}

static int rg_incircle_exact(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
    /* det of rows (x, y, x^2 + y^2, 1) for a, b, c, d, expanded along the lifted column:
     * l_a |bcd| - l_b |acd| + l_c |abd| - l_d |abc|, positive when d is inside the circle of ccw a, b, c. */
    const double px[4] = {ax, bx, cx, dx}, py[4] = {ay, by, cy, dy};
    double total[4 * 96 + 8], next[4 * 96 + 8], scratch[4 * 96 + 8];
    int tn = 0;
    for (int i = 0; i < 4; i++) {
        int idx[3], m = 0;
        for (int j = 0; j < 4; j++) if (j != i) idx[m++] = j;
        double minor[12], lift[4], prod[96], mulscratch[2 * 96];
        int mn = rg_orient_exact_expansion(px[idx[0]], py[idx[0]], px[idx[1]], py[idx[1]], px[idx[2]], py[idx[2]], minor);
        int ln = rg_lift(px[i], py[i], lift);
        int pn = rg_mul(mn, minor, ln, lift, prod, mulscratch);
        if (i & 1) for (int k = 0; k < pn; k++) prod[k] = -prod[k];
        tn = rg_sum(tn, total, pn, prod, next, scratch);
        for (int k = 0; k < tn; k++) total[k] = next[k];
    }
    return tn ? rg_sign_of(tn, total) : 0;
}

/* Sign of incircle(a, b, c, d): +1 when d lies strictly inside the circle through counter-clockwise a, b, c. */
static inline int rg_incircle(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
    double adx = ax - dx, ady = ay - dy, bdx = bx - dx, bdy = by - dy, cdx = cx - dx, cdy = cy - dy;
    double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy, cdxady = cdx * ady, adxcdy = adx * cdy;
    double adxbdy = adx * bdy, bdxady = bdx * ady;
    double alift = adx * adx + ady * ady, blift = bdx * bdx + bdy * bdy, clift = cdx * cdx + cdy * cdy;
    double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    double permanent = (fabs(bdxcdy) + fabs(cdxbdy)) * alift + (fabs(cdxady) + fabs(adxcdy)) * blift +
                       (fabs(adxbdy) + fabs(bdxady)) * clift;
    double bound = rigger_icc_bound * permanent;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    return rg_incircle_exact(ax, ay, bx, by, cx, cy, dx, dy);
}

#endif
