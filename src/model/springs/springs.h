/* The springs model: the extended Skjeltorp–Meakin mass-spring network of thesis chapter 4, its fracture in time, and its 3-D post-process. */
#ifndef FS_MODEL_SPRINGS_H
#define FS_MODEL_SPRINGS_H

#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/params.h"

/* What the 3-D post-process of thesis §4.5 does with the final state. */
typedef enum {
    FS_SPRINGS_POST_GLUE = 0, /* walls glued fully where the spring is intact, at the bottom only where
                                 it broke; bottom fixed on the background; relaxed */
    FS_SPRINGS_POST_CURL = 1, /* 'curl' mode: walls of broken springs not glued at all; the bottom
                                 within `peel` of a crack comes free, so rims curl up; relaxed */
    FS_SPRINGS_POST_FLAT = 2  /* no relaxation: cells drawn from the 2-D positions (a fast preview) */
} fs_springs_post;

typedef struct {
    int layers;              /* material layers through the thickness, 1..8 (thesis §4.3) */
    double shear_lag;        /* shear-lag length in total thicknesses: anchor stiffness E / (shear_lag^2 H) per area; > 0 */
    double slide_length;     /* anchor length (cm) past which anchors slide; < 0 never */
    double residual;         /* equilibrium tolerance: largest node force over the force a median
                                spring carries at its break strain; in (0, 1e-2] */
    int max_breaks;          /* stop after this many breaks; 0 = no limit */
    fs_springs_post post;    /* the 3-D post-process */
    double peel;             /* curl: distance (cm) from a crack within which the bottom comes free */
} fs_springs_params;

/* 1 layer, shear_lag 2, no sliding, residual 1e-3, no break limit, glue, peel 0.5 cm. */
fs_springs_params fs_springs_params_default(void);

/* The model's state (model/springs/internal.h). */
typedef struct fs_springs fs_springs;
struct fs_model_setup;

/* The model interface (model/model.h) of the springs model. create builds the network on mesh at
 * time 0 (not yet relaxed); NULL with fs_error (FS_ERR_DATA for bad parameters, naming the [springs]
 * key, a growth that does not suit the domain or a mesh too small). advance runs from the accepted
 * state to t_end (see the design notes of internal.h) and ends with an accepted equilibrium at t_end,
 * or earlier once max_breaks springs have broken. */
fs_springs *fs_springs_create(const fs_mesh *mesh, const struct fs_model_setup *setup);
int fs_springs_advance(fs_springs *s, double t_end);
fs_model_info fs_springs_info(const fs_springs *s);
void fs_springs_report(const fs_springs *s);
void fs_springs_destroy(fs_springs *s);

/* design: the 3-D post-process of thesis §4.5 (Fig. 4.10), in springs/post.c. Every Voronoi cell
 * (circumcentres of its node's ring; on a non-periodic border closed by the midpoints of the border
 * edges and the node, snapped onto the domain's edge) is extruded through the layers: at each level
 * between layers there is a node at the cell's site and one at each polygon corner, and every
 * triangular prism (site, corner, next corner) between two levels is a rigid sub-network of springs
 * (its nine edges and a diagonal of each side face). Neighbouring cells share their wall nodes at
 * a level where the spring between them, in the layer just below that level, is intact: walls are
 * glued fully where the spring is intact and down to the depth of the crack where it broke; the
 * bottom level is glued everywhere and fixed, except in curl mode. Rest lengths are the reference
 * geometry shrunk by the shrinkage at each level, so the shrinking tops pull away from the cracks;
 * initial positions come from the relaxed 2-D masses (a corner shared by a group of masses is
 * placed by the affine map of their triangle, the similarity of their spring, or the free shrinkage
 * of a lone mass). After relaxation, each cell's top becomes a fan of triangles (cell id = fragment,
 * crack 0) and every open wall a strip of quads (crack 1), all mapped back to texture space through
 * the inverse background flow. The heights are real: cracks reach down to the glued level.
 * Sphere: triangles are unwrapped across the longitude seam and split at the poles.
 * Returns 0 or -1 with fs_error. */
int fs_springs_surface(const fs_springs *s, fs_surface *out);

#endif
