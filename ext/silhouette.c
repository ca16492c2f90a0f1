/* The 3D silhouette tracer; see silhouette.h for the method in brief.
 *
 * Exactness. Projected vertices are snapped to integers with 2^16 steps per cell on a grid of at most 2^14 cells a
 * side, so coordinates stay below 2^30 and every orientation test below is exact in int64. A lattice point p is
 * taken as p + (e, e^2) for an infinitesimal e > 0 (simulation of simplicity): it never lies on a triangle edge, two
 * triangles sharing an edge never both or neither contain it, and the horizontal pass, the vertical pass, the cell
 * refinement and point queries all ask that same predicate. So corners, crossings and chords agree by construction.
 *
 * Pipeline: frame and projection -> snap -> for each family of grid lines, a sweep that keeps the triangles crossing
 * the current line and tallies their exact cross-sections into the union's crossings -> per cell, chords pairing the
 * crossings, with ambiguous cells (more than two crossings) split into quarters along exact midlines until each part
 * is clear -> loops by following the chords -> parts touching at a point pulled a hair apart, specks dropped ->
 * optional simplification that never removes a point whose triangle holds another point. Depth queries bin the
 * triangles on first use and cast exact rays against one bin.
 */
#include "silhouette.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FIX_SHIFT 16
#define FIX_ONE ((int64_t)1 << FIX_SHIFT)
/* Empty cells before the shape. The fraction keeps the mesh's centre and mirror plane off the grid lines, where
 * parts that touch at a point would make an outline touch itself. */
#define GRID_MARGIN 1.3819660112501051
#define TOUCH_NUDGE 1e-6  /* cells a point that an outline visits twice moves to its inner side */
#define SPECK 1e-4        /* loops enclosing less (square cells) are dropped: far below the resolution */
#define SIMPLIFY_LENGTH 64.0 /* cells: the longest simplified segment, which bounds the cost of proving it clear */

typedef struct {
    int32_t block, cols, rows; /* cells per bin side, bin counts */
    int64_t *start;            /* cols * rows + 1 offsets into tri */
    int32_t *tri;
} Bins;

struct SilTrace {
    double origin[3], u[3], v[3], dir[3];
    double corner[2], cell; /* frame coordinates of grid point (0, 0); cell size */
    int32_t width, height;  /* cells; grid points run 0..width and 0..height */
    int64_t n_vertices;
    double *proj;           /* per vertex: x, y, depth in the frame */
    int64_t n_all;
    int32_t *all_tris;      /* every input triangle, for the mesh topology */
    int64_t n_tris;
    int32_t *tris;          /* triangles of non-zero snapped area, counter-clockwise in the frame */
    int8_t *facing;         /* per such triangle: +1 where its own winding was counter-clockwise (it faces the
                               viewer), -1 where it was turned */
    int32_t *corners;       /* per such triangle its snapped corners x0 y0 x1 y1 x2 y2, 2^16 per cell */
    int64_t n_loops;
    int64_t *loop_start;
    double *loop_xy;
    Bins *bins;             /* built on first point query */
    int32_t *vertex_comp;   /* built on first layers query: component (lowest welded vertex) per vertex */
};

typedef struct { /* one triangle's cross-section of one grid line */
    int32_t gap_lo, gap_hi; /* entry lies between grid points gap_lo and gap_lo+1; exit likewise */
    double pos_lo, pos_hi;  /* positions along the line, in cells */
} Span;

typedef struct { /* the union's boundary points on one family of grid lines, sorted by line, gap, position */
    int64_t count, cap;
    int32_t *line, *gap;
    double *pos;
    uint8_t *is_start; /* 1 where the union begins as the line coordinate grows */
    int64_t *line_start;
} Crossings;

typedef struct { /* a crossing met while walking around a cell counter-clockwise */
    int64_t id;
    int enter;   /* the walk goes from outside the shape to inside here */
    int side;    /* 0 bottom, 1 right, 2 top, 3 left */
    double x, y; /* grid position */
} Stop;

typedef struct { /* one ray hit, for layers */
    double depth;
    int32_t comp;
    int8_t facing; /* the triangle's, see SilTrace */
} Hit;

/* ------------------------------------------------------------------------------------------------ memory */

static void *alloc_array(int64_t n, size_t elem)
{
    if (n < 1) n = 1;
    if ((uint64_t)n > SIZE_MAX / elem) return NULL;
    return malloc((size_t)n * elem);
}

static void *zero_array(int64_t n, size_t elem)
{
    if (n < 1) n = 1;
    if ((uint64_t)n > SIZE_MAX / elem) return NULL;
    return calloc((size_t)n, elem);
}

/* Grow *data to hold at least `need` elements. */
static int reserve(void **data, int64_t *cap, int64_t need, size_t elem)
{
    if (need <= *cap) return SIL_OK;
    int64_t grown = *cap < 16 ? 16 : *cap;
    while (grown < need) {
        if (grown > INT64_MAX / 2) return SIL_ERR_NOMEM;
        grown *= 2;
    }
    if ((uint64_t)grown > SIZE_MAX / elem) return SIL_ERR_NOMEM;
    void *p = realloc(*data, (size_t)grown * elem);
    if (!p) return SIL_ERR_NOMEM;
    *data = p;
    *cap = grown;
    return SIL_OK;
}

void sil_release(void *memory) { free(memory); }

static void free_bins(Bins *bins)
{
    if (!bins) return;
    free(bins->start);
    free(bins->tri);
    free(bins);
}

void sil_free(SilTrace *t)
{
    if (!t) return;
    free(t->proj);
    free(t->corners);
    free(t->all_tris);
    free(t->tris);
    free(t->facing);
    free(t->loop_start);
    free(t->loop_xy);
    free_bins(t->bins);
    free(t->vertex_comp);
    free(t);
}

const char *sil_error_message(int code)
{
    switch (code) {
    case SIL_OK: return "ok";
    case SIL_ERR_NOMEM: return "out of memory";
    case SIL_ERR_EMPTY: return "the mesh has no vertices or no triangles";
    case SIL_ERR_TOO_LARGE:
        return "the mesh is too large: more than 2**31 - 1 vertices or triangles, or coordinates so large that "
               "their projection overflows";
    case SIL_ERR_NONFINITE: return "vertex coordinates must be finite (found NaN or infinity)";
    case SIL_ERR_INDEX: return "a triangle indexes a vertex that does not exist";
    case SIL_ERR_DIRECTION: return "direction must be a finite, non-zero 3D vector";
    case SIL_ERR_ZERO_AREA: return "every triangle projects to zero area along this direction: there is no silhouette";
    case SIL_ERR_RESOLUTION: return "resolution is out of range";
    case SIL_ERR_TOLERANCE: return "tolerance must be between 0 and 1 (a fraction of a grid cell)";
    case SIL_ERR_MISMATCH: return "the two traces come from different meshes";
    case SIL_ERR_INTERNAL: return "internal error in the silhouette tracer; please report it with the mesh";
    default: return "unknown error";
    }
}

/* ------------------------------------------------------------------------------------------------ exact arithmetic */

/* Sample m of a line lies inside an edge's half-plane iff alpha * m + beta > 0, or == 0 when the perturbation
 * tips the tie inwards (see left_of). */
#define SURE_FRACTION 1e-7    /* an estimated crossing this far from a whole sample is on the side it appears */
static int inside_sample(int64_t alpha, int64_t beta, int tie, int64_t m)
{
    int64_t f = alpha * m + beta;
    return f > 0 || (f == 0 && tie);
}

/* Is the perturbed point p + (e, e^2) strictly left of the directed edge a -> b? *base gets the unperturbed
 * orientation (twice the signed area of a, b, p). */
static int left_of(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py, int64_t *base)
{
    int64_t dx = bx - ax, dy = by - ay;
    *base = dx * (py - ay) - dy * (px - ax);
    return *base > 0 || (*base == 0 && (dy < 0 || (dy == 0 && dx > 0)));
}

static double clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

/* ------------------------------------------------------------------------------------------------ setup */

static int make_frame(SilTrace *t, const double direction[3])
{
    double scale = 0.0;
    for (int k = 0; k < 3; k++) {
        if (!isfinite(direction[k])) return SIL_ERR_DIRECTION;
        if (fabs(direction[k]) > scale) scale = fabs(direction[k]);
    }
    if (!(scale > 0.0)) return SIL_ERR_DIRECTION;
    double d[3] = {direction[0] / scale, direction[1] / scale, direction[2] / scale};
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++) d[k] /= n;
    /* v is world up (Z, or Y when looking almost straight up or down) made perpendicular to d; u = d x v, so the
     * viewer looking along d sees u to the right and v up, and outer loops come out counter-clockwise. */
    double up[3] = {0.0, 0.0, 1.0};
    if (fabs(d[2]) > 0.9) { up[1] = 1.0; up[2] = 0.0; }
    double along = up[0] * d[0] + up[1] * d[1] + up[2] * d[2];
    double v[3] = {up[0] - along * d[0], up[1] - along * d[1], up[2] - along * d[2]};
    double vn = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++) v[k] /= vn;
    double u[3] = {d[1] * v[2] - d[2] * v[1], d[2] * v[0] - d[0] * v[2], d[0] * v[1] - d[1] * v[0]};
    memcpy(t->dir, d, sizeof d);
    memcpy(t->u, u, sizeof u);
    memcpy(t->v, v, sizeof v);
    return SIL_OK;
}

static int project(SilTrace *t, const double *vertices)
{
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) lo[k] = hi[k] = vertices[k];
    for (int64_t i = 0; i < t->n_vertices; i++) {
        for (int k = 0; k < 3; k++) {
            double c = vertices[3 * i + k];
            if (!isfinite(c)) return SIL_ERR_NONFINITE;
            if (c < lo[k]) lo[k] = c;
            if (c > hi[k]) hi[k] = c;
        }
    }
    for (int k = 0; k < 3; k++) t->origin[k] = 0.5 * lo[k] + 0.5 * hi[k];
    t->proj = alloc_array(3 * t->n_vertices, sizeof(double));
    if (!t->proj) return SIL_ERR_NOMEM;
    for (int64_t i = 0; i < t->n_vertices; i++) {
        double q[3] = {vertices[3 * i] - t->origin[0], vertices[3 * i + 1] - t->origin[1],
                       vertices[3 * i + 2] - t->origin[2]};
        double x = q[0] * t->u[0] + q[1] * t->u[1] + q[2] * t->u[2];
        double y = q[0] * t->v[0] + q[1] * t->v[1] + q[2] * t->v[2];
        double z = q[0] * t->dir[0] + q[1] * t->dir[1] + q[2] * t->dir[2];
        if (!isfinite(x) || !isfinite(y) || !isfinite(z)) return SIL_ERR_TOO_LARGE;
        t->proj[3 * i] = x;
        t->proj[3 * i + 1] = y;
        t->proj[3 * i + 2] = z;
    }
    return SIL_OK;
}

static double cross_xy(const double *p, int32_t a, int32_t b, int32_t c)
{
    return (p[3 * b] - p[3 * a]) * (p[3 * c + 1] - p[3 * a + 1]) -
           (p[3 * b + 1] - p[3 * a + 1]) * (p[3 * c] - p[3 * a]);
}

static int64_t orient_fix(const int32_t *f, int32_t a, int32_t b, int32_t c)
{
    return ((int64_t)f[2 * b] - f[2 * a]) * ((int64_t)f[2 * c + 1] - f[2 * a + 1]) -
           ((int64_t)f[2 * b + 1] - f[2 * a + 1]) * ((int64_t)f[2 * c] - f[2 * a]);
}

/* The lowest and highest snapped corner of a triangle (its corners x0 y0 x1 y1 x2 y2) along axis 0 (x) or 1 (y). */
static void corner_range(const int32_t *xy, int axis, int32_t *lo, int32_t *hi)
{
    int32_t c0 = xy[axis], c1 = xy[2 + axis], c2 = xy[4 + axis];
    *lo = c0 < c1 ? (c0 < c2 ? c0 : c2) : (c1 < c2 ? c1 : c2);
    *hi = c0 > c1 ? (c0 > c2 ? c0 : c2) : (c1 > c2 ? c1 : c2);
}

