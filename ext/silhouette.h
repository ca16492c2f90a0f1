/* The 3D silhouette: the outline of a triangle soup projected along a view direction, plus ray depths.
 *
 * The projected triangles are snapped to a fixed-point lattice (2^16 steps per grid cell) so that every inside/outside
 * decision is exact integer arithmetic, symbolically perturbed so that no grid point ever lies on a triangle edge.
 * Along every horizontal and vertical grid line the union of the triangles' cross-sections is computed exactly; the
 * outline runs through those crossing points, joined inside each cell by straight chords (marching squares whose
 * corners and crossings come from one exact predicate, so the loops close and never cross by construction).
 * Everything is iterative, all buffers grow on the heap, and every error path frees what it allocated.
 */
#ifndef RIGGER_SILHOUETTE_H
#define RIGGER_SILHOUETTE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    SIL_OK = 0,
    SIL_ERR_NOMEM,
    SIL_ERR_EMPTY,
    SIL_ERR_TOO_LARGE,
    SIL_ERR_NONFINITE,
    SIL_ERR_INDEX,
    SIL_ERR_DIRECTION,
    SIL_ERR_ZERO_AREA,
    SIL_ERR_RESOLUTION,
    SIL_ERR_TOLERANCE,
    SIL_ERR_MISMATCH,
    SIL_ERR_INTERNAL
};

/* Grid resolution limits (cells along the longest side of the projected bounding box). */
#define SIL_MIN_RESOLUTION 8
#define SIL_MAX_RESOLUTION 16000

typedef struct SilTrace SilTrace;

/* A human-readable message for an error code. */
const char *sil_error_message(int code);

/* Trace the silhouette of `n_triangles` triangles (vertex index triples) over `n_vertices` xyz vertices seen along
 * `direction`. `resolution`: grid cells along the longest projected side. `tolerance`: how far, in cells (0..1),
 * simplification may move the outline. On success *out owns everything; free it with sil_free. */
int sil_trace(const double *vertices, int64_t n_vertices, const int32_t *triangles, int64_t n_triangles,
              const double direction[3], int32_t resolution, double tolerance, SilTrace **out);
void sil_free(SilTrace *trace);

/* The 2D frame: a 3D point is origin + x*u + y*v + depth*direction. */
void sil_frame(const SilTrace *trace, double origin[3], double u[3], double v[3], double direction[3]);
/* The grid: frame coordinates of grid point (0, 0), the cell size, and the cell counts. */
void sil_grid(const SilTrace *trace, double corner[2], double *cell, int32_t *width, int32_t *height);

/* Loops: loop k holds points offsets[k] .. offsets[k+1]-1 of the interleaved xy array. Outer boundaries are
 * counter-clockwise, holes clockwise; the closing point is not repeated. */
int64_t sil_loop_count(const SilTrace *trace);
const int64_t *sil_loop_offsets(const SilTrace *trace);
const double *sil_loop_points(const SilTrace *trace);

/* For n frame points (interleaved xy): nearest and farthest depth of the mesh along the ray, NaN on a miss. */
int sil_depth(SilTrace *trace, const double *points, int64_t n, double *front, double *back);

/* For n frame points: the depth intervals where each ray is inside the mesh. On success *offsets (n+1 entries) and
 * *intervals (2 per interval: entry, exit) are malloc'ed; release both with sil_release. */
int sil_layers(SilTrace *trace, const double *points, int64_t n, int64_t **offsets, double **intervals);
void sil_release(void *memory);

/* Give `trace` the welded connected components `source` has found (finding them now if it has not): they belong to
 * the mesh, not the view (welded as `source` sees its vertices, exactly equal there), so the views of one mesh find
 * them once. Both must trace the same vertices and triangles (SIL_ERR_MISMATCH when the vertex counts or the
 * triangles differ). A trace that has its components keeps them. */
int sil_share_components(SilTrace *trace, SilTrace *source);

/* The seam gap, as a fraction of the mesh's largest extent: open parts whose boundaries come this close abut. */
#define SIL_SEAM_GAP 1e-3

/* Close the seams of a mesh built of pieces that abut without sharing vertices: copy the n vertices to `out` (3n
 * doubles), then move every boundary vertex (of an edge one triangle alone uses) that lies within SIL_SEAM_GAP of a
 * boundary vertex of another part (parts: connected through triangles, vertices at identical positions welded), and
 * the vertices welded to it, onto the middle of its cluster's bounding box (however the vertices are numbered, and
 * mirror-image seams onto mirror-image points). *moved counts the vertices moved. */
int sil_seal(const double *vertices, int64_t n, const int32_t *triangles, int64_t m, double *out, int64_t *moved);

#ifdef __cplusplus
}
#endif

#endif
