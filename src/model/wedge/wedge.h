/* The wedge finite element model (thesis ch. 5): a layer of 6-node wedges bonded to a growing background, fractured by element removal (§5.6) or splitting (§5.7). */
#ifndef FS_MODEL_WEDGE_H
#define FS_MODEL_WEDGE_H

#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/params.h"

/* Settings of the wedge model that have no shared section (its meshing, fracture and solver settings
 * are fs_mesh_params, fs_fracture_params and fs_solver_params). */
typedef struct {
    double thickness_gradient; /* relative change of the thickness across the texture in u: the
                                  thickness is scaled by 1 + gradient (u - 1/2) */
} fs_wedge_params;

/* No gradient. */
fs_wedge_params fs_wedge_params_default(void);

/* The model's state (model/wedge/internal.h). */
typedef struct fs_wedge_model fs_wedge_model;
struct fs_model_setup;

/* The model interface (model/model.h) of the wedge model. create builds the layer on mesh (borrowed,
 * refined and cut in place), assembles and factorizes it; NULL with fs_error (FS_ERR_DATA for bad
 * parameters or a degenerate element, FS_ERR_INTERNAL for a failed factorization). advance runs from
 * the current time to t (thesis Algorithms 1, 5 and 8, or the splitting of §5.7). */
fs_wedge_model *fs_wedge_create(fs_mesh *mesh, const struct fs_model_setup *setup);
int fs_wedge_advance(fs_wedge_model *w, double t);
fs_model_info fs_wedge_info(const fs_wedge_model *w);
void fs_wedge_report(const fs_wedge_model *w);
void fs_wedge_destroy(fs_wedge_model *w);

/* The render mesh of the current state (SPEC §6, texture space, see geom/surface.h): the top surface of the
 * living elements (height = top of the layer in cm, crack 0, cell = connected fragment + 1 (wrapping
 * past 65535), shade per fragment) and the floor of removed elements (height 0, crack 1, cell 0).
 * With fracture by splitting, the top surface at the in-plane displaced top-node positions (so the
 * cracks open) and a floor (height 0, crack 1, cell 0) exactly in the gaps between the fragments:
 * on the plane and cylinder the mesh partitions texture space, tops and floor meeting vertex to
 * vertex, so that the lift closes every crack with walls (wedge/surface.c).
 * Fragments are the connected components of living elements sharing a node. Returns 0 or -1. */
int fs_wedge_surface(const fs_wedge_model *w, fs_surface *out);

#endif