/* Size the grid on the projected triangles of non-zero area, snap, and keep the triangles that stay non-degenerate. */
static int snap(SilTrace *t, int32_t resolution)
{
    const double *p = t->proj;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    uint8_t *flat = alloc_array(t->n_all, 1), *used = zero_array(t->n_vertices, 1);
    int32_t *fix = NULL;
    int rc = SIL_OK;
    if (!flat || !used) {
        free(flat);
        free(used);
        return SIL_ERR_NOMEM;
    }
    for (int64_t k = 0; k < t->n_all; k++) {
        const int32_t *tri = t->all_tris + 3 * k;
        flat[k] = cross_xy(p, tri[0], tri[1], tri[2]) == 0.0;
        if (!flat[k]) used[tri[0]] = used[tri[1]] = used[tri[2]] = 1;
    }
    for (int64_t i = 0; i < t->n_vertices; i++) {
        for (int a = 0; used[i] && a < 2; a++) {
            if (p[3 * i + a] < lo[a]) lo[a] = p[3 * i + a];
            if (p[3 * i + a] > hi[a]) hi[a] = p[3 * i + a];
        }
    }
    double extent[2] = {hi[0] - lo[0], hi[1] - lo[1]};
    double longest = extent[0] > extent[1] ? extent[0] : extent[1];
    double cell = longest / resolution;
    if (!(lo[0] <= hi[0])) rc = SIL_ERR_ZERO_AREA;
    else if (!isfinite(longest)) rc = SIL_ERR_TOO_LARGE;
    else if (!(cell > 0.0) || !isfinite(1.0 / cell)) rc = SIL_ERR_ZERO_AREA;
    if (rc != SIL_OK) goto done;
    t->cell = cell;
    t->width = (int32_t)ceil(extent[0] / cell + GRID_MARGIN + 1.0);
    t->height = (int32_t)ceil(extent[1] / cell + GRID_MARGIN + 1.0);
    t->corner[0] = lo[0] - GRID_MARGIN * cell;
    t->corner[1] = lo[1] - GRID_MARGIN * cell;

    fix = alloc_array(2 * t->n_vertices, sizeof(int32_t));
    t->tris = alloc_array(3 * t->n_all, sizeof(int32_t));
    t->corners = alloc_array(6 * t->n_all, sizeof(int32_t));
    t->facing = alloc_array(t->n_all, sizeof(int8_t));
    if (!fix || !t->tris || !t->corners || !t->facing) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    double scale = (double)FIX_ONE / cell;
    double limit[2] = {(double)t->width * FIX_ONE - 1.0, (double)t->height * FIX_ONE - 1.0};
    for (int64_t i = 0; i < t->n_vertices; i++) {
        for (int a = 0; a < 2; a++) {
            double g = nearbyint((p[3 * i + a] - t->corner[a]) * scale);
            fix[2 * i + a] = (int32_t)clampd(g, 1.0, limit[a]);
        }
    }
    int64_t kept = 0;
    for (int64_t k = 0; k < t->n_all; k++) {
        const int32_t *tri = t->all_tris + 3 * k;
        if (flat[k]) continue;
        int64_t o = orient_fix(fix, tri[0], tri[1], tri[2]);
        if (o == 0) continue;
        int32_t *out = t->tris + 3 * kept, *xy = t->corners + 6 * kept;
        out[0] = tri[0];
        out[1] = o > 0 ? tri[1] : tri[2];
        out[2] = o > 0 ? tri[2] : tri[1];
        t->facing[kept] = o > 0 ? 1 : -1;
        for (int c = 0; c < 3; c++) {
            xy[2 * c] = fix[2 * out[c]];
            xy[2 * c + 1] = fix[2 * out[c] + 1];
        }
        kept++;
    }
    t->n_tris = kept;
    rc = kept > 0 ? SIL_OK : SIL_ERR_ZERO_AREA;
done:
    free(flat);
    free(used);
    free(fix);
    return rc;
}

/* ------------------------------------------------------------------------------------------------ bins */

/* Bin the triangles by the grid cells their bounding boxes touch, about four triangles per bin. */
static int build_bins(SilTrace *t)
{
    if (t->bins) return SIL_OK;
    Bins *b = calloc(1, sizeof *b);
    if (!b) return SIL_ERR_NOMEM;
    double cells = (double)t->width * t->height;
    double wanted = t->n_tris / 4.0 > 1.0 ? t->n_tris / 4.0 : 1.0;
    double block = ceil(sqrt(cells / wanted));
    int32_t longest = t->width > t->height ? t->width : t->height;
    b->block = block < 1.0 ? 1 : (block > longest ? longest : (int32_t)block);
    b->cols = (t->width + b->block - 1) / b->block + 1;
    b->rows = (t->height + b->block - 1) / b->block + 1;
    int64_t n_bins = (int64_t)b->cols * b->rows;
    b->start = zero_array(n_bins + 1, sizeof(int64_t));
    int rc = b->start ? SIL_OK : SIL_ERR_NOMEM;
    for (int pass = 0; pass < 2 && rc == SIL_OK; pass++) {
        for (int64_t k = 0; k < t->n_tris; k++) {
            int32_t x0, x1, y0, y1;
            corner_range(t->corners + 6 * k, 0, &x0, &x1);
            corner_range(t->corners + 6 * k, 1, &y0, &y1);
            int32_t bx0 = (x0 >> FIX_SHIFT) / b->block, bx1 = (x1 >> FIX_SHIFT) / b->block;
            int32_t by0 = (y0 >> FIX_SHIFT) / b->block, by1 = (y1 >> FIX_SHIFT) / b->block;
            for (int32_t by = by0; by <= by1; by++) {
                for (int32_t bx = bx0; bx <= bx1; bx++) {
                    int64_t bin = (int64_t)by * b->cols + bx;
                    if (pass == 0) b->start[bin + 1]++;
                    else b->tri[b->start[bin]++] = (int32_t)k;
                }
            }
        }
        if (pass == 0) {
            for (int64_t i = 0; i < n_bins; i++) b->start[i + 1] += b->start[i];
            b->tri = alloc_array(b->start[n_bins], sizeof(int32_t));
            if (!b->tri) rc = SIL_ERR_NOMEM;
        } else {
            for (int64_t i = n_bins; i > 0; i--) b->start[i] = b->start[i - 1];
            b->start[0] = 0;
        }
    }
    if (rc != SIL_OK) {
        free_bins(b);
        return rc;
    }
    t->bins = b;
    return SIL_OK;
}

/* The bin range [*first, *last) of the triangles that may contain snapped point (x, y), which must be on the grid
 * (0 <= x <= width * FIX_ONE, likewise y): snap_point only passes such points. */
static void bin_of(const SilTrace *t, int64_t x, int64_t y, int64_t *first, int64_t *last)
{
    const Bins *b = t->bins;
    int64_t bin = ((y >> FIX_SHIFT) / b->block) * b->cols + (x >> FIX_SHIFT) / b->block;
    *first = b->start[bin];
    *last = b->start[bin + 1];
}

/* Does triangle k contain snapped point (x, y)? If so, its barycentric weights (times twice its area) and that area. */
static int triangle_hit(const SilTrace *t, int64_t k, int64_t x, int64_t y, int64_t w[3], int64_t *area2)
{
    const int32_t *xy = t->corners + 6 * k;
    for (int e = 0; e < 3; e++) {
        const int32_t *a = xy + 2 * ((e + 1) % 3), *b = xy + 2 * ((e + 2) % 3);
        if (!left_of(a[0], a[1], b[0], b[1], x, y, &w[e])) return 0;
    }
    *area2 = w[0] + w[1] + w[2];
    return 1;
}

/* ------------------------------------------------------------------------------------------------ line crossings */

static void sort_spans(Span *s, int64_t n)
{
    for (int64_t i = 1; i < n; i++) {
        Span key = s[i];
        int64_t j = i - 1;
        while (j >= 0 && (s[j].gap_lo > key.gap_lo || (s[j].gap_lo == key.gap_lo && s[j].pos_lo > key.pos_lo))) {
            s[j + 1] = s[j];
            j--;
        }
        s[j + 1] = key;
    }
}

static int add_crossing(Crossings *c, int32_t line, int32_t gap, double pos, int is_start)
{
    if (c->count == c->cap) { /* the four arrays share one capacity, committed once all have grown */
        int64_t cap[4] = {c->cap, c->cap, c->cap, c->cap};
        if (reserve((void **)&c->line, &cap[0], c->count + 1, sizeof(int32_t)) != SIL_OK ||
            reserve((void **)&c->gap, &cap[1], c->count + 1, sizeof(int32_t)) != SIL_OK ||
            reserve((void **)&c->pos, &cap[2], c->count + 1, sizeof(double)) != SIL_OK ||
            reserve((void **)&c->is_start, &cap[3], c->count + 1, sizeof(uint8_t)) != SIL_OK)
            return SIL_ERR_NOMEM;
        c->cap = cap[0];
    }
    c->line[c->count] = line;
    c->gap[c->count] = gap;
    c->pos[c->count] = pos;
    c->is_start[c->count] = (uint8_t)is_start;
    c->count++;
    return SIL_OK;
}

static void free_crossings(Crossings *c)
{
    free(c->line);
    free(c->gap);
    free(c->pos);
    free(c->is_start);
    free(c->line_start);
}

typedef struct { /* one triangle edge against a family of lines: sample m is inside iff alpha*m + beta > 0, or == 0
                   * and tie (the symbolic perturbation of left_of); beta grows by dbeta from one line to the next */
    int64_t alpha, beta, dbeta;
    double scale; /* -1 / alpha: the crossing lies beta * scale samples along */
    int tie;
} EdgeStep;

/* Directed edge p -> q (snapped xy) of a counter-clockwise triangle against the line at lattice coordinate `level`
 * (y = level, or x = level when vertical) whose samples sit at origin + m * step along it. */
static void edge_at(const int32_t *p, const int32_t *q, int vertical, int64_t level, int64_t origin, int64_t step,
                    EdgeStep *e)
{
    const int across = vertical ? 0 : 1, along = 1 - across;
    const int64_t sigma = vertical ? -1 : 1;
    int64_t cp = p[across], ap = p[along];
    int64_t da = q[along] - ap, dc = q[across] - cp;
    int64_t dx = vertical ? dc : da, dy = vertical ? da : dc;
    e->tie = dy < 0 || (dy == 0 && dx > 0);
    e->alpha = -sigma * dc * step;
    e->beta = sigma * (da * (level - cp) + dc * (ap - origin));
    e->dbeta = sigma * da * FIX_ONE;
    e->scale = -1.0 / (double)e->alpha;
}

/* The cross-section bounded by edges lo (alpha > 0) and hi (alpha < 0): the exact first and last sample inside
 * (gap_lo + 1 and gap_hi; none when they are equal) and the crossing positions in samples, clamped to agree. Both
 * edges span the line, so each crossing lies on its edge inside the lattice (within 2^22 samples of the origin): the
 * estimates are finite, within a sample of the truth, and |alpha * m| < 2^61. */
static int span_between(const EdgeStep *lo, const EdgeStep *hi, Span *out)
{
    double r_lo = (double)lo->beta * lo->scale, r_hi = (double)hi->beta * hi->scale;
    int64_t first = (int64_t)r_lo, last = (int64_t)r_hi;
    first -= (double)first > r_lo; /* floors */
    last -= (double)last > r_hi;
    /* The estimates err by under 2^-30 samples: away from a whole sample they settle the sample exactly. */
    if (r_lo - (double)first > SURE_FRACTION && r_lo - (double)first < 1.0 - SURE_FRACTION) {
        first++;
    } else {
        while (!inside_sample(lo->alpha, lo->beta, lo->tie, first)) first++;
        while (inside_sample(lo->alpha, lo->beta, lo->tie, first - 1)) first--;
    }
    if (!(r_hi - (double)last > SURE_FRACTION && r_hi - (double)last < 1.0 - SURE_FRACTION)) {
        while (!inside_sample(hi->alpha, hi->beta, hi->tie, last)) last--;
        while (inside_sample(hi->alpha, hi->beta, hi->tie, last + 1)) last++;
    }
    if (first - 1 > last) return SIL_ERR_INTERNAL;
    out->gap_lo = (int32_t)(first - 1);
    out->gap_hi = (int32_t)last;
    out->pos_lo = clampd(r_lo, (double)(first - 1), (double)first);
    out->pos_hi = clampd(r_hi, (double)last, (double)(last + 1));
    if (first - 1 == last && out->pos_hi < out->pos_lo) out->pos_hi = out->pos_lo;
    return SIL_OK;
}

/* The cross-section of triangle k with one line (see edge_at), which it must span: lowest across coordinate <=
 * level < highest. Exactly two of its edges span the line, one bounding it from each side. */
static int cross_section(const SilTrace *t, int64_t k, int64_t level, int vertical, int64_t origin, int64_t step,
                         Span *out)
{
    const int32_t *xy = t->corners + 6 * k;
    const int across = vertical ? 0 : 1;
    EdgeStep bound[2];
    int found[2] = {0, 0};
    for (int e = 0; e < 3; e++) {
        const int32_t *p = xy + 2 * e, *q = xy + 2 * ((e + 1) % 3);
        int64_t cp = p[across], cq = q[across];
        if (!((cp <= level && level < cq) || (cq <= level && level < cp))) continue;
        EdgeStep edge;
        edge_at(p, q, vertical, level, origin, step, &edge);
        int side = edge.alpha > 0 ? 0 : 1;
        bound[side] = edge;
        found[side]++;
    }
    if (found[0] != 1 || found[1] != 1) return SIL_ERR_INTERNAL;
    return span_between(&bound[0], &bound[1], out);
}

/* Merge sorted spans into runs in place; returns the number of runs. */
static int64_t merge_spans(Span *s, int64_t n)
{
    int64_t runs = 0;
    for (int64_t i = 0; i < n; i++) {
        Span *run = s + runs - 1;
        if (runs > 0 && (s[i].gap_lo < run->gap_hi || (s[i].gap_lo == run->gap_hi && s[i].pos_lo <= run->pos_hi))) {
            if (s[i].gap_hi > run->gap_hi || (s[i].gap_hi == run->gap_hi && s[i].pos_hi > run->pos_hi)) {
                run->gap_hi = s[i].gap_hi;
                run->pos_hi = s[i].pos_hi;
            }
        } else {
            s[runs++] = s[i];
        }
    }
    return runs;
}

typedef struct { /* a triangle crossing the current line of a sweep */
    EdgeStep lo, hi;   /* the edges bounding its cross-section from below and above along the line */
    const int32_t *xy; /* its corners */
    int32_t turn;      /* the line where the second short edge takes over, or -1 */
    int32_t last;      /* the last line it crosses */
    int8_t next_edge;  /* that second short edge */
    int8_t next_is_lo; /* and the side it bounds */
} Active;

static int32_t first_line_at(int64_t c) { return (int32_t)((c + FIX_ONE - 1) >> FIX_SHIFT); } /* c >= 0 */

/* Start stepping a triangle (its snapped corners) at its first line: sort the corners along the lines' normal; the
 * long edge bounds one side throughout, the short edges the other side, the second one from line `turn` on. */
