/* Simulation domains (plane, cylinder, sphere), their periodicity and their texture-space maps. */
#ifndef FS_GEOM_DOMAIN_H
#define FS_GEOM_DOMAIN_H

#include <stdbool.h>

typedef enum { FS_DOMAIN_PLANE = 0, FS_DOMAIN_CYLINDER = 1, FS_DOMAIN_SPHERE = 2, FS_DOMAIN_MESH = 3 } fs_domain_type;

/* design: every point lives in "domain coordinates", three doubles:
 *   plane     (x, y, 0)        x in [0, width), y in [0, height)              (cm)
 *   cylinder  (s, z, 0)        s = radius * angle in [0, 2 pi radius), z in [0, height)  (unwrapped, cm)
 *   sphere    (x, y, z)        a point on the sphere of the given radius, centred at the origin (cm)
 * Plane and cylinder are therefore both rectangles [0, period_x) x [0, period_y) in the (first two)
 * coordinates; the cylinder is always periodic in s.
 *   mesh      (x, y, z)        a vertex of a loaded triangle mesh (geom/uvmesh.h), in space (cm)
 * A mesh carries its texture coordinates per triangle corner (its own UV layout), so its points have
 * no texture point of their own: for rendering, texture space is the rectangle width x height (cm
 * per unit of u and v, set from the mesh's area when it is loaded) and the functions below treat it
 * as a non-periodic plane of that size (embedding, normal and texture maps of the flat layout). */
typedef struct {
    fs_domain_type type;
    double width;     /* plane: extent in x (cm); mesh: cm per unit of u */
    double height;    /* plane, cylinder: extent in y / along the axis (cm); mesh: cm per unit of v */
    double radius;    /* cylinder, sphere (cm) */
    bool periodic_x;  /* plane: wraps in x; cylinder: always true (set by fs_domain_normalize) */
    bool periodic_y;  /* plane: wraps in y; cylinder: wraps along the axis */
} fs_domain;

/* A 10 x 10 cm non-periodic plane. */
fs_domain fs_domain_default(void);

/* Makes derived fields consistent (cylinder => periodic_x). */
void fs_domain_normalize(fs_domain *d);

/* The rectangle of the unwrapped domain (plane and cylinder): period_x = width or 2 pi radius,
 * period_y = height. For the sphere: 2 pi radius and pi radius (the equirectangular extent). */
double fs_domain_extent_x(const fs_domain *d);
double fs_domain_extent_y(const fs_domain *d);

/* Surface area (cm^2). */
double fs_domain_area(const fs_domain *d);

/* Wraps a point into the fundamental domain along the periodic directions (plane, cylinder);
 * for the sphere, projects it back onto the sphere. p has three components, modified in place. */
void fs_domain_wrap(const fs_domain *d, double *p);

/* The shortest displacement b - a, taking periodicity into account (plane, cylinder), or the plain
 * difference (sphere). out has three components. */
void fs_domain_delta(const fs_domain *d, const double *a, const double *b, double *out);

/* 3-D world position of a domain point (cylinder: around the z axis; plane: z = 0). */
void fs_domain_embed(const fs_domain *d, const double *p, double *world);

/* Outward unit normal of the surface at a domain point. */
void fs_domain_normal(const fs_domain *d, const double *p, double *n);

/* Texture coordinates (u, v) in [0, 1] of a domain point: plane x/width, y/height; cylinder
 * angle/(2 pi), z/height; sphere longitude/(2 pi) in [0, 1), (latitude + pi/2)/pi. */
void fs_domain_to_uv(const fs_domain *d, const double *p, double *uv);

/* Inverse of fs_domain_to_uv. */
void fs_domain_from_uv(const fs_domain *d, const double *uv, double *p);

/* Whether texture space wraps in u / v (the maps tile seamlessly that way). */
bool fs_domain_wraps_u(const fs_domain *d);
bool fs_domain_wraps_v(const fs_domain *d);

const char *fs_domain_type_name(fs_domain_type t);

#endif
