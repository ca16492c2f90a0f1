/* Exact adaptive orientation and in-circle predicates for the CDT (ext/cdt.pyx).
 *
 * Each predicate first evaluates the determinant in plain double arithmetic with a forward error bound
 * (Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997); only when
 * the result is too close to zero to trust its sign does it go on. Orientation then follows Shewchuk's stages: the
 * determinant of the rounded differences as an exact expansion, then corrected for the differences' rounding to first
 * order. In-circle gets that corrected estimate far more cheaply, from the rounded differences in double-double
 * arithmetic with its own error bound: symmetric outlines make near-cocircular tests common, and a double-double
 * estimate settles nearly all of them. The last resort expands the determinant exactly from the raw coordinates
 * (short and easy to check, and slow; it runs on a tiny fraction of calls).
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
/* second-stage bound (Shewchuk): the determinant computed exactly from rounded differences is off by at most this */
static const double rigger_ccw_bound_b = (2.0 + 12.0 * RIGGER_EPS) * RIGGER_EPS;
/* third stage: first-order corrections for the rounding of the differences, then these bounds */
static const double rigger_ccw_bound_c = (9.0 + 64.0 * RIGGER_EPS) * RIGGER_EPS * RIGGER_EPS;
static const double rigger_result_bound = (3.0 + 8.0 * RIGGER_EPS) * RIGGER_EPS;
/* The in-circle third stage evaluates the determinant of the rounded differences in double-double arithmetic instead
 * of exactly: that adds less than 50 u^2 * permanent (see rg_incircle_dd), a rounding of that estimate (u times it,
 * below u |det| + 4.01 u^2 * permanent since the corrections stay below 4.01 u * permanent) and one more rounding
 * (u |det|) to Shewchuk's stage-C bounds (44 + 576 u) u^2 * permanent + (3 + 8 u) u |det|. These keep a wide margin. */
static const double rigger_icc_bound_dd = (44.0 + 128.0 + 576.0 * RIGGER_EPS) * RIGGER_EPS * RIGGER_EPS;
static const double rigger_result_bound_dd = (6.0 + 8.0 * RIGGER_EPS) * RIGGER_EPS;

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

/* h = e + f in linear time: take the components of both in order of magnitude and carry one running sum through
 * them (Fast-Expansion-Sum). h must hold elen + flen doubles and may not alias e or f. Returns length. */
static int rg_sum(int elen, const double *e, int flen, const double *f, double *h) {
    int i = 0, j = 0, n = 0;
    double q, hh, next;
    if (elen == 0 && flen == 0) {
        h[0] = 0.0;
        return 1;
    }
    if (j >= flen || (i < elen && fabs(e[i]) < fabs(f[j]))) q = e[i++];
    else q = f[j++];
    while (i < elen || j < flen) {
        if (j >= flen || (i < elen && fabs(e[i]) < fabs(f[j]))) next = e[i++];
        else next = f[j++];
        rg_two_sum(q, next, &q, &hh);
        if (hh != 0.0) h[n++] = hh;
    }
    if (q != 0.0 || n == 0) h[n++] = q;
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

/* h = e * f. h and acc (the running sum) must each hold 2 * elen * flen doubles. Returns length. */
static int rg_mul(int elen, const double *e, int flen, const double *f, double *h, double *acc) {
    double part[2 * 16];
    int n = 0;
    for (int j = 0; j < flen; j++) {
        int pn = rg_scale(elen, e, f[j], part);
        n = rg_sum(n, acc, pn, part, h);
        for (int i = 0; i < n; i++) acc[i] = h[i];
    }
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

/* a - b = x + y exactly */
static inline void rg_two_diff(double a, double b, double *x, double *y) {
    double d = a - b;
    double bv = a - d;
    double av = d + bv;
    *x = d;
    *y = (a - av) + (bv - b);
}

static double rg_estimate(int n, const double *e) {
    double sum = 0.0;
    for (int i = 0; i < n; i++) sum += e[i];
    return sum;
}

static inline int rg_sign(double x) { return (x > 0.0) - (x < 0.0); }

/* Exact orientation sign once the plain filter failed. The determinant of the rounded differences, expanded exactly,
 * decides when the differences were exact (nearby points) or when it clears the second-stage bound; otherwise the
 * determinant is expanded from the raw coordinates. */
static int rg_orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy, double detsum) {
    double acx, acy, bcx, bcy, t0, t1, t2, t3, l[2], r[2], e[12];
    rg_two_diff(ax, cx, &acx, &t0);
    rg_two_diff(ay, cy, &acy, &t1);
    rg_two_diff(bx, cx, &bcx, &t2);
    rg_two_diff(by, cy, &bcy, &t3);
    rg_two_product(acx, bcy, &l[1], &l[0]);
    rg_two_product(-acy, bcx, &r[1], &r[0]);
    int n = rg_sum(2, l, 2, r, e);
    if (t0 == 0.0 && t1 == 0.0 && t2 == 0.0 && t3 == 0.0) return rg_sign_of(n, e);
    double est = rg_estimate(n, e);
    if (fabs(est) >= rigger_ccw_bound_b * detsum) return rg_sign(est);
    double bound = rigger_ccw_bound_c * detsum + rigger_result_bound * fabs(est);
    est += (acx * t3 + bcy * t0) - (acy * t2 + bcx * t1);
    if (fabs(est) >= bound) return rg_sign(est);
    n = rg_orient_exact_expansion(ax, ay, bx, by, cx, cy, e);
    return rg_sign_of(n, e);
}

/* Sign of orient(a, b, c): +1 when counter-clockwise, -1 clockwise, 0 collinear. */
static inline int rg_orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
    double left = (ax - cx) * (by - cy);
    double right = (ay - cy) * (bx - cx);
    double det = left - right;
    double bound = rigger_ccw_bound * (fabs(left) + fabs(right));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    return rg_orient2d_exact(ax, ay, bx, by, cx, cy, fabs(left) + fabs(right));
}

