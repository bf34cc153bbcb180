/* The tetrahedral model (O'Brien & Hodgins 1999): a thick layer of linear tetrahedra on its substrate, cracked by node splits along the separation tensor's planes. */
#ifndef FS_MODEL_TET_H
#define FS_MODEL_TET_H

#include <stdint.h>

#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/params.h"

/* Settings of the tetrahedral model that have no shared section ([tet] in a preset). */
typedef struct {
    int layers;            /* element layers through the thickness; 0: as many as make the tetrahedra
                              about as tall as they are wide (1 to 6) */
    double snap_distance;  /* O'Brien & Hodgins' distance threshold: an element corner nearer the
                              fracture plane than this many mean edge lengths is taken as on it */
    double snap_angle;     /* their angle threshold (degrees): ... or one whose direction from the
                              splitting node is within this angle of the plane */
    double bond;           /* tensile strength of the bond between the layer's bottom and the
                              substrate (kPa): a bottom node pulled off harder comes loose, and the
                              layer curls up there; 0: bonded for good */
    int32_t max_events;    /* stop fracturing after this many events (node splits and bonds coming
                              loose); 0: no limit */
} fs_tet_params;

/* layers 0 (automatic), snap distance 0.3 edge lengths, snap angle 5.73 degrees (0.1 rad, the
 * paper's), bond 0 (never comes loose), no event limit. */
fs_tet_params fs_tet_params_default(void);

/* The model's state (model/tet/internal.h). */
typedef struct fs_tet fs_tet;
struct fs_model_setup;

/* The model interface (model/model.h). create builds the layer on the domain of mesh (borrowed; its
 * nodes become the top surface's points, the mesh itself is not changed), assembles and solves it;
 * NULL with fs_error (FS_ERR_DATA for bad parameters, naming the key; FS_ERR_INTERNAL for a mesher or
 * solver failure). advance runs the fracture events from the current time to t. */
fs_tet *fs_tet_create(fs_mesh *mesh, const struct fs_model_setup *setup);
int fs_tet_advance(fs_tet *s, double t);
fs_model_info fs_tet_info(const fs_tet *s);
void fs_tet_report(const fs_tet *s);
void fs_tet_destroy(fs_tet *s);

/* The render surface of the current state (SPEC §6, texture space, geom/surface.h): every face of
 * the layer that is not bonded to the substrate and faces up or sideways, at its displaced position
 * (height = distance from the substrate in cm, so crack walls, their depth and overhangs show):
 * top faces with crack 0, cell = fragment + 1 (wrapping past 65535) and a shade per fragment, crack
 * walls with crack 1 and cell 0. Fragments are the pieces of the layer connected through faces.
 * Returns 0 or -1. */
int fs_tet_surface(const fs_tet *s, fs_surface *out);

/* The fragments as closed 3-D pieces (geom/surface.h, fs_solid): every face of the layer that belongs
 * to one element only, at its displaced position in space (the plane as is, the cylinder's unrolled
 * layer wrapped around its axis at radius R + height), the top with wall 0 and the crack walls, the
 * sides and the bottom with wall 1; each fragment with its own positions, unrolled across the seams
 * (a fragment that wraps all the way round stays cut at the seam). Returns 0 or -1. */
int fs_tet_solid(const fs_tet *s, fs_solid *out);

#endif