static void activate(const int32_t *xy, int vertical, Active *a)
{
    const int across = vertical ? 0 : 1;
    int lowest = 0, highest = 0;
    for (int i = 1; i < 3; i++) {
        if (xy[2 * i + across] < xy[2 * lowest + across]) lowest = i;
        if (xy[2 * i + across] >= xy[2 * highest + across]) highest = i;
    }
    if (highest == lowest) highest = (lowest + 1) % 3;
    int middle = 3 - lowest - highest;
    int32_t first = first_line_at(xy[2 * lowest + across]);
    a->turn = first_line_at(xy[2 * middle + across]);
    a->last = first_line_at(xy[2 * highest + across]) - 1;
    /* Edge e runs corner e -> corner e + 1; the one between corners i and j is i when j follows i, else j. */
    int long_edge = (middle + 1) % 3;
    int low_edge = (lowest + 1) % 3 == middle ? lowest : middle;
    int high_edge = (middle + 1) % 3 == highest ? middle : highest;
    int short_now = a->turn <= first ? high_edge : low_edge;
    EdgeStep along_long, short_edge;
    int64_t level = (int64_t)first << FIX_SHIFT;
    edge_at(xy + 2 * long_edge, xy + 2 * ((long_edge + 1) % 3), vertical, level, 0, FIX_ONE, &along_long);
    edge_at(xy + 2 * short_now, xy + 2 * ((short_now + 1) % 3), vertical, level, 0, FIX_ONE, &short_edge);
    if (!(a->turn > first && a->turn <= a->last)) a->turn = -1; /* one short edge serves every line */
    a->xy = xy;
    a->next_edge = (int8_t)high_edge;
    a->next_is_lo = along_long.alpha < 0;
    a->lo = a->next_is_lo ? short_edge : along_long;
    a->hi = a->next_is_lo ? along_long : short_edge;
}

typedef struct { /* a cross-section that starts and ends between the same two grid points (Tally.bucket's gap) */
    double from, to;
    int64_t next; /* 1 + the previous piece in the same gap, 0 for none */
} Piece;

typedef struct { /* per-gap tallies of one line's cross-sections, kept clear between lines */
    int32_t *points;  /* difference array, then count, of cross-sections holding each grid point */
    int32_t *covers;  /* likewise for cross-sections covering each gap whole */
    double *starts;   /* lowest start of a cross-section leaving each gap covered to its right */
    double *ends;     /* highest end of one reaching into each gap from its left */
    int64_t *bucket;  /* per gap, 1 + the last of its pieces (0: none), linked through piece.next */
    Piece *pieces;
    int64_t piece_cap, n_pieces;
    Piece *local;     /* one gap's pieces, sorted */
    int64_t local_cap;
    uint64_t *touched; /* bit per position holding any of the above, so a line costs its spans, not its width */
} Tally;

static int lowest_bit(uint64_t x) /* x != 0 */
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctzll(x);
#else
    int n = 0;
    while (!(x & 1u)) {
        x >>= 1;
        n++;
    }
    return n;
#endif
}

static void touch_pair(Tally *y, int32_t position) /* position and position + 1 */
{
    y->touched[position / 64] |= (uint64_t)3 << (position % 64);
    if (position % 64 == 63) y->touched[position / 64 + 1] |= 1;
}

static int touched(const Tally *y, int32_t position) { return (int)(y->touched[position / 64] >> (position % 64)) & 1; }

static void sort_pieces(Piece *p, int64_t n)
{
    for (int64_t i = 1; i < n; i++) {
        Piece key = p[i];
        int64_t j = i - 1;
        while (j >= 0 && p[j].from > key.from) {
            p[j + 1] = p[j];
            j--;
        }
        p[j + 1] = key;
    }
}

static int tally_span(Tally *y, const Span *s)
{
    int32_t lo = s->gap_lo + 1, hi = s->gap_hi;
    touch_pair(y, s->gap_lo);
    touch_pair(y, hi);
    if (lo <= hi) {
        y->points[lo]++;
        y->points[hi + 1]--;
    }
    if (lo < hi) {
        y->covers[lo]++;
        y->covers[hi]--;
    }
    if (s->gap_lo < s->gap_hi) {
        if (s->pos_lo < y->starts[s->gap_lo]) y->starts[s->gap_lo] = s->pos_lo;
        if (s->pos_hi > y->ends[s->gap_hi]) y->ends[s->gap_hi] = s->pos_hi;
        return SIL_OK;
    }
    int rc = reserve((void **)&y->pieces, &y->piece_cap, y->n_pieces + 1, sizeof(Piece));
    if (rc != SIL_OK) return rc;
    y->pieces[y->n_pieces].from = s->pos_lo;
    y->pieces[y->n_pieces].to = s->pos_hi;
    y->pieces[y->n_pieces].next = y->bucket[s->gap_lo];
    y->bucket[s->gap_lo] = ++y->n_pieces;
    return SIL_OK;
}

/* Turn one line's tallies over gaps gmin..gmax into the union's crossings, in order, and clear them. Only touched
 * positions can hold a crossing (state changes only where a cross-section starts or ends). A gap covered whole has
 * none; otherwise the union inside it is the piece from its left end (up to the highest end), the pieces within it
 * and the piece to its right end (from the lowest start), merged where they touch. */
static int emit_line(Tally *y, int32_t line, int32_t gmin, int32_t gmax, Crossings *c)
{
    const int64_t first_word = gmin / 64, last_word = (gmax + 1) / 64;
    int rc = SIL_OK;
    int32_t points = 0, covers = 0;
    for (int64_t w = first_word; w <= last_word; w++) { /* running counts at the touched positions */
        for (uint64_t bits = y->touched[w]; bits; bits &= bits - 1) {
            int32_t g = (int32_t)(w * 64 + lowest_bit(bits));
            points += y->points[g];
            covers += y->covers[g];
            y->points[g] = points;
            y->covers[g] = covers;
        }
    }
    for (int64_t w = first_word; w <= last_word && rc == SIL_OK; w++) {
        for (uint64_t bits = y->touched[w]; bits && rc == SIL_OK; bits &= bits - 1) {
            int32_t g = (int32_t)(w * 64 + lowest_bit(bits));
            if (g > gmax) break;
            int left = y->points[g] > 0, right = (touched(y, g + 1) ? y->points[g + 1] : y->points[g]) > 0;
            if (y->covers[g] > 0 || (!left && !right && y->bucket[g] == 0)) continue;
            if ((left && !(y->ends[g] >= g)) || (right && !(y->starts[g] <= g + 1))) return SIL_ERR_INTERNAL;
            if (left && right && y->ends[g] >= y->starts[g]) continue; /* covered end to end */
            int64_t kept = 0;
            for (int64_t i = y->bucket[g]; i != 0; i = y->pieces[i - 1].next) {
                if ((rc = reserve((void **)&y->local, &y->local_cap, kept + 1, sizeof(Piece))) != SIL_OK) break;
                y->local[kept++] = y->pieces[i - 1];
            }
            sort_pieces(y->local, kept);
            int open = left, right_used = !right;
            double end = left ? y->ends[g] : 0.0;
            for (int64_t k = 0; rc == SIL_OK;) {
                double from, to;
                if (!right_used && (k == kept || y->starts[g] <= y->local[k].from)) {
                    from = y->starts[g];
                    to = INFINITY;
                    right_used = 1;
                } else if (k < kept) {
                    from = y->local[k].from;
                    to = y->local[k].to;
                    k++;
                } else {
                    break;
                }
                if (open && from <= end) {
                    if (to > end) end = to;
                    continue;
                }
                if (open && (rc = add_crossing(c, line, g, end, 0)) != SIL_OK) break;
                if ((rc = add_crossing(c, line, g, from, 1)) != SIL_OK) break;
                open = 1;
                end = to;
            }
            if (rc == SIL_OK && open && end != INFINITY) rc = add_crossing(c, line, g, end, 0);
        }
    }
    for (int64_t w = first_word; w <= last_word; w++) {
        for (uint64_t bits = y->touched[w]; bits; bits &= bits - 1) {
            int32_t g = (int32_t)(w * 64 + lowest_bit(bits));
            y->points[g] = y->covers[g] = 0;
            y->starts[g] = INFINITY;
            y->ends[g] = -INFINITY;
            y->bucket[g] = 0;
        }
        y->touched[w] = 0;
    }
    y->n_pieces = 0;
    return rc;
}

/* Sweep one family of grid lines: per line, the union of the active triangles' cross-sections. */
static int sweep(const SilTrace *t, int vertical, Crossings *c)
{
    const int across = vertical ? 0 : 1;
    const int32_t n_lines = (vertical ? t->width : t->height) + 1;
    const int32_t n_gaps = vertical ? t->height : t->width;
    int64_t *first_start = zero_array((int64_t)n_lines + 1, sizeof(int64_t));
    int32_t *ordered = alloc_array(6 * t->n_tris, sizeof(int32_t)); /* the corners again, by first line */
    int32_t *first_line = alloc_array(t->n_tris, sizeof(int32_t));
    Active *active = NULL;
    int64_t active_cap = 0, n_active = 0;
    Tally y;
    memset(&y, 0, sizeof y);
    y.points = zero_array((int64_t)n_gaps + 2, sizeof(int32_t));
    y.covers = zero_array((int64_t)n_gaps + 2, sizeof(int32_t));
    y.starts = alloc_array((int64_t)n_gaps + 2, sizeof(double));
    y.ends = alloc_array((int64_t)n_gaps + 2, sizeof(double));
    y.bucket = zero_array((int64_t)n_gaps + 2, sizeof(int64_t));
    y.touched = zero_array(((int64_t)n_gaps + 2) / 64 + 1, sizeof(uint64_t));
    int rc = SIL_OK;
    c->line_start = zero_array((int64_t)n_lines + 1, sizeof(int64_t));
    if (!first_start || !ordered || !first_line || !c->line_start || !y.points || !y.covers || !y.starts || !y.ends ||
        !y.bucket || !y.touched) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int32_t g = 0; g < n_gaps + 2; g++) {
        y.starts[g] = INFINITY;
        y.ends[g] = -INFINITY;
    }
    /* Bucket the triangles by the first line they cross: lines at levels with lowest <= level < highest. */
    for (int64_t k = 0; k < t->n_tris; k++) {
        int32_t cmin, cmax;
        corner_range(t->corners + 6 * k, across, &cmin, &cmax);
        first_line[k] = first_line_at(cmin);
        if (first_line[k] > first_line_at(cmax) - 1) first_line[k] = -1; /* between two lines: crosses none */
        else first_start[first_line[k] + 1]++;
    }
    for (int32_t l = 0; l < n_lines; l++) first_start[l + 1] += first_start[l];
    for (int64_t k = 0; k < t->n_tris; k++) {
        if (first_line[k] < 0) continue;
        memcpy(ordered + 6 * first_start[first_line[k]]++, t->corners + 6 * k, 6 * sizeof(int32_t));
    }
    for (int32_t l = n_lines; l > 0; l--) first_start[l] = first_start[l - 1];
    first_start[0] = 0;

    for (int32_t line = 0; line < n_lines; line++) {
        c->line_start[line] = c->count;
        int64_t add = first_start[line + 1] - first_start[line];
        if ((rc = reserve((void **)&active, &active_cap, n_active + add, sizeof(Active))) != SIL_OK) goto done;
        for (int64_t i = first_start[line]; i < first_start[line + 1]; i++)
            activate(ordered + 6 * i, vertical, active + n_active++);
        int32_t gmin = INT32_MAX, gmax = -1;
        for (int64_t i = 0; i < n_active;) {
            Active *a = active + i;
            if (a->last < line) { /* finished; the order of the others does not matter */
                *a = active[--n_active];
                continue;
            }
            if (line == a->turn) {
                const int32_t *p = a->xy + 2 * a->next_edge, *q = a->xy + 2 * ((a->next_edge + 1) % 3);
                edge_at(p, q, vertical, (int64_t)line << FIX_SHIFT, 0, FIX_ONE, a->next_is_lo ? &a->lo : &a->hi);
            }
            Span span;
            if ((rc = span_between(&a->lo, &a->hi, &span)) != SIL_OK) goto done;
            if (span.gap_lo < 0 || span.gap_hi >= n_gaps) {
                rc = SIL_ERR_INTERNAL;
                goto done;
            }
            if ((rc = tally_span(&y, &span)) != SIL_OK) goto done;
            if (span.gap_lo < gmin) gmin = span.gap_lo;
            if (span.gap_hi > gmax) gmax = span.gap_hi;
            a->lo.beta += a->lo.dbeta;
            a->hi.beta += a->hi.dbeta;
            i++;
        }
        if (gmax >= 0 && (rc = emit_line(&y, line, gmin, gmax, c)) != SIL_OK) goto done;
    }
    c->line_start[n_lines] = c->count;
done:
    free(first_start);
    free(ordered);
    free(first_line);
    free(active);
    free(y.points);
    free(y.covers);
    free(y.starts);
    free(y.ends);
    free(y.bucket);
    free(y.touched);
    free(y.pieces);
    free(y.local);
    return rc;
}

/* ------------------------------------------------------------------------------------------------ chords */

#define REFINE_DEPTH 8      /* an ambiguous cell splits down to 1/256 of a cell before the centroid rule decides */
#define REFINE_BUDGET 256   /* splits one grid cell may spend, whatever the input */

typedef struct { /* a crossing on one side of a (sub)cell */
    int64_t id;
    double pos;    /* along the side, in cells */
    uint8_t start; /* the shape begins here as the coordinate grows */
} Item;

typedef struct { /* a (sub)cell waiting to be paired or split */
    int64_t x0, y0, size;       /* lattice box */
    uint8_t corner[4];          /* inside at bottom-left, bottom-right, top-right, top-left */
    int64_t first[4], count[4]; /* its sides' items in the pool, by growing coordinate: bottom, right, top, left */
    int depth;
} Box;