/* Exact x^2 + y^2 (4 doubles). */
static int rg_lift(double x, double y, double *out) {
    double xx[2], yy[2];
    rg_two_product(x, x, &xx[1], &xx[0]);
    rg_two_product(y, y, &yy[1], &yy[0]);
    return rg_sum(2, xx, 2, yy, out);
}

static int rg_incircle_exact(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
    /* det of rows (x, y, x^2 + y^2, 1) for a, b, c, d, expanded along the lifted column:
     * l_a |bcd| - l_b |acd| + l_c |abd| - l_d |abc|, positive when d is inside the circle of ccw a, b, c. */
    const double px[4] = {ax, bx, cx, dx}, py[4] = {ay, by, cy, dy};
    double total[4 * 96 + 8], next[4 * 96 + 8];
    int tn = 0;
    for (int i = 0; i < 4; i++) {
        int idx[3], m = 0;
        for (int j = 0; j < 4; j++) if (j != i) idx[m++] = j;
        double minor[12], lift[4], prod[96], mulscratch[96];
        int mn = rg_orient_exact_expansion(px[idx[0]], py[idx[0]], px[idx[1]], py[idx[1]], px[idx[2]], py[idx[2]],
                                           minor);
        int ln = rg_lift(px[i], py[i], lift);
        int pn = rg_mul(mn, minor, ln, lift, prod, mulscratch);
        if (i & 1) for (int k = 0; k < pn; k++) prod[k] = -prod[k];
        tn = rg_sum(tn, total, pn, prod, next);
        for (int k = 0; k < tn; k++) total[k] = next[k];
    }
    return tn ? rg_sign_of(tn, total) : 0;
}

/* x * (p*q - r*s) * x + y * (p*q - r*s) * y, exactly, for one row of the translated in-circle determinant. */
static int rg_lifted_minor(double x, double y, double p, double q, double r, double s, double *out) {
    double pq[2], rs[2], minor[4], xm[8], xxm[16], ym[8], yym[16];
    rg_two_product(p, q, &pq[1], &pq[0]);
    rg_two_product(-r, s, &rs[1], &rs[0]);
    int mn = rg_sum(2, pq, 2, rs, minor);
    int n1 = rg_scale(rg_scale(mn, minor, x, xm), xm, x, xxm);
    int n2 = rg_scale(rg_scale(mn, minor, y, ym), ym, y, yym);
    return rg_sum(n1, xxm, n2, yym, out);
}

/* One row l * m of the translated in-circle determinant, l = x^2 + y^2 and m = p*q - r*s, as hi + lo in double-double
 * arithmetic (u = 2^-53, T = |pq| + |rs|): with l = lh + l' (|l'| <= 2.01 u lh) and m = mh + m' (|m'| <= 2.01 u T),
 * computed l' is within 4.01 u^2 lh and m' within 5.01 u^2 T; lh m' and l' mh are rounded once more and l' m' is
 * dropped, and lo sums three terms of size <= 2.02 u lh T. In all |hi + lo - l m| <= 25.2 u^2 lh T. */
static inline void rg_dd_row(double x, double y, double p, double q, double r, double s, double *hi, double *lo) {
    double xx, xx0, yy, yy0, lh, le, pq, pq0, rs, rs0, mh, me, prod0;
    rg_two_product(x, x, &xx, &xx0);
    rg_two_product(y, y, &yy, &yy0);
    rg_two_sum(xx, yy, &lh, &le);
    double ll = (le + xx0) + yy0;
    rg_two_product(p, q, &pq, &pq0);
    rg_two_product(r, s, &rs, &rs0);
    rg_two_diff(pq, rs, &mh, &me);
    double ml = (me + pq0) - rs0;
    rg_two_product(lh, mh, hi, &prod0);
    *lo = (prod0 + lh * ml) + ll * mh;
}

