/* Conforming refinement of triangles on the sphere into the equirectangular texture, for render meshes. */
#ifndef FS_GEOM_SPHERE_SURFACE_H
#define FS_GEOM_SPHERE_SURFACE_H

#include <stdint.h>

#include "geom/domain.h"
#include "geom/surface.h"

/* Where the pieces of a refined triangle go, and how finely it is cut. */
typedef struct {
    const fs_domain *domain; /* of type FS_DOMAIN_SPHERE */
    double uv_tolerance;     /* largest uv distance of a chord's midpoint image from the mean of its
                              * ends' images before the chord is halved, falling to a quarter of it
                              * over the 7.5 % of the texture height next to each pole; chords
                              * shorter than 1e-3 radii are not halved */
    fs_surface *out;     /* the triangles are appended to it */
    /* Appends to out a vertex at texture point (u, v) whose attributes are w[0] A + w[1] B + w[2] C
     * for the corners A, B, C of the triangle being refined (the weights are >= 0 and sum to 1; the
     * caller mixes its attributes as it likes), and returns its index. */
    int32_t (*vertex)(void *user, double u, double v, const double w[3]);
    void *user;
} fs_sphere_refiner;

/* Draws the triangle (a, b, c) of points in 3-D (on or near the sphere; each point is drawn at the
 * texture point of its radial projection), counter-clockwise seen from outside, into s->out.
 * design: the chords are refined edge by edge until the equirectangular map is close to affine on
 * each piece; whether a chord is halved and where depends only on its two ends (taken in
 * lexicographic order), so two triangles sharing an edge cut it at bit-identical points and the
 * refined mesh is conforming. Each piece's u values are unwrapped around its first corner. A
 * triangle containing a pole is cut at the point X where the ray to the pole meets its plane into
 * three (X, A, B); each is drawn as columns of meridian segments from the points of its chord AB,
 * cut as the neighbour across AB cuts it, to the pole's row of the texture. A degenerate triangle
 * draws nothing. */
void fs_sphere_triangle(const fs_sphere_refiner *s, const double a[3], const double b[3], const double c[3]);

#endif