typedef struct { /* state shared while linking every cell */
    const SilTrace *t;
    int64_t *next, next_cap, n_ids; /* next[id]: the crossing after id along the outline */
    double *extra;                   /* grid positions of crossings made by refinement (ids from first_extra) */
    int64_t extra_cap, first_extra;
    Item *pool;
    int64_t pool_cap, pool_n;
    Box *stack;
    int64_t stack_cap, stack_n, splits;
    Stop *stops;
    int64_t stop_cap;
    Span *spans;
    int64_t span_cap;
    Box *saddles;            /* grid cells with more than two crossings, resolved once every other cell is linked */
    int64_t saddle_cap, n_saddles;
    int64_t *saddle_start;   /* per saddle cell, its triangles: tri_ids[saddle_start[s] .. saddle_start[s + 1]) */
    int32_t *tri_ids;
    const int32_t *near;     /* the triangles of the cell being resolved */
    int64_t n_near;
} Linker;

/* Is snapped point (x, y), in the cell being resolved, covered by the shape? */
static int covered(const Linker *L, int64_t x, int64_t y)
{
    int64_t w[3], area2;
    for (int64_t i = 0; i < L->n_near; i++) {
        if (triangle_hit(L->t, L->near[i], x, y, w, &area2)) return 1;
    }
    return 0;
}

static int push_item(Linker *L, int64_t id, double pos, int start)
{
    int rc = reserve((void **)&L->pool, &L->pool_cap, L->pool_n + 1, sizeof(Item));
    if (rc != SIL_OK) return rc;
    L->pool[L->pool_n].id = id;
    L->pool[L->pool_n].pos = pos;
    L->pool[L->pool_n].start = (uint8_t)start;
    L->pool_n++;
    return SIL_OK;
}

static int new_crossing(Linker *L, double x, double y, int64_t *id)
{
    int64_t k = L->n_ids - L->first_extra;
    int rc = reserve((void **)&L->next, &L->next_cap, L->n_ids + 1, sizeof(int64_t));
    if (rc == SIL_OK) rc = reserve((void **)&L->extra, &L->extra_cap, 2 * (k + 1), sizeof(double));
    if (rc != SIL_OK) return rc;
    L->extra[2 * k] = x;
    L->extra[2 * k + 1] = y;
    L->next[L->n_ids] = -1;
    *id = L->n_ids++;
    return SIL_OK;
}

/* Walk a box's sides counter-clockwise into L->stops: bottom left to right, right side up, top right to left, left
 * side down. A stop enters the shape where the walk goes from outside to inside. Returns the count. */
static int gather_stops(Linker *L, const Box *b, int64_t *n_out)
{
    const double x0 = (double)b->x0 / FIX_ONE, y0 = (double)b->y0 / FIX_ONE;
    const double x1 = (double)(b->x0 + b->size) / FIX_ONE, y1 = (double)(b->y0 + b->size) / FIX_ONE;
    int64_t n = 0, total = b->count[0] + b->count[1] + b->count[2] + b->count[3];
    int rc = reserve((void **)&L->stops, &L->stop_cap, total, sizeof(Stop));
    if (rc != SIL_OK) return rc;
    for (int side = 0; side < 4; side++) {
        int reverse = side >= 2;
        for (int64_t k = 0; k < b->count[side]; k++) {
            const Item *it = L->pool + b->first[side] + (reverse ? b->count[side] - 1 - k : k);
            Stop *s = L->stops + n++;
            s->id = it->id;
            s->enter = reverse ? !it->start : it->start;
            s->side = side;
            s->x = side == 1 ? x1 : (side == 3 ? x0 : it->pos);
            s->y = side == 0 ? y0 : (side == 2 ? y1 : it->pos);
        }
    }
    *n_out = n;
    return SIL_OK;
}

/* Chords from each stop that leaves the shape to an entering one, so the shape lies on the chord's left: to the next
 * stop when the inside arcs join inside the box, else to the previous one (each inside arc cut off on its own). */
static int pair_stops(Linker *L, int64_t n, int join)
{
    for (int64_t k = 0; k < n; k++) {
        if (L->stops[k].enter == L->stops[(k + 1) % n].enter) return SIL_ERR_INTERNAL;
    }
    for (int64_t k = 0; k < n; k++) {
        if (L->stops[k].enter) continue;
        int64_t from = L->stops[k].id, to = L->stops[join ? (k + 1) % n : (k + n - 1) % n].id;
        if (L->next[from] != -1) return SIL_ERR_INTERNAL;
        L->next[from] = to;
    }
    return SIL_OK;
}

/* The crossings of the union with one midline of box b (y = level, or x = level when vertical), sampled at origin,
 * origin + half and origin + 2 * half. Appends the crossings of each half to the pool (count[0], then count[1])
 * and reports whether each of the three samples is inside. */
static int midline(Linker *L, const Box *b, int vertical, uint8_t inside[3], int64_t count[2])
{
    const SilTrace *t = L->t;
    const int across = vertical ? 0 : 1;
    const int64_t half = b->size / 2;
    const int64_t level = (vertical ? b->x0 : b->y0) + half, origin = vertical ? b->y0 : b->x0;
    int64_t n = 0;
    for (int64_t i = 0; i < L->n_near; i++) {
        int64_t k = L->near[i];
        int32_t cmin, cmax;
        corner_range(t->corners + 6 * k, across, &cmin, &cmax);
        if (!(cmin <= level && level < cmax)) continue;
        int rc = reserve((void **)&L->spans, &L->span_cap, n + 1, sizeof(Span));
        if (rc == SIL_OK) rc = cross_section(t, k, level, vertical, origin, half, L->spans + n);
        if (rc != SIL_OK) return rc;
        if (L->spans[n].gap_hi >= 0 && L->spans[n].gap_lo <= 1) n++;
    }
    sort_spans(L->spans, n);
    int64_t runs = merge_spans(L->spans, n);
    inside[0] = inside[1] = inside[2] = 0;
    count[0] = count[1] = 0;
    for (int64_t r = 0; r < runs; r++) {
        const Span *s = L->spans + r;
        for (int m = 0; m < 3; m++) {
            if (s->gap_lo < m && m <= s->gap_hi) inside[m] = 1;
        }
        for (int end = 0; end < 2; end++) {
            int32_t gap = end ? s->gap_hi : s->gap_lo;
            if (gap < 0 || gap > 1) continue;
            double pos = ((double)origin + (end ? s->pos_hi : s->pos_lo) * (double)half) / FIX_ONE;
            double lv = (double)level / FIX_ONE;
            int64_t id;
            int rc = new_crossing(L, vertical ? lv : pos, vertical ? pos : lv, &id);
            if (rc == SIL_OK) rc = push_item(L, id, pos, !end);
            if (rc != SIL_OK) return rc;
            count[gap]++;
        }
    }
    return SIL_OK;
}

/* Where a side's items split at its midpoint: the count before it, made to agree with the exact inside states at the
 * side's start and midpoint (an item within rounding of the midpoint may need to move across it, onto it). */
static int64_t split_side(Item *items, int64_t count, double mid, int start_inside, int mid_inside)
{
    int64_t k = 0;
    while (k < count && items[k].pos < mid) k++;
    if ((k % 2 != 0) != (start_inside != mid_inside)) {
        if (k == count || (k > 0 && mid - items[k - 1].pos < items[k].pos - mid)) k--;
        else k++;
    }
    for (int64_t i = 0; i < count; i++) {
        if (i < k && items[i].pos > mid) items[i].pos = mid;
        if (i >= k && items[i].pos < mid) items[i].pos = mid;
    }
    return k;
}

/* Split box b into four, computing its two midlines exactly, and push the quarters. */
static int split_box(Linker *L, const Box *b)
{
    uint8_t h[3], v[3];
    int64_t h_count[2], v_count[2];
    int64_t h_first = L->pool_n;
    int rc = midline(L, b, 0, h, h_count);
    int64_t v_first = L->pool_n;
    if (rc == SIL_OK) rc = midline(L, b, 1, v, v_count);
    if (rc != SIL_OK) return rc;
    if (h[1] != v[1]) return SIL_ERR_INTERNAL;
    const int64_t half = b->size / 2;
    const double xm = (double)(b->x0 + half) / FIX_ONE, ym = (double)(b->y0 + half) / FIX_ONE;
    const uint8_t *c = b->corner;
    int64_t kb = split_side(L->pool + b->first[0], b->count[0], xm, c[0], v[0]);
    int64_t kr = split_side(L->pool + b->first[1], b->count[1], ym, c[1], h[2]);
    int64_t kt = split_side(L->pool + b->first[2], b->count[2], xm, c[3], v[2]);
    int64_t kl = split_side(L->pool + b->first[3], b->count[3], ym, c[0], h[0]);
    if ((rc = reserve((void **)&L->stack, &L->stack_cap, L->stack_n + 4, sizeof(Box))) != SIL_OK) return rc;
    Box *q = L->stack + L->stack_n;
    L->stack_n += 4;
    const int64_t hs[2] = {h_first, h_first + h_count[0]}, vs[2] = {v_first, v_first + v_count[0]};
    for (int i = 0; i < 4; i++) {
        q[i].size = half;
        q[i].depth = b->depth + 1;
        q[i].x0 = b->x0 + (i == 1 || i == 2 ? half : 0);
        q[i].y0 = b->y0 + (i >= 2 ? half : 0);
    }
    /* 0: bottom-left, 1: bottom-right, 2: top-right, 3: top-left; corners and sides as in Box. */
    const uint8_t corners[4][4] = {
        {c[0], v[0], h[1], h[0]}, {v[0], c[1], h[2], h[1]}, {h[1], h[2], c[2], v[2]}, {h[0], h[1], v[2], c[3]}};
    const int64_t firsts[4][4] = {
        {b->first[0], vs[0], hs[0], b->first[3]},
        {b->first[0] + kb, b->first[1], hs[1], vs[0]},
        {hs[1], b->first[1] + kr, b->first[2] + kt, vs[1]},
        {hs[0], vs[1], b->first[2], b->first[3] + kl}};
    const int64_t counts[4][4] = {
        {kb, v_count[0], h_count[0], kl},
        {b->count[0] - kb, kr, h_count[1], v_count[0]},
        {h_count[1], b->count[1] - kr, b->count[2] - kt, v_count[1]},
        {h_count[0], v_count[1], kt, b->count[3] - kl}};
    for (int i = 0; i < 4; i++) {
        memcpy(q[i].corner, corners[i], sizeof corners[i]);
        memcpy(q[i].first, firsts[i], sizeof firsts[i]);
        memcpy(q[i].count, counts[i], sizeof counts[i]);
    }
    return SIL_OK;
}

/* Would pairing these stops (see pair_stops) run a chord along a side line of box b over another stop? Stops on one
 * side, or clamped onto a corner, are collinear, and of the two pairings only one pairs them as neighbours. */
static int chord_over_stop(const Stop *stops, int64_t n, int join, const Box *b)
{
    const double lines[4] = {(double)b->y0 / FIX_ONE, (double)(b->x0 + b->size) / FIX_ONE,
                             (double)(b->y0 + b->size) / FIX_ONE, (double)b->x0 / FIX_ONE};
    for (int64_t k = 0; k < n; k++) {
        if (stops[k].enter) continue;
        const Stop *p = stops + k, *q = stops + (join ? (k + 1) % n : (k + n - 1) % n);
        for (int side = 0; side < 4; side++) {
            int vertical = side % 2; /* the line is x = const for the right and left sides */
            double level = lines[side];
            if ((vertical ? p->x : p->y) != level || (vertical ? q->x : q->y) != level) continue;
            double lo = vertical ? p->y : p->x, hi = vertical ? q->y : q->x;
            if (lo > hi) {
                double swap = lo;
                lo = hi;
                hi = swap;
            }
            for (int64_t m = 0; m < n; m++) {
                double along = vertical ? stops[m].y : stops[m].x;
                if ((vertical ? stops[m].x : stops[m].y) == level && along > lo && along < hi) return 1;
            }
        }
    }
    return 0;
}

/* How deep a box with these n > 2 stops is worth splitting. Two stops on each of two opposite sides are a strip
 * passing through or two tips, which the centroid tells apart once the box is small enough for the walls to be
 * nearly straight; two on each of two adjacent sides may also bend round the corner; anything else mixes features
 * and splits to the full depth. (Splitting along a hair-thin strip would otherwise double the work at each level.) */
static int split_depth(const Stop *stops, int64_t n)
{
    int count[4] = {0, 0, 0, 0};
    for (int64_t k = 0; k < n; k++) count[stops[k].side]++;
    if (n == 4) {
        for (int side = 0; side < 4; side++) {
            if (count[side] != 2) continue;
            if (count[(side + 2) % 4] == 2) return 2;
            if (count[(side + 1) % 4] == 2 || count[(side + 3) % 4] == 2) return 4;
        }
    }
    return REFINE_DEPTH;
}

/* Link one grid cell whose side items are in the pool. Two crossings pair directly; a saddle is split until its
 * parts are unambiguous, and past the depth or budget limit the centroid of the crossings decides (covered ->
 * join): it lies inside a thin strip or crack linking them and at the centre of a symmetric saddle. */
static int link_cell(Linker *L, Box *root)
{
    int rc = reserve((void **)&L->stack, &L->stack_cap, 1, sizeof(Box));
    if (rc != SIL_OK) return rc;
    L->stack[0] = *root;
    L->stack_n = 1;
    L->splits = 0;
    while (L->stack_n > 0 && rc == SIL_OK) {
        Box b = L->stack[--L->stack_n];
        int64_t n;
        if ((rc = gather_stops(L, &b, &n)) != SIL_OK) break;
        if (n % 2 != 0) rc = SIL_ERR_INTERNAL;
        else if (n <= 2) rc = pair_stops(L, n, 0);
        else if (b.depth < split_depth(L->stops, n) && L->splits < REFINE_BUDGET) {
            if (b.depth == 0) {
                for (int c = 0; c < 4; c++) {
                    int64_t x = b.x0 + (c == 1 || c == 2 ? b.size : 0), y = b.y0 + (c >= 2 ? b.size : 0);
                    b.corner[c] = (uint8_t)covered(L, x, y);
                }
            }
            L->splits++;
            rc = split_box(L, &b);
        } else {
            double cx = 0.0, cy = 0.0;
            for (int64_t k = 0; k < n; k++) {
                cx += L->stops[k].x;
                cy += L->stops[k].y;
            }
            int join = covered(L, (int64_t)nearbyint(cx / n * FIX_ONE), (int64_t)nearbyint(cy / n * FIX_ONE));
            if (chord_over_stop(L->stops, n, join, &b)) join = !join;
            rc = pair_stops(L, n, join);
        }
    }
    return rc;
}

