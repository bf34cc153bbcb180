/* The crack graph of a rendered raster: crack centre lines, junctions and ends, and fragment adjacency. */
#ifndef FS_RENDER_CRACKGRAPH_H
#define FS_RENDER_CRACKGRAPH_H

#include <stdbool.h>
#include <stdint.h>

#include "render/render.h"

typedef struct {
    float crack_threshold;   /* crack coverage at or above which a pixel is crack (as the crack
                              * distance map counts it) */
    int32_t min_island;      /* islands of material smaller than this (pixels) are specks inside a
                              * crack, not fragments: the graph treats them as crack */
    double simplify;         /* Douglas-Peucker tolerance of the centre lines (pixels) */
    double spur_ratio;       /* a branch from a junction to a free end is skeleton noise, not a crack,
                              * when shorter than spur_ratio crack half-widths at the junction */
    double min_spur;         /* ... or shorter than this many pixels */
    int32_t min_contact;     /* fragments are adjacent when they face each other across a crack
                              * along at least this many pixels */
} fs_crackgraph_params;

/* threshold 0.5, min_island 8 px, simplify 0.75 px, spur_ratio 2.5, min_spur 3 px, min_contact 2 px. */
fs_crackgraph_params fs_crackgraph_params_default(void);

typedef enum {
    FS_CRACK_JUNCTION = 0, /* three or more crack branches meet */
    FS_CRACK_END = 1,      /* a crack tip inside the map */
    FS_CRACK_BORDER = 2    /* a crack runs out of a non-wrapping border of the map */
} fs_crack_node_kind;

typedef struct {
    double uv[2];            /* texture coordinates, in [0, 1) on wrapping axes, [0, 1] otherwise */
    int32_t degree;          /* crack branch ends meeting here (a loop through the node counts twice) */
    fs_crack_node_kind kind;
} fs_crack_node;

/* One crack branch between two nodes, or a closed crack with no node. Its centre line is stored as
 * pieces that each lie in [0, 1]^2: on a wrapping axis the line is cut where it crosses the seam, a
 * piece ending at u = 1 (v = 0) continuing as the next piece from u = 0 (v = 1) at the same v (u). */
typedef struct {
    int32_t node[2];         /* start and end node, -1 for a closed crack */
    int32_t first_piece, n_pieces; /* into fs_crackgraph.piece_start */
    double length;           /* centre line length in pixels (before simplification) */
    double width;            /* mean crack width across the centre line in pixels */
    uint16_t left, right;    /* fragment on each side, looking along the line with v up (0 = none) */
} fs_crack_edge;

typedef struct {
    uint16_t id;             /* the fragment id of the cell-id raster */
    int64_t area;            /* pixels */
    double centroid[2];      /* mean texture position (circular mean on wrapping axes) */
} fs_crack_fragment;

typedef struct {
    uint16_t a, b;           /* fragment ids, a < b */
    int32_t contact;         /* pixels along which they face each other across a crack */
} fs_crack_adjacency;

typedef struct {
    int width, height;       /* raster size the graph was traced at */
    bool wrap_u, wrap_v;
    int32_t n_nodes;
    fs_crack_node *node;
    int32_t n_edges;
    fs_crack_edge *edge;
    int32_t n_pieces;
    int32_t *piece_start;    /* n_pieces + 1 offsets into point */
    double *point;           /* 2 * piece_start[n_pieces] texture coordinates */
    int32_t n_fragments;
    fs_crack_fragment *fragment; /* by increasing id */
    int32_t n_adjacent;
    fs_crack_adjacency *adjacent; /* by increasing (a, b) */
} fs_crackgraph;

/* design: the crack pixels are those of coverage >= threshold, plus a one-pixel line where two
 * fragment ids touch (a crack thinner than a pixel), plus material islands smaller than
 * min_island. They are thinned to a one-pixel 8-connected skeleton by sequential deletion of
 * simple points in alternating directional passes (a pixel goes only when the skeleton keeps its
 * topology, and free ends are kept; thesis-independent, standard digital topology), wrapping on
 * periodic axes; at
 * non-wrapping borders the mask is first extended outwards so that cracks reaching a border keep
 * their centre line up to it. Skeleton pixels with three or more neighbours, joined into clusters,
 * are junctions; one-neighbour pixels are ends. The skeleton is traced into branches between them,
 * short junction-to-end spurs are pruned, and lines are simplified by Douglas-Peucker. Fragments
 * are grown into the cracks by breadth-first search from the cell-id raster; two fragments are
 * adjacent where their grown regions meet inside a crack, and a branch's left and right fragments
 * are the grown regions on its two sides. Deterministic: no randomness, fixed scan orders.
 *
 * Works on any model's raster. Cost about linear in the pixels (about 0.3 s for a 1024 x 1024
 * voronoi tile). Builds the graph of raster r (crack coverage and cell ids). Returns 0 with out
 * owned by the caller (fs_crackgraph_free), or -1 with fs_error (the distance transform failed). */
int fs_crackgraph_build(const fs_raster *r, bool wrap_u, bool wrap_v, const fs_crackgraph_params *p,
                        fs_crackgraph *out);
void fs_crackgraph_free(fs_crackgraph *g);

#endif
