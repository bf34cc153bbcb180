/* The discrete shell model (Gingold et al. 2004): membrane and bending strain per triangle, plasticity with linear kinematic hardening, fracture through the faces. */
#ifndef FS_MODEL_SHELL_H
#define FS_MODEL_SHELL_H

#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/params.h"

/* Settings of the shell model that have no shared section (material, growth, shrinkage, time and
 * fracture come from their sections). */
typedef struct {
    double bond;         /* stiffness of the bond between the shell and the surface it lies on, relative
                            to a layer bonded along its bottom face (a wedge layer of the same
                            thickness: 2G/h per unit area tangentially, 2E/h normally); 0 = a free shell */
    double yield;        /* von Mises yield stress (kPa) of the plasticity, 0 = elastic */
    double hardening;    /* linear kinematic hardening coefficient gamma (h_kin / 2 mu, Gingold et al.),
                            >= 0 */
    double budge;        /* a crack line passing within this fraction of an edge's length of one of its
                            ends moves (budges) that vertex onto the line instead of splitting the edge,
                            in [0, 0.45] */
    double gap_scale;    /* the maps draw crack openings this many times wider than simulated (>= 1) */
    double max_step;     /* longest time step, as a fraction of [time] end (plasticity is updated once
                            per step) */
} fs_shell_params;

/* Bond 1, no plasticity (hardening 0.1 when on), budging within 0.2 of an edge, gaps drawn 1:1,
 * steps of at most 1/20 of the run. */
fs_shell_params fs_shell_params_default(void);

/* The model's state (model/shell/internal.h). */
typedef struct fs_shell fs_shell;
struct fs_model_setup;

/* The model interface (model/model.h) of the shell model. create builds the shell on mesh (borrowed;
 * fracture cuts it in place) at time 0, resting on the mesh's surface: the plane and the periodic
 * plane flat, the cylinder and the sphere embedded in 3-D, a mesh domain (setup->corner_uv) as given.
 * NULL with fs_error (FS_ERR_DATA for bad parameters or a degenerate triangle). advance runs from the
 * current time to t: equilibrium by Newton's method (CHOLMOD), the plastic update once per accepted
 * step, and fracture events found by the search in time (fracture/event.h). */
fs_shell *fs_shell_create(fs_mesh *mesh, const struct fs_model_setup *setup);
int fs_shell_advance(fs_shell *s, double t);
fs_model_info fs_shell_info(const fs_shell *s);
void fs_shell_report(const fs_shell *s);
void fs_shell_destroy(fs_shell *s);

/* The render mesh of the current state in texture space (geom/surface.h): every triangle at its
 * corners' texture coordinates moved by the opening of the cracks (times gap_scale), height the
 * thickness, cell = fragment + 1; under it a floor (height 0, crack 1) over the rest layout, so the
 * gaps show as cracks. On a mesh domain the charts of the UV layout are padded by a skirt a few
 * pixels wide (at 1024 pixels) copying their border, so that mip-maps do not bleed. Returns 0 or -1. */
int fs_shell_surface(const fs_shell *s, fs_surface *out);

#endif