/* For each saddle cell, the triangles whose bounding boxes meet it (closed), in one pass over the triangles that
 * rejects most of them on a map of 16 x 16 cell blocks holding saddles and the rest on a bitmap of saddle cells. */
static int gather_saddle_triangles(Linker *L)
{
    const SilTrace *t = L->t;
    const int32_t block_cols = t->width / 16 + 1;
    uint8_t *blocks = zero_array((int64_t)block_cols * (t->height / 16 + 1), 1);
    uint8_t *marked = zero_array(((int64_t)t->width * t->height + 7) / 8, 1);
    int64_t *keys = alloc_array(L->n_saddles, sizeof(int64_t));
    int64_t *pairs = NULL, pair_cap = 0, n_pairs = 0; /* saddle index, triangle */
    int rc = SIL_OK;
    L->saddle_start = zero_array(L->n_saddles + 1, sizeof(int64_t));
    if (!blocks || !marked || !keys || !L->saddle_start) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t i = 0; i < L->n_saddles; i++) { /* saddles arrive row by row, so the keys are sorted */
        int64_t cx = L->saddles[i].x0 >> FIX_SHIFT, cy = L->saddles[i].y0 >> FIX_SHIFT;
        keys[i] = cy * t->width + cx;
        marked[keys[i] / 8] |= (uint8_t)(1u << (keys[i] % 8));
        blocks[(cy / 16) * block_cols + cx / 16] = 1;
    }
    for (int64_t k = 0; k < t->n_tris; k++) {
        int32_t x0, x1, y0, y1;
        corner_range(t->corners + 6 * k, 0, &x0, &x1);
        corner_range(t->corners + 6 * k, 1, &y0, &y1);
        /* closed cells [c, c + 1] meeting [lo, hi] in lattice units: ceil(lo) - 1 <= c <= floor(hi) */
        int32_t cx0 = (x0 - 1) >> FIX_SHIFT, cx1 = x1 >> FIX_SHIFT, cy0 = (y0 - 1) >> FIX_SHIFT, cy1 = y1 >> FIX_SHIFT;
        int any = 0;
        for (int32_t by = cy0 / 16; by <= cy1 / 16; by++) {
            for (int32_t bx = cx0 / 16; bx <= cx1 / 16; bx++) any |= blocks[by * block_cols + bx];
        }
        for (int32_t cy = cy0; any && cy <= cy1; cy++) {
            for (int32_t cx = cx0; cx <= cx1; cx++) {
                int64_t key = (int64_t)cy * t->width + cx, lo = 0, hi = L->n_saddles;
                if (!(marked[key / 8] & (1u << (key % 8)))) continue;
                while (lo < hi) {
                    int64_t mid = (lo + hi) / 2;
                    if (keys[mid] < key) lo = mid + 1;
                    else hi = mid;
                }
                if ((rc = reserve((void **)&pairs, &pair_cap, 2 * (n_pairs + 1), sizeof(int64_t))) != SIL_OK) goto done;
                pairs[2 * n_pairs] = lo;
                pairs[2 * n_pairs + 1] = k;
                n_pairs++;
                L->saddle_start[lo + 1]++;
            }
        }
    }
    for (int64_t i = 0; i < L->n_saddles; i++) L->saddle_start[i + 1] += L->saddle_start[i];
    L->tri_ids = alloc_array(n_pairs, sizeof(int32_t));
    if (!L->tri_ids) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t i = 0; i < n_pairs; i++) L->tri_ids[L->saddle_start[pairs[2 * i]]++] = (int32_t)pairs[2 * i + 1];
    for (int64_t i = L->n_saddles; i > 0; i--) L->saddle_start[i] = L->saddle_start[i - 1];
    L->saddle_start[0] = 0;
done:
    free(blocks);
    free(marked);
    free(keys);
    free(pairs);
    return rc;
}

/* Link every cell: next[] gets, for each crossing id (horizontal crossings, then vertical ones, then those made by
 * refinement), the crossing after it along the outline. */
static int link_cells(Linker *L, const Crossings *h, const Crossings *v)
{
    const SilTrace *t = L->t;
    const int64_t n_h = h->count;
    int64_t *row_start = zero_array((int64_t)t->height + 2, sizeof(int64_t));
    int64_t *row_ids = alloc_array(v->count, sizeof(int64_t));
    int rc = SIL_OK;
    if (!row_start || !row_ids) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t k = 0; k < v->count; k++) row_start[v->gap[k] + 1]++;
    for (int32_t j = 0; j <= t->height; j++) row_start[j + 1] += row_start[j];
    for (int64_t k = 0; k < v->count; k++) row_ids[row_start[v->gap[k]]++] = k;
    for (int32_t j = t->height; j > 0; j--) row_start[j] = row_start[j - 1];
    row_start[0] = 0;

    for (int32_t j = 0; j < t->height; j++) {
        int64_t bp = h->line_start[j], be = h->line_start[j + 1];
        int64_t tp = h->line_start[j + 1], te = h->line_start[j + 2];
        int64_t vp = row_start[j], ve = row_start[j + 1];
        int64_t done_cell = -1;
        for (;;) {
            int64_t cell = INT64_MAX;
            if (bp < be) cell = h->gap[bp];
            if (tp < te && h->gap[tp] < cell) cell = h->gap[tp];
            if (vp < ve) {
                int64_t l = v->line[row_ids[vp]];
                int64_t candidate = l - 1 > done_cell ? l - 1 : l;
                if (candidate < cell) cell = candidate;
            }
            if (cell == INT64_MAX) break;
            Box box;
            memset(&box, 0, sizeof box);
            box.x0 = cell << FIX_SHIFT;
            box.y0 = (int64_t)j << FIX_SHIFT;
            box.size = FIX_ONE;
            box.first[0] = L->pool_n;
            for (; bp < be && h->gap[bp] == cell && rc == SIL_OK; bp++)
                rc = push_item(L, bp, h->pos[bp], h->is_start[bp]);
            int64_t l1 = vp;
            while (l1 < ve && v->line[row_ids[l1]] == cell) l1++;
            box.first[1] = L->pool_n;
            for (; l1 < ve && v->line[row_ids[l1]] == cell + 1 && rc == SIL_OK; l1++) {
                int64_t k = row_ids[l1];
                rc = push_item(L, n_h + k, v->pos[k], v->is_start[k]);
            }
            box.first[2] = L->pool_n;
            for (; tp < te && h->gap[tp] == cell && rc == SIL_OK; tp++)
                rc = push_item(L, tp, h->pos[tp], h->is_start[tp]);
            box.first[3] = L->pool_n;
            for (; vp < ve && v->line[row_ids[vp]] == cell && rc == SIL_OK; vp++) {
                int64_t k = row_ids[vp];
                rc = push_item(L, n_h + k, v->pos[k], v->is_start[k]);
            }
            if (rc != SIL_OK) goto done;
            box.count[0] = box.first[1] - box.first[0];
            box.count[1] = box.first[2] - box.first[1];
            box.count[2] = box.first[3] - box.first[2];
            box.count[3] = L->pool_n - box.first[3];
            done_cell = cell;
            if (L->pool_n - box.first[0] <= 2) {
                int64_t n;
                if ((rc = gather_stops(L, &box, &n)) != SIL_OK || (rc = pair_stops(L, n, 0)) != SIL_OK) goto done;
                L->pool_n = box.first[0];
            } else {
                if ((rc = reserve((void **)&L->saddles, &L->saddle_cap, L->n_saddles + 1, sizeof(Box))) != SIL_OK)
                    goto done;
                L->saddles[L->n_saddles++] = box;
            }
        }
    }
    if (L->n_saddles > 0 && (rc = gather_saddle_triangles(L)) == SIL_OK) {
        for (int64_t i = 0; i < L->n_saddles && rc == SIL_OK; i++) {
            L->near = L->tri_ids + L->saddle_start[i];
            L->n_near = L->saddle_start[i + 1] - L->saddle_start[i];
            rc = link_cell(L, &L->saddles[i]);
        }
    }
done:
    free(row_start);
    free(row_ids);
    return rc;
}

/* ------------------------------------------------------------------------------------------------ loops */

typedef struct {
    int64_t n_loops, loop_cap, n_points, point_cap;
    int64_t *start; /* n_loops + 1 */
    double *xy;     /* grid units */
} Loops;

static void free_loops(Loops *l)
{
    free(l->start);
    free(l->xy);
}

static double signed_area(const double *xy, int64_t n)
{
    double area = 0.0, x0 = xy[0], y0 = xy[1];
    for (int64_t i = 1; i + 1 < n; i++) {
        area += (xy[2 * i] - x0) * (xy[2 * i + 3] - y0) - (xy[2 * i + 2] - x0) * (xy[2 * i + 1] - y0);
    }
    return 0.5 * area;
}

/* A loop too small to keep: fewer than three points or less than SPECK of area (finite grid points, so no NaN). */
static int is_speck(const double *xy, int64_t count)
{
    return count < 3 || fabs(signed_area(xy, count)) < SPECK;
}

/* Follow next[] into closed loops, dropping repeated points and loops without area (specks thinner than a line). */
static int collect_loops(const Crossings *h, const Crossings *v, const Linker *L, Loops *out)
{
    const int64_t n_h = h->count, n = L->n_ids, *next = L->next;
    uint8_t *seen = zero_array(n, 1);
    int64_t *incoming = zero_array(n, sizeof(int64_t));
    int rc = SIL_OK;
    memset(out, 0, sizeof *out);
    if (!seen || !incoming) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t i = 0; i < n; i++) {
        if (next[i] < 0 || next[i] >= n || incoming[next[i]]++ != 0) {
            rc = SIL_ERR_INTERNAL;
            goto done;
        }
    }
    if ((rc = reserve((void **)&out->start, &out->loop_cap, 1, sizeof(int64_t))) != SIL_OK) goto done;
    out->start[0] = 0;
    for (int64_t s = 0; s < n; s++) {
        if (seen[s]) continue;
        int64_t begin = out->n_points, i = s;
        do {
            seen[i] = 1;
            double x, y;
            if (i < n_h) {
                x = h->pos[i];
                y = h->line[i];
            } else if (i < L->first_extra) {
                x = v->line[i - n_h];
                y = v->pos[i - n_h];
            } else {
                x = L->extra[2 * (i - L->first_extra)];
                y = L->extra[2 * (i - L->first_extra) + 1];
            }
            int64_t m = out->n_points;
            if (m == begin || out->xy[2 * m - 2] != x || out->xy[2 * m - 1] != y) {
                if ((rc = reserve((void **)&out->xy, &out->point_cap, 2 * (m + 1), sizeof(double))) != SIL_OK)
                    goto done;
                out->xy[2 * m] = x;
                out->xy[2 * m + 1] = y;
                out->n_points++;
            }
            i = next[i];
        } while (i != s);
        int64_t count = out->n_points - begin;
        while (count > 1 && out->xy[2 * begin] == out->xy[2 * (begin + count - 1)] &&
               out->xy[2 * begin + 1] == out->xy[2 * (begin + count - 1) + 1])
            count--;
        if (is_speck(out->xy + 2 * begin, count)) {
            out->n_points = begin;
            continue;
        }
        out->n_points = begin + count;
        if ((rc = reserve((void **)&out->start, &out->loop_cap, out->n_loops + 2, sizeof(int64_t))) != SIL_OK)
            goto done;
        out->start[++out->n_loops] = out->n_points;
    }
done:
    free(seen);
    free(incoming);
    if (rc != SIL_OK) free_loops(out);
    return rc;
}

typedef struct { /* a loop point with its index, sortable by position */
    double x, y;
    int64_t index;
} Placed;

static int compare_placed(const void *a, const void *b)
{
    const Placed *p = a, *q = b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    return p->index < q->index ? -1 : (p->index > q->index);
}

typedef struct { /* one of the edges leaving or reaching a point that several visits share */
    double angle;
    int64_t visit; /* the loop point of that visit */
    int out;       /* 1: the edge leaving the visit, 0: the edge arriving at it */
} Ray;

static int compare_rays(const void *a, const void *b)
{
    const Ray *p = a, *q = b;
    if (p->angle != q->angle) return p->angle < q->angle ? -1 : 1;
    return p->out - q->out;
}

/* Where parts of the shape touch at a single point, outlines pass through it several times. Around such a point the
 * edges alternate leaving / arriving, and counter-clockwise from each leaving edge to the next arriving one lies one
 * part. Re-link every arrival to the departure that opens its own part, then move each visit a hair into that part,
 * so the loops become strictly simple (loops may split or merge on the way). A point whose edges do not alternate
 * (overlapping edges) stays as it is. Rebuilds `loops`. */