/* The determinant of the rounded differences within 50 u^2 * permanent (plus the rounding of the result): the rows'
 * his are summed exactly by two-sums, and the five small parts (each row's lo <= 5.05 u of its share of the
 * permanent, the two two-sum errors together <= 2.01 u * permanent) are added in plain arithmetic; the rounding of
 * those four additions is below u times the sum of the partial sums, < 23.2 u^2 * permanent, on top of the rows'
 * 25.2 u^2. */
static inline double rg_incircle_dd(double adx, double ady, double bdx, double bdy, double cdx, double cdy) {
    double ha, la, hb, lb, hc, lc, s1, e1, s2, e2;
    rg_dd_row(adx, ady, bdx, cdy, cdx, bdy, &ha, &la);
    rg_dd_row(bdx, bdy, cdx, ady, adx, cdy, &hb, &lb);
    rg_dd_row(cdx, cdy, adx, bdy, bdx, ady, &hc, &lc);
    rg_two_sum(ha, hb, &s1, &e1);
    rg_two_sum(s1, hc, &s2, &e2);
    return s2 + ((((e1 + e2) + la) + lb) + lc);
}

/* Exact determinant of the rounded differences as an expansion, for when they are exact (t = 0) but the double-double
 * estimate was too close to zero. */
static int rg_incircle_expansion(double adx, double ady, double bdx, double bdy, double cdx, double cdy, double *all) {
    double ra[32], rb[32], rc[32], ab[64];
    int na = rg_lifted_minor(adx, ady, bdx, cdy, cdx, bdy, ra);
    int nb = rg_lifted_minor(bdx, bdy, cdx, ady, adx, cdy, rb);
    int nc = rg_lifted_minor(cdx, cdy, adx, bdy, bdx, ady, rc);
    int nab = rg_sum(na, ra, nb, rb, ab);
    return rg_sum(nab, ab, nc, rc, all);
}

/* In-circle sign once the plain filter failed (near-cocircular): the determinant of the rounded differences in
 * double-double arithmetic, plus the first-order effect of the differences' tails, d(L_a M_a) = dL_a M_a + L_a dM_a
 * summed over the rows (Shewchuk's stage C); exact expansions when even that is too close to zero. */
static int rg_incircle_adapt(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy,
                             double permanent) {
    double adx = ax - dx, ady = ay - dy, bdx = bx - dx, bdy = by - dy, cdx = cx - dx, cdy = cy - dy;
    double alift = adx * adx + ady * ady, blift = bdx * bdx + bdy * bdy, clift = cdx * cdx + cdy * cdy;
    double t[6], x;
    rg_two_diff(ax, dx, &x, &t[0]);
    rg_two_diff(ay, dy, &x, &t[1]);
    rg_two_diff(bx, dx, &x, &t[2]);
    rg_two_diff(by, dy, &x, &t[3]);
    rg_two_diff(cx, dx, &x, &t[4]);
    rg_two_diff(cy, dy, &x, &t[5]);
    double est = rg_incircle_dd(adx, ady, bdx, bdy, cdx, cdy);
    est += (alift * ((bdx * t[5] + cdy * t[2]) - (bdy * t[4] + cdx * t[3])) +
            2.0 * (adx * t[0] + ady * t[1]) * (bdx * cdy - bdy * cdx)) +
           (blift * ((cdx * t[1] + ady * t[4]) - (cdy * t[0] + adx * t[5])) +
            2.0 * (bdx * t[2] + bdy * t[3]) * (cdx * ady - cdy * adx)) +
           (clift * ((adx * t[3] + bdy * t[0]) - (ady * t[2] + bdx * t[1])) +
            2.0 * (cdx * t[4] + cdy * t[5]) * (adx * bdy - ady * bdx));
    if (fabs(est) >= rigger_icc_bound_dd * permanent + rigger_result_bound_dd * fabs(est)) return rg_sign(est);
    if (t[0] == 0.0 && t[1] == 0.0 && t[2] == 0.0 && t[3] == 0.0 && t[4] == 0.0 && t[5] == 0.0) {
        double all[96];
        return rg_sign_of(rg_incircle_expansion(adx, ady, bdx, bdy, cdx, cdy, all), all);
    }
    return rg_incircle_exact(ax, ay, bx, by, cx, cy, dx, dy);
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
    return rg_incircle_adapt(ax, ay, bx, by, cx, cy, dx, dy, permanent);
}

#endif
