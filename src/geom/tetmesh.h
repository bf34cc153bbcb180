/* Tetrahedral meshes of a layer: nodes, tetrahedra with periodic image shifts, node lists, faces, checks, and the layered Delaunay mesher. */
#ifndef FS_GEOM_TETMESH_H
#define FS_GEOM_TETMESH_H

#include <stdbool.h>
#include <stdint.h>

#include "geom/domain.h"
#include "geom/sample.h"

/* design: node positions are material coordinates in cm:
 *   plane, cylinder  (x, y, z): the unrolled layer; (x, y) are domain coordinates (s = R angle and
 *                    the axial height on the cylinder), z the height above the substrate
 *   sphere           (x, y, z) in space: the shell between radius R and R + thickness
 * On wrapping axes (period[d] > 0: plane and cylinder) a tetrahedron may straddle the seam: each
 * corner carries an image shift (sx, sy), and
 *   unwrapped corner = pos[node] + (sx period[0], sy period[1], 0)
 * gives a coherent, positively oriented tetrahedron (as fs_mesh's triangles, geom/mesh.h).
 * zeta is each node's relative height in the layer: 0 on the substrate, 1 on top, exactly so for the
 * nodes of those two surfaces (the cuts of geom/tetcut.h keep it exact).
 * Face f of a tetrahedron is the one opposite its corner f; fs_tet_face[f] lists its corners
 * counter-clockwise seen from outside the tetrahedron. */
extern const int fs_tet_face[4][3];

/* A growable list of indices. */
typedef struct {
    int32_t n, cap;
    int32_t *v;
} fs_tet_list;

typedef struct {
    fs_domain domain;      /* normalized (fs_domain_normalize) */
    double period[2];      /* periods of the unrolled layer in x and y; 0 where it does not wrap */
    double thickness;      /* thickness the mesh was built with (cm) */
    int32_t n_nodes, cap_nodes;
    double *pos;           /* 3 per node: material coordinates */
    double *zeta;          /* per node: relative height in the layer */
    int32_t n_tets, cap_tets;
    int32_t *tet;          /* 4 node indices per tetrahedron */
    int8_t *shift;         /* 8 per tetrahedron: image shift (sx, sy) of each corner */
    fs_tet_list *node_tets; /* per node: the tetrahedra it is a corner of (fs_tetmesh_build_node_tets),
                             * kept up to date by fs_tetmesh_add_tet and fs_tetmesh_set_tet; NULL
                             * until built */
} fs_tetmesh;

/* Releases everything and zeroes the mesh. */
void fs_tetmesh_free(fs_tetmesh *m);

/* Signed volume of the tetrahedron of 4 points x[3*c + k] (positive when oriented as in the
 * design note: (x1 - x0, x2 - x0, x3 - x0) right-handed). */
double fs_tet_volume(const double x[12]);

/* Quality in [0, 1]: 6 sqrt(2) volume / (root mean square edge)^3, 1 for the regular tetrahedron,
 * near 0 for flat ones (slivers, needles, caps); negative when inverted. */
double fs_tet_quality(const double x[12]);

/* Unwrapped position of corner c of tetrahedron t (3 values), and all four corners (12 values). */
void fs_tetmesh_corner(const fs_tetmesh *m, int32_t t, int c, double out[3]);
void fs_tetmesh_corners(const fs_tetmesh *m, int32_t t, double x[12]);

/* Signed volume of tetrahedron t (cm^3). */
double fs_tetmesh_volume(const fs_tetmesh *m, int32_t t);

/* Appends a node (its list empty if lists are built); returns its index. */
int32_t fs_tetmesh_add_node(fs_tetmesh *m, const double pos[3], double zeta);

/* Appends a tetrahedron (shift NULL: all zero) and enters it in its nodes' lists if built; returns
 * its index. */
int32_t fs_tetmesh_add_tet(fs_tetmesh *m, const int32_t v[4], const int8_t *shift);

/* Replaces the corners of tetrahedron t, keeping the node lists. */
void fs_tetmesh_set_tet(fs_tetmesh *m, int32_t t, const int32_t v[4], const int8_t *shift);

/* Builds the node lists (each in ascending tetrahedron order). */
void fs_tetmesh_build_node_tets(fs_tetmesh *m);

/* The tetrahedra having both a and b as corners, with b's shift relative to a's equal to rel (2
 * values; NULL for any), into out (growable); returns their number. Needs the node lists. */