static int separate_touches(Loops *loops)
{
    const int64_t n = loops->n_points;
    const double turn = 8.0 * atan(1.0);
    Placed *order = alloc_array(n, sizeof(Placed));
    int64_t *prev = alloc_array(n, sizeof(int64_t)), *next = alloc_array(n, sizeof(int64_t));
    int64_t *adopt = NULL, adopt_cap = 0; /* per visit of the current point: the successor it takes */
    int64_t *start = NULL, n_loops = 0, loop_cap = 0;
    double *moved = alloc_array(2 * n, sizeof(double)), *xy = alloc_array(2 * n, sizeof(double));
    uint8_t *seen = zero_array(n, 1);
    Ray *rays = NULL;
    int64_t ray_cap = 0;
    int rc = SIL_OK;
    if (!order || !prev || !next || !moved || !xy || !seen) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t l = 0; l < loops->n_loops; l++) {
        int64_t first = loops->start[l], last = loops->start[l + 1] - 1;
        for (int64_t i = first; i <= last; i++) {
            prev[i] = i == first ? last : i - 1;
            next[i] = i == last ? first : i + 1;
        }
    }
    for (int64_t i = 0; i < n; i++) order[i] = (Placed){loops->xy[2 * i], loops->xy[2 * i + 1], i};
    qsort(order, (size_t)n, sizeof(Placed), compare_placed);
    memcpy(moved, loops->xy, (size_t)(2 * n) * sizeof(double));
    for (int64_t a = 0, b; a < n; a = b) {
        const double p[2] = {order[a].x, order[a].y};
        for (b = a + 1; b < n && order[b].x == p[0] && order[b].y == p[1];) b++;
        const int64_t k = b - a, m = 2 * k;
        if (k < 2) continue;
        if ((rc = reserve((void **)&rays, &ray_cap, m, sizeof(Ray))) != SIL_OK) goto done;
        if ((rc = reserve((void **)&adopt, &adopt_cap, k, sizeof(int64_t))) != SIL_OK) goto done;
        for (int64_t i = 0; i < k; i++) {
            int64_t v = order[a + i].index;
            const double *to = loops->xy + 2 * next[v], *from = loops->xy + 2 * prev[v];
            rays[2 * i] = (Ray){atan2(to[1] - p[1], to[0] - p[0]), v, 1};
            rays[2 * i + 1] = (Ray){atan2(from[1] - p[1], from[0] - p[0]), v, 0};
        }
        qsort(rays, (size_t)m, sizeof(Ray), compare_rays);
        int64_t shift = rays[0].out ? 0 : 1; /* walk from a leaving edge */
        int alternate = 1;
        for (int64_t r = 0; r < m; r++) {
            const Ray *ray = rays + (r + shift) % m, *after = rays + (r + shift + 1) % m;
            if (ray->out == after->out || ray->angle == after->angle) alternate = 0;
        }
        if (!alternate) continue;
        for (int64_t r = 0; r < m; r += 2) {
            const Ray *leave = rays + (r + shift) % m, *arrive = rays + (r + shift + 1) % m;
            double span = arrive->angle - leave->angle;
            if (span <= 0.0) span += turn;
            double middle = leave->angle + 0.5 * span;
            moved[2 * arrive->visit] = p[0] + TOUCH_NUDGE * cos(middle);
            moved[2 * arrive->visit + 1] = p[1] + TOUCH_NUDGE * sin(middle);
            adopt[r / 2] = next[leave->visit];
        }
        for (int64_t r = 0; r < m; r += 2) {
            int64_t v = rays[(r + shift + 1) % m].visit;
            next[v] = adopt[r / 2];
            prev[adopt[r / 2]] = v;
        }
    }
    if ((rc = reserve((void **)&start, &loop_cap, 1, sizeof(int64_t))) != SIL_OK) goto done;
    start[0] = 0;
    for (int64_t s = 0, m = 0; s < n; s++) {
        if (seen[s]) continue;
        for (int64_t i = s; !seen[i]; i = next[i]) {
            seen[i] = 1;
            xy[2 * m] = moved[2 * i];
            xy[2 * m + 1] = moved[2 * i + 1];
            m++;
        }
        if ((rc = reserve((void **)&start, &loop_cap, n_loops + 2, sizeof(int64_t))) != SIL_OK) goto done;
        start[++n_loops] = m;
    }
    free(loops->xy);
    free(loops->start);
    loops->xy = xy;
    loops->start = start;
    loops->n_loops = n_loops;
    loops->loop_cap = loop_cap;
    loops->point_cap = 2 * n;
    xy = NULL;
    start = NULL;
done:
    free(order);
    free(prev);
    free(next);
    free(adopt);
    free(moved);
    free(xy);
    free(seen);
    free(rays);
    free(start);
    return rc;
}

/* Drop the speck loops, keeping the others in order. */
static void drop_specks(Loops *loops)
{
    int64_t kept = 0, m = 0;
    for (int64_t l = 0, first = 0; l < loops->n_loops; l++) {
        int64_t end = loops->start[l + 1], count = end - first; /* start[l + 1] is not rewritten yet */
        if (!is_speck(loops->xy + 2 * first, count)) {
            memmove(loops->xy + 2 * m, loops->xy + 2 * first, (size_t)(2 * count) * sizeof(double));
            m += count;
            loops->start[++kept] = m;
        }
        first = end;
    }
    loops->n_loops = kept;
    loops->n_points = m;
}

/* ------------------------------------------------------------------------------------------------ simplification */

typedef struct { /* alive points of all loops, bucketed by coarse grid cell, to prove a removal triangle empty */
    int32_t block, cols, rows;
    int64_t *start;
    int64_t *ids;
} PointIndex;

typedef struct {
    const double *xy;
    int64_t *prev, *next, *loop;
    int64_t *alive_in_loop;
    uint8_t *alive;
    double *drift;  /* per alive point: how far the traced outline may lie from its segment to next[] */
    double *cost;
    int64_t *heap, *slot, heap_n;
    PointIndex index;
} Simplifier;

static double segment_distance(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    double s = len2 > 0.0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
    s = clampd(s, 0.0, 1.0);
    double ex = ax + s * dx - px, ey = ay + s * dy - py;
    return sqrt(ex * ex + ey * ey);
}

/* A bound on how far the traced outline would lie from the simplified one if point i went: the bounds of its two
 * segments plus its distance from the new segment prev(i)-next(i) (the old pair of segments lies within that distance
 * of the new one). Infinite when the new segment would be longer than SIMPLIFY_LENGTH. */
static double removal_cost(const Simplifier *s, int64_t i)
{
    int64_t a = s->prev[i], b = s->next[i];
    double ax = s->xy[2 * a], ay = s->xy[2 * a + 1], bx = s->xy[2 * b], by = s->xy[2 * b + 1];
    if ((bx - ax) * (bx - ax) + (by - ay) * (by - ay) > SIMPLIFY_LENGTH * SIMPLIFY_LENGTH) return INFINITY;
    double drift = s->drift[a] > s->drift[i] ? s->drift[a] : s->drift[i];
    return drift + segment_distance(s->xy[2 * i], s->xy[2 * i + 1], ax, ay, bx, by);
}

static int heap_less(const Simplifier *s, int64_t a, int64_t b)
{
    return s->cost[a] < s->cost[b] || (s->cost[a] == s->cost[b] && a < b);
}

static void heap_swap(Simplifier *s, int64_t i, int64_t j)
{
    int64_t a = s->heap[i], b = s->heap[j];
    s->heap[i] = b;
    s->heap[j] = a;
    s->slot[b] = i;
    s->slot[a] = j;
}

static void heap_fix(Simplifier *s, int64_t pos)
{
    while (pos > 0 && heap_less(s, s->heap[pos], s->heap[(pos - 1) / 2])) {
        heap_swap(s, pos, (pos - 1) / 2);
        pos = (pos - 1) / 2;
    }
    for (;;) {
        int64_t best = pos, l = 2 * pos + 1, r = l + 1;
        if (l < s->heap_n && heap_less(s, s->heap[l], s->heap[best])) best = l;
        if (r < s->heap_n && heap_less(s, s->heap[r], s->heap[best])) best = r;
        if (best == pos) break;
        heap_swap(s, pos, best);
        pos = best;
    }
}

/* Could removing point i create a crossing? Only if some other alive point lies in (or within a hair of) the
 * triangle prev(i), i, next(i): a segment crossing the new edge without crossing the old ones must end inside it. */
static int removal_blocked(const Simplifier *s, int64_t i)
{
    const PointIndex *ix = &s->index;
    int64_t a = s->prev[i], b = s->next[i];
    double p[3][2] = {{s->xy[2 * a], s->xy[2 * a + 1]},
                      {s->xy[2 * i], s->xy[2 * i + 1]},
                      {s->xy[2 * b], s->xy[2 * b + 1]}};
    const double hair = 1e-9;
    double x0 = p[0][0], x1 = x0, y0 = p[0][1], y1 = y0;
    for (int c = 1; c < 3; c++) {
        if (p[c][0] < x0) x0 = p[c][0];
        if (p[c][0] > x1) x1 = p[c][0];
        if (p[c][1] < y0) y0 = p[c][1];
        if (p[c][1] > y1) y1 = p[c][1];
    }
    double orient = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    int32_t cx0 = (int32_t)clampd(floor((x0 - hair) / ix->block), 0, ix->cols - 1);
    int32_t cx1 = (int32_t)clampd(floor((x1 + hair) / ix->block), 0, ix->cols - 1);
    int32_t cy0 = (int32_t)clampd(floor((y0 - hair) / ix->block), 0, ix->rows - 1);
    int32_t cy1 = (int32_t)clampd(floor((y1 + hair) / ix->block), 0, ix->rows - 1);
    for (int32_t cy = cy0; cy <= cy1; cy++) {
        for (int32_t cx = cx0; cx <= cx1; cx++) {
            int64_t bin = (int64_t)cy * ix->cols + cx;
            for (int64_t k = ix->start[bin]; k < ix->start[bin + 1]; k++) {
                int64_t q = ix->ids[k];
                if (!s->alive[q] || q == a || q == i || q == b) continue;
                double qx = s->xy[2 * q], qy = s->xy[2 * q + 1];
                if (qx < x0 - hair || qx > x1 + hair || qy < y0 - hair || qy > y1 + hair) continue;
                int inside = orient != 0.0;
                for (int e = 0; e < 3 && inside; e++) {
                    const double *u = p[e], *w = p[(e + 1) % 3];
                    double side = (w[0] - u[0]) * (qy - u[1]) - (w[1] - u[1]) * (qx - u[0]);
                    inside = orient > 0 ? side > 0 : side < 0;
                }
                if (inside) return 1;
                for (int e = 0; e < 3; e++) {
                    const double *u = p[e], *w = p[(e + 1) % 3];
                    if (segment_distance(qx, qy, u[0], u[1], w[0], w[1]) <= hair) return 1;
                }
            }
        }
    }
    return 0;
}

static int build_point_index(PointIndex *ix, const double *xy, int64_t n, int32_t width, int32_t height)
{
    int32_t longest = width > height ? width : height;
    ix->block = longest / 1024 > 8 ? longest / 1024 : 8;
    ix->cols = width / ix->block + 1;
    ix->rows = height / ix->block + 1;
    int64_t n_bins = (int64_t)ix->cols * ix->rows;
    ix->start = zero_array(n_bins + 1, sizeof(int64_t));
    ix->ids = alloc_array(n, sizeof(int64_t));
    if (!ix->start || !ix->ids) return SIL_ERR_NOMEM;
    for (int64_t i = 0; i < n; i++) {
        int64_t cx = (int64_t)clampd(floor(xy[2 * i] / ix->block), 0, ix->cols - 1);
        int64_t cy = (int64_t)clampd(floor(xy[2 * i + 1] / ix->block), 0, ix->rows - 1);
        ix->start[cy * ix->cols + cx + 1]++;
    }
    for (int64_t b = 0; b < n_bins; b++) ix->start[b + 1] += ix->start[b];
    for (int64_t i = 0; i < n; i++) {
        int64_t cx = (int64_t)clampd(floor(xy[2 * i] / ix->block), 0, ix->cols - 1);
        int64_t cy = (int64_t)clampd(floor(xy[2 * i + 1] / ix->block), 0, ix->rows - 1);
        ix->ids[ix->start[cy * ix->cols + cx]++] = i;
    }
    for (int64_t b = n_bins; b > 0; b--) ix->start[b] = ix->start[b - 1];
    ix->start[0] = 0;
    return SIL_OK;
}

/* Remove points, cheapest first, while the outline moves at most `tolerance` cells and no loop can cross another or
 * itself; loops keep at least four points. Writes the surviving points back into `loops`. */
static int simplify(Loops *loops, double tolerance, int32_t width, int32_t height)
{
    const int64_t n = loops->n_points;
    Simplifier s;
    memset(&s, 0, sizeof s);
    s.xy = loops->xy;
    s.prev = alloc_array(n, sizeof(int64_t));
    s.next = alloc_array(n, sizeof(int64_t));
    s.loop = alloc_array(n, sizeof(int64_t));
    s.alive_in_loop = alloc_array(loops->n_loops, sizeof(int64_t));
    s.alive = alloc_array(n, 1);
    s.cost = alloc_array(n, sizeof(double));
    s.drift = zero_array(n, sizeof(double));
    s.heap = alloc_array(n, sizeof(int64_t));
    s.slot = alloc_array(n, sizeof(int64_t));
    double *kept = NULL;
    int rc = SIL_OK;
    if (!s.prev || !s.next || !s.loop || !s.alive_in_loop || !s.alive || !s.drift || !s.cost || !s.heap || !s.slot) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    if ((rc = build_point_index(&s.index, loops->xy, n, width, height)) != SIL_OK) goto done;
    for (int64_t l = 0; l < loops->n_loops; l++) {
        int64_t first = loops->start[l], last = loops->start[l + 1] - 1;
        s.alive_in_loop[l] = last - first + 1;
        for (int64_t i = first; i <= last; i++) {
            s.prev[i] = i == first ? last : i - 1;
            s.next[i] = i == last ? first : i + 1;
            s.loop[i] = l;
            s.alive[i] = 1;
        }
    }
    for (int64_t i = 0; i < n; i++) {
        s.cost[i] = removal_cost(&s, i);
        s.heap[i] = i;
        s.slot[i] = i;
    }
    s.heap_n = n;
    for (int64_t i = n / 2; i >= 0 && n > 0; i--) heap_fix(&s, i);
    while (s.heap_n > 0) {
        int64_t i = s.heap[0];
        if (!(s.cost[i] <= tolerance)) break;
        if (s.alive_in_loop[s.loop[i]] <= 4 || removal_blocked(&s, i)) {
            s.cost[i] = INFINITY; /* retried if a neighbour goes */
            heap_fix(&s, 0);
            continue;
        }
        s.alive[i] = 0;
        s.alive_in_loop[s.loop[i]]--;
        heap_swap(&s, 0, --s.heap_n);
        heap_fix(&s, 0);
        int64_t a = s.prev[i], b = s.next[i];
        s.drift[a] = s.cost[i];
        s.next[a] = b;
        s.prev[b] = a;
        s.cost[a] = removal_cost(&s, a);
        heap_fix(&s, s.slot[a]);
        s.cost[b] = removal_cost(&s, b);
        heap_fix(&s, s.slot[b]);
    }
    kept = alloc_array(2 * n, sizeof(double));
    if (!kept) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    int64_t m = 0;
    for (int64_t l = 0; l < loops->n_loops; l++) {
        int64_t first = loops->start[l];
        loops->start[l] = m;
        for (int64_t i = first; i < loops->start[l + 1]; i++) {
            if (!s.alive[i]) continue;
            kept[2 * m] = loops->xy[2 * i];
            kept[2 * m + 1] = loops->xy[2 * i + 1];
            m++;
        }
    }
    loops->start[loops->n_loops] = m;
    loops->n_points = m;
    free(loops->xy);
    loops->xy = kept;
    kept = NULL;
done:
    free(s.prev);
    free(s.next);
    free(s.loop);
    free(s.alive_in_loop);
    free(s.alive);
    free(s.drift);
    free(s.cost);
    free(s.heap);
    free(s.slot);
    free(s.index.start);
    free(s.index.ids);
    free(kept);
    return rc;
}

