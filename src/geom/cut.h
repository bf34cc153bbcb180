/* The mesh surgery of a crack in a triangle mesh: new nodes, split edges, duplicated nodes, and the record of what changed, for any triangle model. */
#ifndef FS_GEOM_CUT_H
#define FS_GEOM_CUT_H

#include <stdint.h>

#include "geom/mesh.h"

/* design: a crack in a triangle mesh (thesis §5.7.3, Algorithm 10) is made of three operations on
 * the mesh, in place: a new node on an edge, splitting that edge and the triangle on either side of
 * it (fs_cut_split_edge, so the mesh stays conforming), and the duplication of a node whose fan the
 * crack disconnects into one copy per connected sector (fs_cut_duplicate_node), so that crack walls
 * are boundary edges and fragments separate because they share no node. Periodic planes and
 * cylinders keep working: a corner set on a node carries the image offset from the unwrapped
 * position the caller gives (fs_cut_set_corner); on the sphere positions are already on it.
 *
 * One fs_cut records a sequence of operations (one fracture event) the way a model needs to bring
 * itself up to date: the nodes appended from n_nodes_before on, each with its two parents and the
 * weight of the second (a point a + w (b - a) of edge ab; a copy of node v has parents (v, v) and
 * weight 0); the triangles appended from n_tris_before on, each with the pre-cut triangle it was
 * cut from; the pre-cut triangles whose corners, shifts or geometry changed. What it does not know
 * is the model: which triangles still count around a node (a model may have removed some) and how
 * to find them fast; the model passes that lookup as a callback (fs_cut_tris_fn).
 *
 * Usage: fs_cut_begin, the operations, fs_cut_update_adjacency whenever the next operation walks the
 * mesh (it reads m->adj), then the model reads the record, and fs_cut_free. The derived arrays of the
 * mesh (edges, rings) are not maintained: drop or rebuild them afterwards. */

struct fs_cut;

/* The triangles having node as a corner in the mesh as the cut has changed it so far, ascending,
 * into *out (capacity *cap, grown with FS_ARRAY_RESERVE of base/array.h as needed); returns how
 * many. Every triangle whose corners the cut rewrote is in cut->changed_list or new (from
 * cut->n_tris_before), so a model's own node-to-triangle lists, taken from before the cut, plus
 * those give the answer. */
typedef int32_t (*fs_cut_tris_fn)(void *ctx, const struct fs_cut *cut, int32_t node, int32_t **out, int32_t *cap);

typedef struct fs_cut {
    fs_mesh *mesh;               /* borrowed: the mesh being cut */
    int32_t n_nodes_before;      /* nodes and triangles when the cut began */
    int32_t n_tris_before;

    int32_t *node_parent;        /* 2 per new node */
    double *node_weight;         /* 1 per new node */
    int32_t cap_nodes;
    int32_t *tri_parent;         /* 1 per new triangle: the pre-cut triangle it descends from */
    int32_t cap_tris;
    uint8_t *changed;            /* per pre-cut triangle: 1 if its corners, shifts or geometry changed */
    int32_t *changed_list;       /* those triangles, in the order they were first marked */
    int32_t n_changed, cap_changed;
    int32_t n_tris_adj;          /* triangles the adjacency was last brought up to date for */

    fs_cut_tris_fn tris_at;      /* the model's lookup, NULL: a scan of every triangle */
    void *tris_ctx;
} fs_cut;

/* Starts recording a cut of m (with adjacency). tris_at and ctx: the model's lookup (see
 * fs_cut_tris_fn), or NULL for a scan of the whole mesh per lookup. */
void fs_cut_begin(fs_cut *c, fs_mesh *m, fs_cut_tris_fn tris_at, void *ctx);

/* Releases the record (not the mesh) and zeroes c. */
void fs_cut_free(fs_cut *c);

/* Appends a node at pos (domain coordinates, wrapped) as the point of edge ab with weight w on b
 * (a copy of node v: a = b = v, w = 0). pos may point into m->pos. Returns its index. */
int32_t fs_cut_new_node(fs_cut *c, const double pos[3], int32_t a, int32_t b, double w);

/* Appends a copy of triangle parent (corners and shifts) and records its pre-cut ancestor. Its
 * adjacency is made by the next fs_cut_update_adjacency. Returns its index. */
int32_t fs_cut_new_tri(fs_cut *c, int32_t parent);

/* Records that pre-cut triangle t changed (repeats and new triangles are ignored). */
void fs_cut_mark_changed(fs_cut *c, int32_t t);

/* Sets corner k of triangle t to node, whose unwrapped position in t's frame is p (its image
 * offset, on a periodic plane or cylinder, is taken from p against the node's position). */
void fs_cut_set_corner(fs_mesh *m, int32_t t, int k, int32_t node, const double p[3]);

/* Renormalises the shifts of triangle t so that its first corner has shift (0, 0). */
void fs_cut_normalize_shifts(fs_mesh *m, int32_t t);

/* The triangles at node now (see fs_cut_tris_fn), ascending, into *out (capacity *cap, grown as
 * needed); returns how many. */
int32_t fs_cut_tris_at(const fs_cut *c, int32_t node, int32_t **out, int32_t *cap);

/* Brings m->adj up to the changes so far (fs_mesh_update_adjacency on the changed and the new
 * triangles). Returns 0, or -1 with fs_error(FS_ERR_DATA) for a non-manifold edge. */
int fs_cut_update_adjacency(fs_cut *c);

/* Splits edge ia (corners ia and ia + 1) of triangle t at a + s (b - a), 0 < s < 1, taken in t's
 * unwrapped frame, and the neighbour across it (m->adj must be current), appending the new node
 * (parents a, b, weight s) and one triangle per side: t keeps (.., a, p, ..) and the new one gets
 * (.., p, b, ..) in t's corner order, and likewise the neighbour. Both are marked changed. Returns the
 * new node. */
int32_t fs_cut_split_edge(fs_cut *c, int32_t t, int ia, double s);

/* Splits node v into one copy per connected sector of its fan once the edges (v, cut[k]) no longer
 * join their two triangles: triangles of the fan stay joined across their edges at v that are
 * shared (m->adj current) and not cut. The sector of the fan's first triangle keeps v; each other
 * gets a new node at v's position (parents (v, v), weight 0), and its triangles are marked changed.
 * Returns the number of sectors (1: v stays whole, nothing changed). */
int32_t fs_cut_duplicate_node(fs_cut *c, int32_t v, const int32_t *cut, int32_t n_cut);

/* The changed pre-cut triangles ascending, in a new array of c->n_changed entries (at least one
 * allocated) the caller frees. */
int32_t *fs_cut_changed_ascending(const fs_cut *c);

#endif
