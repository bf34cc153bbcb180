/* The tangent frame at a node of the wedge model's surface, for the 2-D geometry of the split (fracture
 * planes, cuts, collapses) and of the crack-tip smoothing. Internal to src/model/wedge_*.c. */
#ifndef FS_MODEL_WEDGE_FRAME_H
#define FS_MODEL_WEDGE_FRAME_H

#include <math.h>

#include "base/vec.h"
#include "model/wedge/internal.h"

/* The tangent plane at a node: the flat frame's x and y, or on the sphere a right-handed pair
 * (e1, e2, normal), so triangles counter-clockwise from outside are counter-clockwise in it. */
typedef struct {
    double e1[3], e2[3];
} fs_wedge_frame;

static inline void fs_wedge_frame_at(const fs_wedge_model *w, int32_t n, fs_wedge_frame *f)
{
    if (w->flat) {
        f->e1[0] = 1.0, f->e1[1] = 0.0, f->e1[2] = 0.0;
        f->e2[0] = 0.0, f->e2[1] = 1.0, f->e2[2] = 0.0;
        return;
    }
    const double *nrm = w->normal + 3 * (size_t)n;
    double axis[3] = {0.0, 0.0, 1.0};
    if (fabs(nrm[2]) > 0.9) {
        axis[0] = 1.0;
        axis[2] = 0.0;
    }
    fs_cross3(f->e1, axis, nrm);
    double len = fs_norm3(f->e1);
    for (int k = 0; k < 3; k++)
        f->e1[k] /= len;
    fs_cross3(f->e2, nrm, f->e1);
}

/* A 3-D vector's coordinates in the frame. */
static inline void fs_wedge_frame_to_2d(const fs_wedge_frame *f, const double v[3], double out[2])
{
    out[0] = fs_dot3(f->e1, v);
    out[1] = fs_dot3(f->e2, v);
}

/* The 3-D vector of frame coordinates v. */
static inline void fs_wedge_frame_from_2d(const fs_wedge_frame *f, const double v[2], double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = v[0] * f->e1[k] + v[1] * f->e2[k];
}

#endif