/* ------------------------------------------------------------------------------------------------ trace */

static int trace_outline(SilTrace *t, double tolerance)
{
    Crossings h, v;
    Loops loops;
    Linker L;
    memset(&h, 0, sizeof h);
    memset(&v, 0, sizeof v);
    memset(&loops, 0, sizeof loops);
    memset(&L, 0, sizeof L);
    L.t = t;
    int rc = sweep(t, 0, &h);
    if (rc == SIL_OK) rc = sweep(t, 1, &v);
    if (rc == SIL_OK) {
        L.n_ids = L.first_extra = h.count + v.count;
        rc = reserve((void **)&L.next, &L.next_cap, L.n_ids, sizeof(int64_t));
    }
    if (rc == SIL_OK) {
        for (int64_t i = 0; i < L.n_ids; i++) L.next[i] = -1;
        rc = link_cells(&L, &h, &v);
    }
    if (rc == SIL_OK) rc = collect_loops(&h, &v, &L, &loops);
    free(L.next);
    free(L.extra);
    free(L.pool);
    free(L.stack);
    free(L.stops);
    free(L.spans);
    free(L.saddles);
    free(L.saddle_start);
    free(L.tri_ids);
    free_crossings(&h);
    free_crossings(&v);
    if (rc == SIL_OK && loops.n_loops > 0 && (rc = separate_touches(&loops)) == SIL_OK) drop_specks(&loops);
    if (rc == SIL_OK && tolerance > 0.0 && loops.n_loops > 0) rc = simplify(&loops, tolerance, t->width, t->height);
    if (rc != SIL_OK) {
        free_loops(&loops);
        return rc;
    }
    for (int64_t i = 0; i < loops.n_points; i++) {
        loops.xy[2 * i] = t->corner[0] + loops.xy[2 * i] * t->cell;
        loops.xy[2 * i + 1] = t->corner[1] + loops.xy[2 * i + 1] * t->cell;
    }
    if (loops.n_loops == 0) { /* the loop arrays may never have been allocated */
        free_loops(&loops);
        loops.start = zero_array(1, sizeof(int64_t));
        loops.xy = zero_array(1, sizeof(double));
        if (!loops.start || !loops.xy) {
            free_loops(&loops);
            return SIL_ERR_NOMEM;
        }
    }
    t->n_loops = loops.n_loops;
    t->loop_start = loops.start;
    t->loop_xy = loops.xy;
    return SIL_OK;
}

int sil_trace(const double *vertices, int64_t n_vertices, const int32_t *triangles, int64_t n_triangles,
              const double direction[3], int32_t resolution, double tolerance, SilTrace **out)
{
    *out = NULL;
    if (resolution < SIL_MIN_RESOLUTION || resolution > SIL_MAX_RESOLUTION) return SIL_ERR_RESOLUTION;
    if (!(tolerance >= 0.0 && tolerance <= 1.0)) return SIL_ERR_TOLERANCE;
    if (n_vertices <= 0 || n_triangles <= 0) return SIL_ERR_EMPTY;
    if (n_vertices > INT32_MAX || n_triangles > INT32_MAX) return SIL_ERR_TOO_LARGE;
    SilTrace *t = calloc(1, sizeof *t);
    if (!t) return SIL_ERR_NOMEM;
    t->n_vertices = n_vertices;
    t->n_all = n_triangles;
    int rc = make_frame(t, direction);
    if (rc == SIL_OK) rc = project(t, vertices);
    if (rc == SIL_OK) {
        t->all_tris = alloc_array(3 * n_triangles, sizeof(int32_t));
        if (!t->all_tris) rc = SIL_ERR_NOMEM;
        for (int64_t i = 0; rc == SIL_OK && i < 3 * n_triangles; i++) {
            if (triangles[i] < 0 || triangles[i] >= n_vertices) rc = SIL_ERR_INDEX;
            else t->all_tris[i] = triangles[i];
        }
    }
    if (rc == SIL_OK) rc = snap(t, resolution);
    if (rc == SIL_OK) rc = trace_outline(t, tolerance);
    if (rc != SIL_OK) {
        sil_free(t);
        return rc;
    }
    *out = t;
    return SIL_OK;
}

void sil_frame(const SilTrace *t, double origin[3], double u[3], double v[3], double direction[3])
{
    memcpy(origin, t->origin, sizeof t->origin);
    memcpy(u, t->u, sizeof t->u);
    memcpy(v, t->v, sizeof t->v);
    memcpy(direction, t->dir, sizeof t->dir);
}

void sil_grid(const SilTrace *t, double corner[2], double *cell, int32_t *width, int32_t *height)
{
    corner[0] = t->corner[0];
    corner[1] = t->corner[1];
    *cell = t->cell;
    *width = t->width;
    *height = t->height;
}

int64_t sil_loop_count(const SilTrace *t) { return t->n_loops; }
const int64_t *sil_loop_offsets(const SilTrace *t) { return t->loop_start; }
const double *sil_loop_points(const SilTrace *t) { return t->loop_xy; }

/* ------------------------------------------------------------------------------------------------ ray queries */

/* Snap a frame point to the lattice; 0 when it is off the grid (or NaN), where no triangle can be hit. */
static int snap_point(const SilTrace *t, double x, double y, int64_t *fx, int64_t *fy)
{
    double gx = (x - t->corner[0]) / t->cell, gy = (y - t->corner[1]) / t->cell;
    if (!(gx >= 0.0 && gx <= t->width && gy >= 0.0 && gy <= t->height)) return 0;
    *fx = (int64_t)nearbyint(gx * FIX_ONE);
    *fy = (int64_t)nearbyint(gy * FIX_ONE);
    return 1;
}

/* The depth of triangle k (already hit by the exact test) under frame point (x, y), interpolated on the unsnapped
 * geometry; the weights are clamped to the triangle, and the snapped ones serve a triangle too thin for doubles. */
static double hit_depth(const SilTrace *t, int64_t k, double x, double y, const int64_t w[3], int64_t area2)
{
    const int32_t *tri = t->tris + 3 * k;
    const double *p[3] = {t->proj + 3 * tri[0], t->proj + 3 * tri[1], t->proj + 3 * tri[2]};
    double weight[3], total = 0.0;
    for (int c = 0; c < 3; c++) {
        const double *a = p[(c + 1) % 3], *b = p[(c + 2) % 3];
        double side = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
        weight[c] = side > 0.0 ? side : 0.0;
        total += weight[c];
    }
    if (!(total > 0.0)) {
        for (int c = 0; c < 3; c++) weight[c] = (double)w[c];
        total = (double)area2;
    }
    return (weight[0] * p[0][2] + weight[1] * p[1][2] + weight[2] * p[2][2]) / total;
}

int sil_depth(SilTrace *t, const double *points, int64_t n, double *front, double *back)
{
    int rc = build_bins(t);
    if (rc != SIL_OK) return rc;
    for (int64_t p = 0; p < n; p++) {
        double lo = NAN, hi = NAN;
        int64_t x = 0, y = 0, first, last, w[3], area2;
        if (snap_point(t, points[2 * p], points[2 * p + 1], &x, &y)) {
            bin_of(t, x, y, &first, &last);
            for (int64_t i = first; i < last; i++) {
                int64_t k = t->bins->tri[i];
                if (!triangle_hit(t, k, x, y, w, &area2)) continue;
                double z = hit_depth(t, k, points[2 * p], points[2 * p + 1], w, area2);
                if (!(z >= lo)) lo = z;
                if (!(z <= hi)) hi = z;
            }
        }
        front[p] = lo;
        back[p] = hi;
    }
    return SIL_OK;
}

static int32_t find_root(int32_t *parent, int32_t r)
{
    while (parent[r] != r) {
        parent[r] = parent[parent[r]];
        r = parent[r];
    }
    return r;
}

static void join_roots(int32_t *parent, int32_t a, int32_t b) /* roots point to the lower index */
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
}

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    return h;
}

/* Weld vertices at identical positions and join them along triangles: *weld_out maps each vertex to its welded
 * vertex (the lowest index at its position), *parent_out each welded vertex to its part's lowest welded vertex. */
static int weld_parts(const double *pos, int64_t n, const int32_t *tris, int64_t m, int32_t **weld_out,
                      int32_t **parent_out)
{
    *weld_out = *parent_out = NULL;
    int64_t table_size = 1;
    while (table_size < 2 * n) table_size *= 2;
    int32_t *table = alloc_array(table_size, sizeof(int32_t));
    int32_t *weld = alloc_array(n, sizeof(int32_t));
    int32_t *parent = alloc_array(n, sizeof(int32_t));
    if (!table || !weld || !parent) {
        free(table);
        free(weld);
        free(parent);
        return SIL_ERR_NOMEM;
    }
    for (int64_t i = 0; i < table_size; i++) table[i] = -1;
    for (int64_t i = 0; i < n; i++) {
        const double *p = pos + 3 * i;
        uint64_t h = 1469598103934665603ull;
        for (int c = 0; c < 3; c++) {
            double value = p[c] + 0.0; /* -0.0 and 0.0 weld */
            uint64_t bits;
            memcpy(&bits, &value, sizeof bits);
            h = (h ^ bits) * 1099511628211ull;
            h ^= h >> 29;
        }
        int64_t slot = (int64_t)(h & (uint64_t)(table_size - 1));
        for (;;) {
            int32_t other = table[slot];
            if (other < 0) {
                table[slot] = (int32_t)i;
                weld[i] = (int32_t)i;
                break;
            }
            const double *q = pos + 3 * other;
            if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) {
                weld[i] = other;
                break;
            }
            slot = (slot + 1) & (table_size - 1);
        }
        parent[i] = (int32_t)i;
    }
    free(table);
    for (int64_t k = 0; k < m; k++) {
        join_roots(parent, weld[tris[3 * k]], weld[tris[3 * k + 1]]);
        join_roots(parent, weld[tris[3 * k]], weld[tris[3 * k + 2]]);
    }
    for (int64_t i = 0; i < n; i++) { /* parents point to lower indices, so one forward pass resolves every root */
        parent[i] = parent[parent[i]];
    }
    *weld_out = weld;
    *parent_out = parent;
    return SIL_OK;
}

/* Mark the welded vertices on an open boundary: those of an edge that one triangle alone uses. Edges are keyed
 * (low, high) welded vertex; bit 62 of a table entry records a second use. */
static int mark_boundary(int64_t n, const int32_t *tris, int64_t m, const int32_t *weld, uint8_t *boundary)
{
    int64_t table_size = 1;
    while (table_size < 4 * m) table_size *= 2;
    int64_t *table = alloc_array(table_size, sizeof(int64_t));
    if (!table) return SIL_ERR_NOMEM;
    const int64_t empty = -1, twice = (int64_t)1 << 62;
    for (int64_t i = 0; i < table_size; i++) table[i] = empty;
    for (int64_t k = 0; k < m; k++) {
        for (int c = 0; c < 3; c++) {
            int64_t a = weld[tris[3 * k + c]], b = weld[tris[3 * k + (c + 1) % 3]];
            if (a == b) continue;
            int64_t key = a < b ? a * n + b : b * n + a;
            int64_t slot = (int64_t)(mix64((uint64_t)key) & (uint64_t)(table_size - 1));
            while (table[slot] != empty && (table[slot] & ~twice) != key) slot = (slot + 1) & (table_size - 1);
            table[slot] = table[slot] == empty ? key : key | twice;
        }
    }
    for (int64_t slot = 0; slot < table_size; slot++) {
        if (table[slot] == empty || (table[slot] & twice)) continue;
        boundary[table[slot] / n] = 1;
        boundary[table[slot] % n] = 1;
    }
    free(table);
    return SIL_OK;
}

#define SEAM_CANDIDATES 1024 /* most boundary vertices one is compared with: bounds the cost where thousands crowd
                                * into a few cells (a degenerate soup), far beyond any seam's density */

/* Join into clusters (in ``cluster``, lowest index the root) the boundary vertices of different parts that lie within
 * ``gap`` of each other, bucketing them on a grid of that spacing. */