int32_t fs_tetmesh_edge_tets(const fs_tetmesh *m, int32_t a, int32_t b, const int8_t *rel, fs_tet_list *out);

/* Appends v to the list; fs_tet_list_free releases it. */
void fs_tet_list_push(fs_tet_list *l, int32_t v);
void fs_tet_list_free(fs_tet_list *l);

/* Face adjacency: adj[4 t + f] receives the tetrahedron across face f of t, or -1 where no other
 * tetrahedron has that face (same nodes and relative shifts, opposite orientation). Returns the number
 * of faces that are held by more than two tetrahedra or twice the same way (0 in a valid mesh; they
 * are left at -1). */
int32_t fs_tetmesh_adjacency(const fs_tetmesh *m, int32_t *adj);

/* Connected components of tetrahedra through shared faces (adj as above): comp[t] in 0..count-1,
 * numbered in order of their smallest tetrahedron. Returns the count. */
int32_t fs_tetmesh_components(const fs_tetmesh *m, const int32_t *adj, int32_t *comp);

/* Facts about a mesh, for checks, tests and logs. */
typedef struct {
    int32_t bad_faces;      /* faces held by more than two tetrahedra or twice the same way */
    int32_t boundary_faces; /* faces held by one tetrahedron */
    int32_t nonpositive;    /* tetrahedra of volume <= 0 */
    int32_t unused_nodes;   /* nodes no tetrahedron uses */
    double volume;          /* total volume (cm^3) */
    double min_volume;      /* smallest tetrahedron volume */
    double min_quality;     /* smallest fs_tet_quality */
    int32_t components;     /* connected components (through faces) */
    int64_t euler;          /* V - E + F - T of the whole mesh (edges and faces counted with shifts):
                             * the sum over the components, 1 for each one that is a ball, 0 for
                             * one that wraps like a periodic slab */
} fs_tetmesh_report;

/* Fills r. Returns 0 when the mesh is valid (no bad faces, no tetrahedron of volume <= 0, every
 * node used), else -1 (r still filled; nothing reported through fs_error). */
int fs_tetmesh_check(const fs_tetmesh *m, fs_tetmesh_report *r);

/* How fs_tetmesh_layer builds a layer. */
typedef struct {
    double thickness;      /* layer thickness (cm, > 0) */
    int layers;            /* element layers through the thickness (>= 1): layers + 1 point layers */
    int iterations;        /* repulsion iterations of the point layers below the top */
    double radius_jitter;  /* their repulsion radius jitter */
    uint64_t seed;         /* their seed (each layer its own stream) */
    double sliver_quality; /* tetrahedra below this fs_tet_quality (in the isotropic frame of the
                            * design note) are slivers to be fixed */
} fs_tetlayer_params;

/* 1 layer of 1 cm, 30 iterations, jitter 0.2, seed 1, sliver quality 0.05. */
fs_tetlayer_params fs_tetlayer_params_default(void);

/* design: a layer of thickness h on domain d (plane, periodic or not; cylinder, unrolled and
 * periodic around; sphere, a shell outside the sphere's surface) from point layers: the top layer
 * is `top` (the domain's sample, domain coordinates), the others are fresh repulsion samples of as
 * many points, one independent stream per layer, at relative heights k / layers. Qhull's 3-D
 * Delaunay runs in an isotropic frame: the heights are stretched so that the layers lie about 0.82
 * spacings apart, as in a close-packed lattice (on the sphere the radial distance from the surface
 * is stretched, which is not affine but nearly so for a shell thin against its radius); the
 * tetrahedra are then taken back to the true heights, which keeps them valid on the plane and the
 * cylinder exactly. On the sphere the tetrahedra inside the hollow (all four corners on the
 * bottom surface) are dropped. Slivers (quality below sliver_quality in the isotropic frame) are
 * fixed by moving their corners within their layers (never the top layer's corners across the
 * surface) by a small pseudo-random step and triangulating again, a few rounds; the count left is
 * logged. Periodic seams: the margin of copied points starts at three spacings and doubles until the
 * mesh checks (faces matched, the volume of one period filled).
 * Returns 0, or -1 with fs_error (FS_ERR_DATA for bad parameters or points; FS_ERR_INTERNAL when
 * Qhull fails or no valid mesh results). */
int fs_tetmesh_layer(const fs_domain *d, const fs_points *top, const fs_tetlayer_params *p, fs_tetmesh *out);

#endif