static int cluster_seams(const double *pos, int64_t n, const uint8_t *boundary, const int32_t *part, double gap,
                         int32_t *cluster)
{
    int64_t count = 0, buckets = 1;
    double lo[3] = {INFINITY, INFINITY, INFINITY};
    for (int64_t i = 0; i < n; i++) {
        if (!boundary[i]) continue;
        count++;
        for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], pos[3 * i + c]);
    }
    while (buckets < 2 * count) buckets *= 2;
    int32_t *head = alloc_array(buckets, sizeof(int32_t)), *next = alloc_array(n, sizeof(int32_t));
    int64_t *cell = alloc_array(3 * n, sizeof(int64_t));
    if (!head || !next || !cell) {
        free(head);
        free(next);
        free(cell);
        return SIL_ERR_NOMEM;
    }
    for (int64_t b = 0; b < buckets; b++) head[b] = -1;
    for (int64_t i = 0; i < n; i++) {
        if (!boundary[i]) continue;
        uint64_t h = 0;
        for (int c = 0; c < 3; c++) {
            cell[3 * i + c] = (int64_t)floor((pos[3 * i + c] - lo[c]) / gap);
            h = mix64(h ^ (uint64_t)cell[3 * i + c]);
        }
        next[i] = head[h & (uint64_t)(buckets - 1)];
        head[h & (uint64_t)(buckets - 1)] = (int32_t)i;
    }
    for (int64_t i = 0; i < n; i++) {
        if (!boundary[i]) continue;
        const double *p = pos + 3 * i;
        int64_t budget = SEAM_CANDIDATES;
        for (int d = 0; d < 27 && budget > 0; d++) { /* the 3 x 3 x 3 cells around i's */
            const int offset[3] = {d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1};
            uint64_t h = 0;
            for (int c = 0; c < 3; c++) h = mix64(h ^ (uint64_t)(cell[3 * i + c] + offset[c]));
            for (int32_t j = head[h & (uint64_t)(buckets - 1)]; j >= 0 && budget-- > 0; j = next[j]) {
                const double *q = pos + 3 * j;
                double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
                if (part[i] != part[j] && dx * dx + dy * dy + dz * dz <= gap * gap)
                    join_roots(cluster, (int32_t)i, j);
            }
        }
    }
    free(head);
    free(next);
    free(cell);
    return SIL_OK;
}

/* Whether the triangles join all the vertices they use into one part without welding (most meshes: then nothing is
 * split along seams, and the hash of welding is not needed). */
static int one_piece(int64_t n, const int32_t *tris, int64_t m, int *rc)
{
    int32_t *parent = alloc_array(n, sizeof(int32_t));
    if (!parent) {
        *rc = SIL_ERR_NOMEM;
        return 0;
    }
    for (int64_t i = 0; i < n; i++) parent[i] = (int32_t)i;
    for (int64_t k = 0; k < m; k++) {
        join_roots(parent, tris[3 * k], tris[3 * k + 1]);
        join_roots(parent, tris[3 * k], tris[3 * k + 2]);
    }
    int32_t root = find_root(parent, tris[0]);
    int one = 1;
    for (int64_t k = 0; k < 3 * m && one; k++) one = find_root(parent, tris[k]) == root;
    free(parent);
    return one;
}

int sil_seal(const double *vertices, int64_t n, const int32_t *tris, int64_t m, double *out, int64_t *moved)
{
    *moved = 0;
    memcpy(out, vertices, (size_t)(3 * n) * sizeof(double));
    int32_t *weld = NULL, *part = NULL, *cluster = NULL;
    double *box = NULL;
    uint8_t *boundary = NULL;
    int rc = SIL_OK;
    if (m == 0 || one_piece(n, tris, m, &rc)) return rc;
    if ((rc = weld_parts(vertices, n, tris, m, &weld, &part)) != SIL_OK) goto done;
    int several = 0; /* parts after welding */
    for (int64_t k = 1; k < 3 * m && !several; k++) several = part[weld[tris[k]]] != part[weld[tris[0]]];
    if (!several) goto done;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, extent = 0.0;
    for (int64_t k = 0; k < 3 * m; k++) {
        const double *p = vertices + 3 * (int64_t)tris[k];
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], p[c]);
            hi[c] = fmax(hi[c], p[c]);
        }
    }
    for (int c = 0; c < 3; c++) extent = fmax(extent, hi[c] - lo[c]);
    boundary = calloc((size_t)n, 1);
    cluster = alloc_array(n, sizeof(int32_t));
    if (!boundary || !cluster) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    if ((rc = mark_boundary(n, tris, m, weld, boundary)) != SIL_OK) goto done;
    for (int64_t i = 0; i < n; i++) cluster[i] = (int32_t)i;
    if (!(extent > 0.0)) goto done;
    if ((rc = cluster_seams(vertices, n, boundary, part, SIL_SEAM_GAP * extent, cluster)) != SIL_OK) goto done;
    box = alloc_array(6 * n, sizeof(double)); /* per cluster root: the low and high corners of its members' box */
    if (!box) {
        rc = SIL_ERR_NOMEM;
        goto done;
    }
    for (int64_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            box[6 * i + c] = INFINITY;
            box[6 * i + 3 + c] = -INFINITY;
        }
    for (int64_t i = 0; i < n; i++) {
        double *corners = box + 6 * (int64_t)find_root(cluster, weld[i]);
        for (int c = 0; c < 3; c++) {
            corners[c] = fmin(corners[c], vertices[3 * i + c]);
            corners[3 + c] = fmax(corners[3 + c], vertices[3 * i + c]);
        }
    }
    for (int64_t i = 0; i < n; i++) {
        const double *corners = box + 6 * (int64_t)find_root(cluster, weld[i]);
        int same = 1;
        for (int c = 0; c < 3; c++) {
            out[3 * i + c] = 0.5 * (corners[c] + corners[3 + c]);
            same = same && out[3 * i + c] == vertices[3 * i + c];
        }
        if (!same) (*moved)++;
    }
done:
    free(weld);
    free(part);
    free(boundary);
    free(cluster);
    free(box);
    return rc;
}

/* Connected components of the welded mesh (vertices at identical positions merged, as glTF and game exports split
 * them along seams): hits pair up within one component, so nested or overlapping parts do not mix their layers. */
static int build_components(SilTrace *t)
{
    if (t->vertex_comp) return SIL_OK;
    int32_t *weld = NULL, *parent = NULL;
    int rc = weld_parts(t->proj, t->n_vertices, t->all_tris, t->n_all, &weld, &parent);
    if (rc != SIL_OK) return rc;
    for (int64_t i = 0; i < t->n_vertices; i++) weld[i] = parent[weld[i]];
    t->vertex_comp = weld;
    free(parent);
    return SIL_OK;
}

int sil_share_components(SilTrace *t, SilTrace *source)
{
    if (t == source) return build_components(t); /* its own parts: found once, kept */
    if (t->n_vertices != source->n_vertices || t->n_all != source->n_all ||
        memcmp(t->all_tris, source->all_tris, (size_t)(3 * t->n_all) * sizeof(int32_t)) != 0)
        return SIL_ERR_MISMATCH;
    if (t->vertex_comp) return SIL_OK;
    int rc = build_components(source);
    if (rc != SIL_OK) return rc;
    t->vertex_comp = alloc_array(t->n_vertices, sizeof(int32_t));
    if (!t->vertex_comp) return SIL_ERR_NOMEM;
    memcpy(t->vertex_comp, source->vertex_comp, (size_t)t->n_vertices * sizeof(int32_t));
    return SIL_OK;
}

static void sort_hits(Hit *h, int64_t n)
{
    for (int64_t i = 1; i < n; i++) {
        Hit key = h[i];
        int64_t j = i - 1;
        while (j >= 0 && (h[j].comp > key.comp || (h[j].comp == key.comp && h[j].depth > key.depth))) {
            h[j + 1] = h[j];
            j--;
        }
        h[j + 1] = key;
    }
}

static void sort_intervals(double *iv, int64_t n)
{
    for (int64_t i = 1; i < n; i++) {
        double a = iv[2 * i], b = iv[2 * i + 1];
        int64_t j = i - 1;
        while (j >= 0 && iv[2 * j] > a) {
            iv[2 * j + 2] = iv[2 * j];
            iv[2 * j + 3] = iv[2 * j + 1];
            j--;
        }
        iv[2 * j + 2] = a;
        iv[2 * j + 3] = b;
    }
}

/* Whether one component's n sorted hits nest by winding: facing as its nearest hit does enters the component,
 * facing the other way leaves it, and the count of entries less exits never drops below zero and ends at zero (a
 * closed, consistently wound surface, or several such overlapping; either winding, as its nearest hit sets it). */
static int winding_nests(const Hit *h, int64_t n)
{
    int64_t depth = 0;
    for (int64_t i = 0; i < n; i++) {
        depth += h[i].facing == h[0].facing ? 1 : -1;
        if (depth < 0) return 0;
    }
    return depth == 0;
}

/* Pair one component's sorted hits into inside intervals. Hits that nest by winding (winding_nests) give the
 * stretches where the winding is positive, so pieces of one part that overlap stay solid where they overlap; other
 * even counts pair by parity; an odd count (only on open components) leaves alone the one hit whose removal gives the
 * thinnest pairing, as a zero-thickness layer. */
static int pair_hits(const Hit *h, int64_t n, double **iv, int64_t *cap, int64_t *count)
{
    int64_t single = -1;
    if (n % 2 != 0) {
        double front = 0.0, rest = 0.0, best = INFINITY;
        for (int64_t i = 1; i + 1 < n; i += 2) rest += h[i + 1].depth - h[i].depth;
        for (int64_t k = 0; k < n; k += 2) {
            if (front + rest < best) {
                best = front + rest;
                single = k;
            }
            if (k + 2 < n) {
                front += h[k + 1].depth - h[k].depth;
                rest -= h[k + 2].depth - h[k + 1].depth;
            }
        }
    }
    if (n % 2 == 0 && n > 2 && winding_nests(h, n)) {
        int64_t depth = 0;
        for (int64_t i = 0; i < n; i++) {
            int64_t before = depth;
            depth += h[i].facing == h[0].facing ? 1 : -1;
            if (before == 0) {
                int rc = reserve((void **)iv, cap, 2 * (*count + 1), sizeof(double));
                if (rc != SIL_OK) return rc;
                (*iv)[2 * *count] = h[i].depth;
            } else if (depth == 0) {
                (*iv)[2 * (*count)++ + 1] = h[i].depth;
            }
        }
        return SIL_OK;
    }
    for (int64_t i = 0; i < n;) {
        int rc = reserve((void **)iv, cap, 2 * (*count + 1), sizeof(double));
        if (rc != SIL_OK) return rc;
        if (i == single) {
            (*iv)[2 * *count] = (*iv)[2 * *count + 1] = h[i].depth;
            i += 1;
        } else {
            (*iv)[2 * *count] = h[i].depth;
            (*iv)[2 * *count + 1] = h[i + 1].depth;
            i += 2;
        }
        (*count)++;
    }
    return SIL_OK;
}

int sil_layers(SilTrace *t, const double *points, int64_t n, int64_t **offsets_out, double **intervals_out)
{
    *offsets_out = NULL;
    *intervals_out = NULL;
    int rc = build_bins(t);
    if (rc == SIL_OK) rc = build_components(t);
    if (rc != SIL_OK) return rc;
    int64_t *offsets = alloc_array(n + 1, sizeof(int64_t));
    double *out = NULL, *local = NULL;
    int64_t out_cap = 0, n_out = 0, local_cap = 0;
    Hit *hits = NULL;
    int64_t hit_cap = 0;
    if (!offsets) return SIL_ERR_NOMEM;
    offsets[0] = 0;
    for (int64_t p = 0; p < n; p++) {
        int64_t x = 0, y = 0, first = 0, last = 0, w[3], area2, n_hits = 0, n_local = 0;
        if (snap_point(t, points[2 * p], points[2 * p + 1], &x, &y)) bin_of(t, x, y, &first, &last);
        for (int64_t i = first; i < last; i++) {
            int64_t k = t->bins->tri[i];
            if (!triangle_hit(t, k, x, y, w, &area2)) continue;
            if ((rc = reserve((void **)&hits, &hit_cap, n_hits + 1, sizeof(Hit))) != SIL_OK) goto fail;
            hits[n_hits].depth = hit_depth(t, k, points[2 * p], points[2 * p + 1], w, area2);
            hits[n_hits].comp = t->vertex_comp[t->tris[3 * k]];
            hits[n_hits].facing = t->facing[k];
            n_hits++;
        }
        sort_hits(hits, n_hits);
        for (int64_t i = 0; i < n_hits;) {
            int64_t j = i;
            while (j < n_hits && hits[j].comp == hits[i].comp) j++;
            if ((rc = pair_hits(hits + i, j - i, &local, &local_cap, &n_local)) != SIL_OK) goto fail;
            i = j;
        }
        sort_intervals(local, n_local);
        for (int64_t i = 0; i < n_local; i++) { /* union over components */
            double a = local[2 * i], b = local[2 * i + 1];
            if (n_out > offsets[p] && a <= out[2 * n_out - 1]) {
                if (b > out[2 * n_out - 1]) out[2 * n_out - 1] = b;
                continue;
            }
            if ((rc = reserve((void **)&out, &out_cap, 2 * (n_out + 1), sizeof(double))) != SIL_OK) goto fail;
            out[2 * n_out] = a;
            out[2 * n_out + 1] = b;
            n_out++;
        }
        offsets[p + 1] = n_out;
    }
    if (!out && !(out = alloc_array(1, sizeof(double)))) {
        rc = SIL_ERR_NOMEM;
        goto fail;
    }
    free(hits);
    free(local);
    *offsets_out = offsets;
    *intervals_out = out;
    return SIL_OK;
fail:
    free(hits);
    free(local);
    free(offsets);
    free(out);
    return rc;
}
